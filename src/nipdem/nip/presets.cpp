#include "nipdem/nip/presets.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/embedded_preset_black.hpp"
#include "nipdem/embedded_preset_color.hpp"
#include "nipdem/io/field_map.hpp"
#include "nipdem/nip/nip_config.hpp"

namespace nipdem::nip {
std::vector<std::string> preset_names() { return {"black", "color"}; }
std::string preset_text(const std::string& name) {
  if (name == "black") return kPreset_black;
  if (name == "color" || name == "colour") return kPreset_color;
  throw_input("presets", "NAME", "\"" + name + "\"", "unknown preset", "black, color");
}

magnet::BlockAssembly preset_magnet(const std::string& name, const MagnetOverrides& o) {
  const NipConfig c = read_nip_config(preset_text(name), "preset:" + name);
  if (c.magnet.field == "knife") {
    magnet::KnifeParams k;
    if (o.tip_depth_m) k.tip_depth_m = *o.tip_depth_m;
    if (o.br_T) k.blade_Br_T = *o.br_T;
    return magnet::make_knife(k);
  }
  if (c.magnet.field == "color_pole") {
    magnet::ColorPoleParams k;
    if (o.tip_depth_m) k.tip_depth_m = *o.tip_depth_m;
    if (o.br_T) k.Br_T = *o.br_T;
    return magnet::make_color_pole(k);
  }
  throw_input("preset:" + name, "magnet.field", c.magnet.field, "not an analytic magnet", "knife, color_pole");
}

PresetToner preset_toner(const std::string& name) {
  const NipConfig c = read_nip_config(preset_text(name), "preset:" + name);
  return {c.magnet.toner, 0.5 * c.size.d50};
}

void check_field_options(const FieldOptions& o, const std::string& where) {
  if (o.preset != "black" && o.preset != "color") throw_input(where, "--preset", o.preset, "unknown preset", "black, color");
  if (o.radius_m) require_range(where, "--radius", *o.radius_m, 1e-7, 1e-3);
  if (o.tip_depth_m) require_range(where, "--tip-depth", *o.tip_depth_m, 0.0, 5e-3);
  if (o.br_T) require_range(where, "--br", *o.br_T, -2.5, 2.5);
}

FieldSetup make_field_setup(const FieldOptions& o) {
  FieldSetup s;
  const PresetToner t = preset_toner(o.preset);
  s.toner = t.magnetisation;
  s.radius_m = o.radius_m.value_or(t.d50_radius_m);
  require_range("field", "radius_m", s.radius_m, 1e-7, 1e-3);
  if (!o.map.empty()) {
    if (o.tip_depth_m || o.br_T) throw_input("field", "--tip-depth/--br", "", "magnet parameters do not apply to a field map");
    s.field = std::make_unique<io::FieldMap>(io::FieldMap::from_file(o.map));
  } else {
    s.field = std::make_unique<magnet::BlockAssembly>(preset_magnet(o.preset, {.tip_depth_m = o.tip_depth_m, .br_T = o.br_T}));
  }
  return s;
}

namespace {
// A point on an edge (within round-off of its length) or inside the closed polygon `v`.
bool on_or_in(Vec2 p, const std::vector<Vec2>& v) {
  bool in = false;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    const Vec2 a = v[j], b = v[i], ab = b - a, ap = p - a;
    const double len2 = norm2(ab);
    const double t = len2 > 0 ? std::clamp(dot(ap, ab) / len2, 0.0, 1.0) : 0.0;
    if (norm(ap - t * ab) <= 1e-12 * std::sqrt(len2)) return true;  // on the edge (round-off of its length)
    if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * ab.x / ab.y) in = !in;
  }
  return in;
}
}  // namespace

MagnetMaterial::MagnetMaterial(const magnet::MagnetField& f) : blocks_(f.material()), top_(-std::numeric_limits<double>::infinity()) {
  for (const auto& poly : blocks_)
    for (const Vec2& v : poly) top_ = std::max(top_, v.y);
}

void MagnetMaterial::require_outside(Vec2 p, const std::string& where, const std::string& keys, const std::string& allowed_prefix) const {
  for (std::size_t k = 0; k < blocks_.size(); ++k)
    if (on_or_in(p, blocks_[k]))
      throw_input(where, keys, fmt::format("point ({:g}, {:g}) m", p.x, p.y),
                  fmt::format("the point lies on or inside the magnet (block {} of {}): the field there is not one a toner "
                              "can feel, and it is singular on the blocks' corners",
                              k + 1, blocks_.size()),
                  fmt::format("{} outside the magnet's blocks, e.g. y > {:g} m (their top)", allowed_prefix, top_));
}

void require_finite(const std::vector<double>& values, Vec2 p, const std::string& where, const std::string& keys,
                    const std::string& allowed) {
  for (double v : values)
    if (!std::isfinite(v))
      throw_input(where, keys, fmt::format("point ({:g}, {:g}) m", p.x, p.y),
                  "the field or the force is not finite there (a magnet corner or edge, where the field is singular)", allowed);
}

nlohmann::json field_probe(const FieldOptions& o, double x, double y) {
  require_range("field probe", "--x", x, -1.0, 1.0);
  require_range("field probe", "--y", y, -1.0, 1.0);
  check_field_options(o, "field probe");
  const FieldSetup s = make_field_setup(o);
  const std::string keys = "--x, --y";
  MagnetMaterial(*s.field).require_outside({x, y}, "field probe", keys, "a point");  // an analytic magnet's (a map has none)
  const auto smp = s.field->at({x, y});
  const Vec2 m = magnet::induced_moment(s.toner, s.radius_m, smp.B);
  const Vec2 F = magnet::dipole_force(m, smp);
  nlohmann::json j = {{"preset", o.preset},         {"source", s.field->describe()}, {"x_m", x},
          {"y_m", y},                   {"Bx_T", smp.B.x},                {"By_T", smp.B.y},
          {"B_T", norm(smp.B)},         {"dBx_dx_T_per_m", smp.dB.xx},    {"dBx_dy_T_per_m", smp.dB.xy},
          {"dBy_dx_T_per_m", smp.dB.yx}, {"dBy_dy_T_per_m", smp.dB.yy},   {"radius_m", s.radius_m},
          {"mx_Am2", m.x},              {"my_Am2", m.y},                  {"moment_Am2", norm(m)},
          {"Fx_N", F.x},                {"Fy_N", F.y},                    {"force_N", norm(F)}};
  std::vector<double> values;
  for (const auto& [k, v] : j.items())
    if (v.is_number()) values.push_back(v.get<double>());
  require_finite(values, {x, y}, "field probe", keys, "a point off the magnet's corners and edges");
  return j;
}
}  // namespace nipdem::nip
