#include "nipdem/solvers/ldc/setup_file.hpp"

#include <cstdint>
#include <initializer_list>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "nipdem/core/error.hpp"

namespace nipdem::ldc {
namespace {
using nlohmann::json;

// The setup format nests 3 levels deep (boundary.top.kind, discs[k].x_m); anything much deeper is
// not a setup. The bound is checked while parsing, so a file of 100,000 '[' is refused before the
// recursive parts of the JSON library (dump, copy) ever see it (they overflowed the stack).
constexpr int kMaxNesting = 64;
// Values and keys quoted in a message are cut to this many bytes (a message is one line).
constexpr std::size_t kMaxShown = 60;

std::string cut(std::string s, std::size_t max = kMaxShown) {
  if (s.size() <= max) return s;
  std::size_t n = max - 3;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;  // not inside a UTF-8 character
  s.resize(n);
  return s + "...";
}
// A value as quoted in a message: its JSON text, cut to kMaxShown bytes.
std::string shown(const json& v) { return cut(v.dump()); }

struct Reader {
  const std::string& where;

  // Every key of `o` must be one of `known` (a misspelt key would otherwise be ignored silently).
  void only(const json& o, std::initializer_list<const char*> known, const std::string& prefix) const {
    for (const auto& [key, value] : o.items()) {
      bool ok = false;
      for (const char* k : known) ok = ok || key == k;
      if (!ok) {
        std::string list;
        for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
        throw_input(where, prefix + cut(key), shown(value), "unknown key", list);
      }
    }
  }

  // An optional object `key` of `o` (null if absent); anything but an object is an error.
  const json* object(const json& o, const std::string& key, const std::string& name) const {
    const auto it = o.find(key);
    if (it == o.end()) return nullptr;
    if (!it->is_object()) throw_input(where, name, shown(*it), "must be an object (table)");
    return &*it;
  }
  void number(const json& o, const char* key, const std::string& prefix, double& v) const {
    const auto it = o.find(key);
    if (it == o.end()) return;
    if (!it->is_number()) throw_input(where, prefix + key, shown(*it), "must be a number");
    v = it->get<double>();
  }
  void integer(const json& o, const char* key, const std::string& prefix, int& v) const {
    const auto it = o.find(key);
    if (it == o.end()) return;
    if (!it->is_number_integer()) throw_input(where, prefix + key, shown(*it), "must be an integer");
    if (it->is_number_unsigned() ? it->get<std::uint64_t>() > static_cast<std::uint64_t>(INT32_MAX)
                                 : (it->get<std::int64_t>() < INT32_MIN || it->get<std::int64_t>() > INT32_MAX))
      throw_input(where, prefix + key, shown(*it), "integer too large", "[-2^31, 2^31)");
    v = static_cast<int>(it->get<std::int64_t>());
  }
};

json to_json(const std::string& text, const std::string& where, bool is_toml) {
  // Refuses an array or object nested deeper than kMaxNesting as soon as the parser opens it.
  const json::parser_callback_t depth_bound = [&where](int depth, json::parse_event_t event, json&) {
    if ((event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) &&
        depth >= kMaxNesting)
      throw_input(where, "", "", "arrays/objects nested too deeply", "at most " + std::to_string(kMaxNesting) + " levels");
    return true;
  };
  try {
    if (is_toml) {  // same keys as the JSON form; [[discs]] array of tables
      std::ostringstream os;
      os << toml::json_formatter{toml::parse(text, where)};
      return json::parse(os.str(), depth_bound);
    }
    return json::parse(text, depth_bound);
  } catch (const toml::parse_error& e) {
    throw_input(where, "", "", cut("invalid TOML: " + std::string(e.description()), 4 * kMaxShown));
  } catch (const json::exception& e) {
    throw_input(where, "", "", cut(std::string("invalid JSON: ") + e.what(), 4 * kMaxShown));
  }
}
}  // namespace

Setup parse_setup(const std::string& text, const std::string& where, bool is_toml) {
  const json j = to_json(text, where, is_toml);
  if (!j.is_object()) throw_input(where, "", "", "setup must be a JSON object");
  const Reader r{where};
  Setup s;
  Params& p = s.params;
  r.only(j, {"box", "boundary", "permittivity_F_per_m", "local_radius_factor", "safety_m", "tolerance", "max_iterations",
             "fd_refinement", "discs"}, "");
  if (const json* b = r.object(j, "box", "box")) {
    r.only(*b, {"x_min_m", "x_max_m", "y_min_m", "y_max_m", "cells_x", "cells_y"}, "box.");
    r.number(*b, "x_min_m", "box.", p.x_min_m);
    r.number(*b, "x_max_m", "box.", p.x_max_m);
    r.number(*b, "y_min_m", "box.", p.y_min_m);
    r.number(*b, "y_max_m", "box.", p.y_max_m);
    r.integer(*b, "cells_x", "box.", p.cells_x);
    r.integer(*b, "cells_y", "box.", p.cells_y);
  }
  if (const json* b = r.object(j, "boundary", "boundary")) {
    r.only(*b, {"bottom", "top", "left", "right"}, "boundary.");
    for (auto [name, side] : {std::pair{"bottom", &p.bottom}, {"top", &p.top}, {"left", &p.left}, {"right", &p.right}}) {
      const std::string prefix = std::string("boundary.") + name + ".";
      const json* sj = r.object(*b, name, prefix.substr(0, prefix.size() - 1));
      if (!sj) continue;
      r.only(*sj, {"kind", "value_V"}, prefix);
      std::string kind = "dirichlet";
      if (const auto it = sj->find("kind"); it != sj->end()) {
        if (!it->is_string()) throw_input(where, prefix + "kind", shown(*it), "must be a string", "dirichlet, neumann");
        kind = it->get<std::string>();
      }
      if (kind == "dirichlet") side->kind = SideKind::dirichlet;
      else if (kind == "neumann") side->kind = SideKind::neumann;
      else throw_input(where, prefix + "kind", cut(kind), "unknown kind", "dirichlet, neumann");
      r.number(*sj, "value_V", prefix, side->value_V);
    }
  }
  r.number(j, "permittivity_F_per_m", "", p.permittivity_F_per_m);
  r.number(j, "local_radius_factor", "", p.local_radius_factor);
  r.number(j, "safety_m", "", p.safety_m);
  r.number(j, "tolerance", "", p.tolerance);
  r.integer(j, "max_iterations", "", p.max_iterations);
  r.integer(j, "fd_refinement", "", p.fd_refinement);
  const auto discs = j.find("discs");
  if (discs == j.end() || !discs->is_array()) throw_input(where, "discs", "", "missing array of discs");
  s.discs.reserve(discs->size());
  for (std::size_t k = 0; k < discs->size(); ++k) {
    const json& d = (*discs)[k];
    const std::string prefix = "discs[" + std::to_string(k) + "].";
    if (!d.is_object()) throw_input(where, prefix.substr(0, prefix.size() - 1), shown(d), "must be an object (table)");
    r.only(d, {"x_m", "y_m", "radius_m", "charge_C_per_m"}, prefix);
    Disc disc;
    r.number(d, "x_m", prefix, disc.center_m.x);
    r.number(d, "y_m", prefix, disc.center_m.y);
    r.number(d, "radius_m", prefix, disc.radius_m);
    r.number(d, "charge_C_per_m", prefix, disc.charge_C_per_m);
    s.discs.push_back(disc);
  }
  return s;
}

}  // namespace nipdem::ldc
