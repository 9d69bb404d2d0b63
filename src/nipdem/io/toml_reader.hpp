// Strict TOML reading: every value is read through a Section that knows the file name and
// the dotted key path, checks type and range, and remembers which keys were used, so that
// finish() can reject unknown keys. Messages name file, key, value and the allowed range.
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <toml++/toml.h>

namespace nipdem::io {

class Section {
 public:
  Section(toml::table* t, std::string file, std::string path);

  bool has(const std::string& key) const;
  double number(const std::string& key, double lo, double hi);                    // required
  double number(const std::string& key, double lo, double hi, double fallback);   // optional
  std::int64_t integer(const std::string& key, std::int64_t lo, std::int64_t hi, std::int64_t fallback);
  bool boolean(const std::string& key, bool fallback);
  std::string choice(const std::string& key, const std::vector<std::string>& allowed, const std::string& fallback);
  std::string string(const std::string& key, const std::string& fallback);
  std::vector<double> numbers(const std::string& key, std::size_t n, double lo, double hi,
                              const std::vector<double>& fallback);
  // Required forms: a missing key is an InputError ("missing required key").
  std::int64_t integer(const std::string& key, std::int64_t lo, std::int64_t hi);
  bool boolean(const std::string& key);
  std::string choice(const std::string& key, const std::vector<std::string>& allowed);
  std::string string(const std::string& key);
  std::vector<double> numbers(const std::string& key, std::size_t n, double lo, double hi);
  // Writes `value` under `key` (marking it used): records a value derived from other keys, so
  // that the table becomes the complete resolved configuration. Needs a table that exists.
  void record(const std::string& key, double value);
  // Sub-table (created empty if absent, so optional sections read defaults).
  Section sub(const std::string& key);
  std::vector<std::string> subtable_keys() const;
  // Throws InputError for any key of this table not read (sub-tables checked by their own finish()).
  void finish() const;
  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  std::string key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

 private:
  void require(const std::string& key, const std::string& allowed) const;
  toml::table* t_;
  toml::table empty_;
  std::string file_, path_;
  std::set<std::string> used_;
};

// Parses TOML text; syntax errors become InputError naming file, line and column.
toml::table parse_toml(const std::string& text, const std::string& file);
// Copies every key of `over` into `base`; tables merge key by key (recursively), any other
// value replaces base's.
void merge_into(toml::table& base, const toml::table& over);
// Applies "a.b.c=value" overrides (value parsed as TOML: numbers, booleans, "strings", arrays).
void apply_override(toml::table& root, const std::string& assignment, const std::string& file);

}  // namespace nipdem::io
