#include "nipdem/io/toml_reader.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"

namespace nipdem::io {

Section::Section(toml::table* t, std::string file, std::string path)
    : t_(t ? t : &empty_), file_(std::move(file)), path_(std::move(path)) {}

bool Section::has(const std::string& key) const { return t_->contains(key); }

static std::string show(const toml::node& n) {
  std::ostringstream ss;
  n.visit([&](auto&& v) { ss << v; });
  return ss.str();
}

static std::string range_text(double lo, double hi) {
  auto b = [](double v) { return std::isinf(v) ? (v > 0 ? std::string("inf") : std::string("-inf")) : fmt::format("{:g}", v); };
  return "[" + b(lo) + ", " + b(hi) + "]";
}

double Section::number(const std::string& key, double lo, double hi) {
  used_.insert(key);
  const toml::node* n = t_->get(key);
  if (!n) throw_input(file_, key_path(key), "", "missing required key", range_text(lo, hi));
  std::optional<double> v;
  if (auto d = n->value<double>()) v = *d;
  if (!v || !(n->is_floating_point() || n->is_integer()))
    throw_input(file_, key_path(key), show(*n), "must be a number", range_text(lo, hi));
  if (!(*v >= lo && *v <= hi) || std::isnan(*v))
    throw_input(file_, key_path(key), fmt::format("{:g}", *v), "out of range", range_text(lo, hi));
  return *v;
}

double Section::number(const std::string& key, double lo, double hi, double fallback) {
  if (!has(key)) { used_.insert(key); return fallback; }
  return number(key, lo, hi);
}

std::int64_t Section::integer(const std::string& key, std::int64_t lo, std::int64_t hi, std::int64_t fallback) {
  used_.insert(key);
  const toml::node* n = t_->get(key);
  if (!n) return fallback;
  // The type first: value<int64_t>() of a float node converts it, undefined for |x| >= 2^63
  // (`run.seed = -2e291`, found by fuzz_config).
  if (!n->is_integer()) throw_input(file_, key_path(key), show(*n), "must be an integer", fmt::format("[{}, {}]", lo, hi));
  const std::int64_t v = n->as_integer()->get();
  if (v < lo || v > hi) throw_input(file_, key_path(key), std::to_string(v), "out of range", fmt::format("[{}, {}]", lo, hi));
  return v;
}

bool Section::boolean(const std::string& key, bool fallback) {
  used_.insert(key);
  const toml::node* n = t_->get(key);
  if (!n) return fallback;
  if (!n->is_boolean()) throw_input(file_, key_path(key), show(*n), "must be true or false");
  return *n->value<bool>();
}

std::string Section::string(const std::string& key, const std::string& fallback) {
  used_.insert(key);
  const toml::node* n = t_->get(key);
  if (!n) return fallback;
  if (!n->is_string()) throw_input(file_, key_path(key), show(*n), "must be a string");
  return *n->value<std::string>();
}

std::string Section::choice(const std::string& key, const std::vector<std::string>& allowed, const std::string& fallback) {
  const std::string v = string(key, fallback);
  for (const auto& a : allowed) if (a == v) return v;
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  throw_input(file_, key_path(key), "\"" + v + "\"", "unknown choice", list);
}

std::vector<double> Section::numbers(const std::string& key, std::size_t n, double lo, double hi,
                                     const std::vector<double>& fallback) {
  used_.insert(key);
  const toml::node* node = t_->get(key);
  if (!node) return fallback;
  const toml::array* a = node->as_array();
  if (!a || (n != 0 && a->size() != n))
    throw_input(file_, key_path(key), show(*node), n ? fmt::format("must be an array of {} numbers", n) : "must be an array of numbers");
  std::vector<double> out;
  for (const auto& e : *a) {
    auto v = e.value<double>();
    if (!v) throw_input(file_, key_path(key), show(*node), "array elements must be numbers");
    if (!(*v >= lo && *v <= hi)) throw_input(file_, key_path(key), fmt::format("{:g}", *v), "element out of range", range_text(lo, hi));
    out.push_back(*v);
  }
  return out;
}

void Section::require(const std::string& key, const std::string& allowed) const {
  if (!has(key)) throw_input(file_, key_path(key), "", "missing required key", allowed);
}

std::int64_t Section::integer(const std::string& key, std::int64_t lo, std::int64_t hi) {
  require(key, fmt::format("[{}, {}]", lo, hi));
  return integer(key, lo, hi, 0);
}

bool Section::boolean(const std::string& key) {
  require(key, "true or false");
  return boolean(key, false);
}

std::string Section::string(const std::string& key) {
  require(key, "a string");
  return string(key, std::string());
}

std::string Section::choice(const std::string& key, const std::vector<std::string>& allowed) {
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  require(key, list);
  return choice(key, allowed, std::string());
}

std::vector<double> Section::numbers(const std::string& key, std::size_t n, double lo, double hi) {
  require(key, n ? fmt::format("an array of {} numbers in {}", n, range_text(lo, hi)) : "an array of numbers");
  return numbers(key, n, lo, hi, {});
}

void Section::record(const std::string& key, double value) {
  if (t_ == &empty_) throw std::logic_error("Section::record: [" + path_ + "] is not part of the configuration");
  used_.insert(key);
  t_->insert_or_assign(key, value);
}

Section Section::sub(const std::string& key) {
  used_.insert(key);
  toml::node* n = t_->get(key);
  if (n && !n->is_table()) throw_input(file_, key_path(key), show(*n), "must be a table ([" + key_path(key) + "])");
  return Section(n ? n->as_table() : nullptr, file_, key_path(key));
}

std::vector<std::string> Section::subtable_keys() const {
  std::vector<std::string> k;
  for (const auto& [key, node] : *t_) if (node.is_table()) k.emplace_back(key.str());
  return k;
}

void Section::finish() const {
  for (const auto& [key, node] : *t_) {
    const std::string k(key.str());
    if (!used_.count(k)) {
      std::string known;
      for (const auto& u : used_) known += (known.empty() ? "" : ", ") + u;
      throw_input(file_, key_path(k), show(node), "unknown key", known.empty() ? "none here" : known);
    }
  }
}

toml::table parse_toml(const std::string& text, const std::string& file) {
  try {
    return toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw InputError(fmt::format("{}:{}:{}: TOML syntax error: {}", file, b.line, b.column, e.description()));
  }
}

void merge_into(toml::table& base, const toml::table& over) {
  for (const auto& [k, v] : over) {
    toml::node* b = base.get(k);
    if (b && b->is_table() && v.is_table()) {
      merge_into(*b->as_table(), *v.as_table());
    } else {
      base.insert_or_assign(k, v);
    }
  }
}

void apply_override(toml::table& root, const std::string& assignment, const std::string& file) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw_input("--set", "", assignment, "expected KEY=VALUE (e.g. run.end_time_s=1e-3)");
  const std::string key = assignment.substr(0, eq);
  const std::string value = assignment.substr(eq + 1);
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    parsed = toml::table{{"v", value}};  // bare word: treat as a string
  }
  toml::table* t = &root;
  std::size_t start = 0;
  for (;;) {
    const auto dot = key.find('.', start);
    const std::string part = key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (part.empty()) throw_input("--set", key, value, "empty key component");
    if (dot == std::string::npos) {
      t->insert_or_assign(part, *parsed.get("v"));
      return;
    }
    toml::node* n = t->get(part);
    if (!n) {
      t->insert(part, toml::table{});
      n = t->get(part);
    }
    if (!n->is_table()) throw_input(file, key.substr(0, dot), "", "--set: not a table");
    t = n->as_table();
    start = dot + 1;
  }
}

}  // namespace nipdem::io
