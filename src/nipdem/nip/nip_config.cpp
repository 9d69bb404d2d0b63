#include "nipdem/nip/nip_config.hpp"

#include <cstdio>
#include <unistd.h>

#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/toml_reader.hpp"
#include "nipdem/io/print_pattern.hpp"
#include "nipdem/nip/presets.hpp"
#include <algorithm>
#include <filesystem>

namespace nipdem::nip {

using constants::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();

namespace {
// Every key below is required: the preset supplies whatever the user's file omits, so the
// loader holds no default of its own (data/presets/*.toml is the one source). Only values
// derived from other keys (the pigment's magnetisation, the charge preset's RC values, the
// capacitor range = d50) are filled in here, and recorded in the resolved table.
CollisionType read_collision(io::Section s) {
  CollisionType c;
  c.restitution = s.number("restitution", 0.01, 1.0);
  c.k = s.number("k_N_per_m", 1e-6, 1e9);
  c.mu_s = s.number("mu_s", 0.0, 10.0);
  c.mu_d = s.number("mu_d", 0.0, 10.0);
  if (c.mu_d > c.mu_s) throw_input(s.file(), s.key_path("mu_d"), fmt::format("{:g}", c.mu_d), "dynamic friction must not exceed static", fmt::format("[0, mu_s = {:g}]", c.mu_s));
  s.finish();
  return c;
}

double derived(io::Section& s, const std::string& key, double lo, double hi, double value) {
  if (s.has(key)) return s.number(key, lo, hi);
  s.record(key, value);
  return value;
}

// The preset named by the file's (or an override's) `preset` key, with the file and the
// overrides merged over it key by key.
toml::table resolve(const std::string& text, const std::string& file, const std::vector<std::string>& overrides, toml::table& user) {
  user = io::parse_toml(text, file);
  for (const auto& o : overrides) io::apply_override(user, o, file);
  std::string preset = "black";
  if (const toml::node* n = user.get("preset")) {
    const auto names = preset_names();
    const auto v = n->value<std::string>();
    if (!v || std::find(names.begin(), names.end(), *v) == names.end())
      throw_input(file, "preset", v ? "\"" + *v + "\"" : "(not a string)", "unknown preset", "black, color");
    preset = *v;
  }
  toml::table root = io::parse_toml(preset_text(preset), "preset:" + preset);
  io::merge_into(root, user);
  return root;
}
}  // namespace

toml::table resolve_nip_table(const std::string& text, const std::string& file, const std::vector<std::string>& overrides) {
  toml::table user;
  return resolve(text, file, overrides, user);
}

namespace {
void check_resource_bounds(const NipConfig& c, const TimeStep& ts);
}  // namespace

NipConfig read_nip_config(const std::string& text, const std::string& file, const std::vector<std::string>& overrides) {
  toml::table user;
  NipConfig c;
  c.table = resolve(text, file, overrides, user);
  toml::table& root = c.table;
  c.print_given = user.contains("print");
  c.file = file;
  io::Section top(&root, file, "");
  c.preset = top.choice("preset", preset_names());

  {
    auto s = top.sub("run");
    c.seed = static_cast<std::uint64_t>(s.integer("seed", 0, std::numeric_limits<std::int64_t>::max()));
    c.end_time = s.number("end_time_s", 0.0, 10.0);
    c.output_interval = s.number("output_interval_s", 1e-9, 10.0);
    c.checkpoint_interval = s.number("checkpoint_interval_s", 1e-9, 10.0);
    c.threads = static_cast<int>(s.integer("threads", 1, 256));
    c.integrator = s.choice("integrator", {"velocity_verlet", "newmark_explicit"}) == "velocity_verlet"
                       ? engine::Integrator::velocity_verlet : engine::Integrator::newmark_explicit;
    c.dt = s.number("dt_s", 0.0, 1e-3);
    c.dt_fraction = s.number("dt_fraction_of_contact_time", 1e-4, 0.5);
    c.list_skin_d50 = s.number("neighbor_skin_d50", 0.01, 2.0);
    s.finish();
  }
  {
    auto s = top.sub("geometry");
    c.gap = s.number("gap_m", 1e-6, 5e-3);
    c.drum_radius = s.number("drum_radius_m", 1e-3, 1.0);
    c.roller_radius = s.number("roller_radius_m", 1e-3, 1.0);
    c.drum_speed = s.number("drum_surface_speed_m_per_s", -100.0, 100.0);
    c.roller_speed = s.number("roller_surface_speed_m_per_s", -100.0, 100.0);
    c.nip_x = s.number("nip_x_m", -0.01, 0.01);
    c.x_min = s.number("window_x_min_m", -0.01, 0.0);
    c.x_max = s.number("window_x_max_m", 0.0, 0.01);
    if (c.x_max - c.x_min < 50e-6) throw_input(file, "geometry.window_x_max_m", fmt::format("{:g}", c.x_max), "window narrower than 50 um", "window_x_max_m - window_x_min_m >= 5e-5");
    auto r = s.sub("roughness");
    c.roughness = r.boolean("enabled");
    c.rough_height = r.number("height_m", 0.0, 1e-3);
    c.rough_base = r.number("base_m", 1e-7, 1e-2);
    c.rough_spacing = r.number("spacing_m", 0.0, 1e-2);
    if (c.rough_spacing > 0.0 && c.rough_spacing < 1e-9)  // a flat of atomic size: use 0 (side by side)
      throw_input(file, "geometry.roughness.spacing_m", fmt::format("{:g}", c.rough_spacing), "a flat shorter than 1 nm",
                  "0 (pyramids side by side) or [1e-9, 0.01]");
    r.finish();
    s.finish();
  }
  {
    auto s = top.sub("toner");
    c.size.d_small = s.number("d_small_m", 1e-7, 1e-3);
    c.size.d50 = s.number("d50_m", 1e-7, 1e-3);
    c.size.d_large = s.number("d_large_m", 1e-7, 1e-3);
    c.size.number_weighted = s.choice("size_weighting", {"number", "volume"}) == "number";
    c.size.validate(file);
    c.density = s.number("density_kg_per_m3", 1.0, 1e5);
    c.cluster = s.string("cluster");
    c.cluster_file = s.string("cluster_file");
    s.finish();
  }
  if (c.cluster_file.empty()) {
    c.templates = builtin_templates();
  } else {
    c.templates = parse_templates(io::read_file(c.cluster_file), c.cluster_file);
  }
  find_template(c.templates, c.cluster, file, "toner.cluster");
  {
    auto s = top.sub("collision");
    c.stiffness_scale = s.number("stiffness_scale", 1e-6, 1.0);
    c.damping = s.choice("damping_convention", {"physical", "thesis"}) == "physical"
                    ? models::DampingConvention::physical : models::DampingConvention::thesis;
    c.tt = read_collision(s.sub("toner_toner"));
    c.ti = read_collision(s.sub("toner_roller"));
    c.td = read_collision(s.sub("toner_drum"));
    s.finish();
  }
  {
    auto s = top.sub("adhesion");
    c.adhesion_distance = s.choice("distance", {"surface", "centre"}) == "surface"
                              ? models::HamakerParams::Distance::surface : models::HamakerParams::Distance::centre;
    c.min_separation = s.number("min_separation_m", 1e-11, 1e-6);
    c.adhesion_cutoff = s.number("cutoff_m", 0.0, 1e-4);
    c.adhesion_roller_force = s.number("roller_force_N", 0.0, 1e-3);
    c.adhesion_drum_force = s.number("drum_force_N", 0.0, 1e-3);
    c.cohesion_ratio = s.number("cohesion_ratio", 0.0, 1e6);
    s.finish();
  }
  {
    auto s = top.sub("inflow");
    c.layer_thickness = s.number("layer_thickness_m", 0.0, 1e-3);
    c.area_fraction = s.number("area_fraction", 0.0, 0.85);
    c.insert_interval = static_cast<int>(s.integer("interval_steps", 1, 1000000));
    c.prefill = s.boolean("prefill");
    c.roller_pits_filled = s.choice("roller_pits", {"empty", "filled"}) == "filled";
    s.finish();
  }
  {
    auto s = top.sub("initial_assembly");
    auto& a = c.assembly;
    a.enabled = s.boolean("enabled");
    a.x_min = s.number("x_min_m", -0.05, 0.05);
    a.x_max = s.number("x_max_m", -0.05, 0.05);
    a.height = s.number("height_m", 0.0, 1e-2);
    a.area_fraction = s.number("area_fraction", 0.05, 0.75);
    s.finish();
  }
  {
    auto s = top.sub("gravity");
    auto g = s.numbers("vector_m_per_s2", 2, -1e6, 1e6);
    c.gravity = {g[0], g[1]};
    s.finish();
  }
  {
    auto s = top.sub("magnet");
    c.magnet.field = s.choice("field", {"knife", "color_pole", "map", "none"});
    c.magnet.map_file = s.string("map_file");
    if (c.magnet.field == "map" && c.magnet.map_file.empty())
      throw_input(file, "magnet.map_file", "", "field = \"map\" needs a map_file (CSV x_m,y_m,Bx_T,By_T)");
    const std::string pig = s.choice("pigment", {"black", "color"});
    c.magnet_pigment = pig;
    const magnet::MagnetisationParams p = pig == "black" ? magnet::black_toner() : magnet::color_toner();
    c.magnet.toner = p;
    c.magnet.toner.Ms_A_per_m = derived(s, "saturation_magnetisation_A_per_m", 1e-3, 1e7, p.Ms_A_per_m);
    c.magnet.toner.B_sat_T = derived(s, "saturation_flux_T", 1e-6, 10.0, p.B_sat_T);
    c.magnet.toner.eta = derived(s, "pigment_volume_fraction", 1e-6, 1.0, p.eta);
    c.magnet.dipole_dipole = s.boolean("dipole_dipole");
    c.magnet.dipole_cutoff = s.number("dipole_cutoff_m", 1e-7, 1e-3);
    c.magnet.dipole_skin = s.number("dipole_skin_m", 1e-8, 1e-4);
    c.magnet.dipole_interval = static_cast<int>(s.integer("dipole_interval_steps", 1, 100000));
    c.magnet.field_interval = static_cast<int>(s.integer("field_interval_steps", 1, 100000));
    s.finish();
  }
  {
    auto s = top.sub("electric");
    auto& e = c.electric;
    e.enabled = s.boolean("enabled");
    e.force.model = electric::parse_force_model(s.choice("model", {"exact", "series", "approx"}), file, "electric.model");
    e.force.approx_coefficient = s.number("approx_coefficient", 1e-3, 10.0);
    e.dielectric_layer = s.boolean("dielectric_layer");
    e.layer_thickness = s.number("layer_thickness_m", 0.0, 1e-4);
    e.layer_permittivity = s.number("layer_permittivity", 1.0, 1e4);
    c.charge_preset = s.choice("charge_preset", {"black", "color"});
    const auto rc = c.charge_preset == "black" ? charge::RcChargeParams::black() : charge::RcChargeParams::colour();
    e.rc = rc;
    e.rc.R_tt_ohm = derived(s, "R_tt_ohm", 1.0, 1e30, rc.R_tt_ohm);
    e.rc.R_ti_ohm = derived(s, "R_ti_ohm", 1.0, 1e30, rc.R_ti_ohm);
    e.rc.C_td_F = derived(s, "C_td_F", 1e-25, 1e-6, rc.C_td_F);
    e.rc.R_td_ohm = derived(s, "R_td_ohm", 1.0, 1e40, rc.R_td_ohm);
    e.rc.range_m = derived(s, "range_m", 1e-8, 1e-3, c.size.d50);
    e.corridor_fraction = s.number("corridor_fraction", 0.0, 0.999);
    e.path_interval = static_cast<int>(s.integer("path_interval_steps", 1, 1000000));
    s.finish();
    e.force.validate();
    e.rc.validate();
    toml::table* print = root["print"].as_table();
    top.sub("print");  // its keys are checked by the pattern parser (validate)
    if (!print) throw_input(file, "print", "", "must be a table ([print])");
    c.print = *print;
  }
  {
    auto s = top.sub("output");
    c.vtk = s.boolean("vtk");
    s.finish();
  }
  top.finish();
  return c;
}

namespace {
// Writes a number, keeping an integer node an integer while the value is integral (a file's
// `voltage_V = 40` serializes as written).
void put(toml::table& t, std::string_view key, double v) {
  const toml::node* n = t.get(key);
  if (n && n->is_integer() && std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 9.0e15)
    t.insert_or_assign(key, static_cast<std::int64_t>(v));
  else
    t.insert_or_assign(key, v);
}
void put_int(toml::table& t, std::string_view key, std::int64_t v) { t.insert_or_assign(key, v); }
void put_bool(toml::table& t, std::string_view key, bool v) { t.insert_or_assign(key, v); }
void put_str(toml::table& t, std::string_view key, const std::string& v) { t.insert_or_assign(key, v); }
toml::table& sub(toml::table& t, std::string_view key) {
  if (!t.get(key) || !t.get(key)->is_table()) t.insert_or_assign(key, toml::table{});
  return *t.get(key)->as_table();
}
void put_collision(toml::table& t, const CollisionType& c) {
  put(t, "restitution", c.restitution);
  put(t, "k_N_per_m", c.k);
  put(t, "mu_s", c.mu_s);
  put(t, "mu_d", c.mu_d);
}

// Every field under the key the reader reads it from (read_nip_config): the typed fields are
// the configuration, the table only its serialization. A test checks that writing into an
// empty table gives every key of the resolved configuration.
void write_fields(const NipConfig& c, toml::table& root) {
  put_str(root, "preset", c.preset);
  {
    auto& t = sub(root, "run");
    put_int(t, "seed", static_cast<std::int64_t>(c.seed));
    put(t, "end_time_s", c.end_time);
    put(t, "output_interval_s", c.output_interval);
    put(t, "checkpoint_interval_s", c.checkpoint_interval);
    put_int(t, "threads", c.threads);
    put_str(t, "integrator", c.integrator == engine::Integrator::velocity_verlet ? "velocity_verlet" : "newmark_explicit");
    put(t, "dt_s", c.dt);
    put(t, "dt_fraction_of_contact_time", c.dt_fraction);
    put(t, "neighbor_skin_d50", c.list_skin_d50);
  }
  {
    auto& t = sub(root, "geometry");
    put(t, "gap_m", c.gap);
    put(t, "drum_radius_m", c.drum_radius);
    put(t, "roller_radius_m", c.roller_radius);
    put(t, "drum_surface_speed_m_per_s", c.drum_speed);
    put(t, "roller_surface_speed_m_per_s", c.roller_speed);
    put(t, "nip_x_m", c.nip_x);
    put(t, "window_x_min_m", c.x_min);
    put(t, "window_x_max_m", c.x_max);
    auto& r = sub(t, "roughness");
    put_bool(r, "enabled", c.roughness);
    put(r, "height_m", c.rough_height);
    put(r, "base_m", c.rough_base);
    put(r, "spacing_m", c.rough_spacing);
  }
  {
    auto& t = sub(root, "toner");
    put(t, "d_small_m", c.size.d_small);
    put(t, "d50_m", c.size.d50);
    put(t, "d_large_m", c.size.d_large);
    put_str(t, "size_weighting", c.size.number_weighted ? "number" : "volume");
    put(t, "density_kg_per_m3", c.density);
    put_str(t, "cluster", c.cluster);
    put_str(t, "cluster_file", c.cluster_file);
  }
  {
    auto& t = sub(root, "collision");
    put(t, "stiffness_scale", c.stiffness_scale);
    put_str(t, "damping_convention", c.damping == models::DampingConvention::physical ? "physical" : "thesis");
    put_collision(sub(t, "toner_toner"), c.tt);
    put_collision(sub(t, "toner_roller"), c.ti);
    put_collision(sub(t, "toner_drum"), c.td);
  }
  {
    auto& t = sub(root, "adhesion");
    put_str(t, "distance", c.adhesion_distance == models::HamakerParams::Distance::surface ? "surface" : "centre");
    put(t, "min_separation_m", c.min_separation);
    put(t, "cutoff_m", c.adhesion_cutoff);
    put(t, "roller_force_N", c.adhesion_roller_force);
    put(t, "drum_force_N", c.adhesion_drum_force);
    put(t, "cohesion_ratio", c.cohesion_ratio);
  }
  {
    auto& t = sub(root, "inflow");
    put(t, "layer_thickness_m", c.layer_thickness);
    put(t, "area_fraction", c.area_fraction);
    put_int(t, "interval_steps", c.insert_interval);
    put_bool(t, "prefill", c.prefill);
    put_str(t, "roller_pits", c.roller_pits_filled ? "filled" : "empty");
  }
  {
    auto& t = sub(root, "initial_assembly");
    put_bool(t, "enabled", c.assembly.enabled);
    put(t, "x_min_m", c.assembly.x_min);
    put(t, "x_max_m", c.assembly.x_max);
    put(t, "height_m", c.assembly.height);
    put(t, "area_fraction", c.assembly.area_fraction);
  }
  {
    auto& t = sub(root, "gravity");
    toml::array g;
    const toml::array* old = t["vector_m_per_s2"].as_array();
    const double v[2] = {c.gravity.x, c.gravity.y};
    for (int k = 0; k < 2; ++k) {
      const bool integer = old && old->size() == 2 && (*old)[k].is_integer() && v[k] == std::floor(v[k]) && std::fabs(v[k]) < 9.0e15;
      if (integer) g.push_back(static_cast<std::int64_t>(v[k]));
      else g.push_back(v[k]);
    }
    t.insert_or_assign("vector_m_per_s2", std::move(g));
  }
  {
    auto& t = sub(root, "magnet");
    const auto& m = c.magnet;
    put_str(t, "field", m.field);
    put_str(t, "map_file", m.map_file);
    put_str(t, "pigment", c.magnet_pigment);
    put(t, "saturation_magnetisation_A_per_m", m.toner.Ms_A_per_m);
    put(t, "saturation_flux_T", m.toner.B_sat_T);
    put(t, "pigment_volume_fraction", m.toner.eta);
    put_bool(t, "dipole_dipole", m.dipole_dipole);
    put(t, "dipole_cutoff_m", m.dipole_cutoff);
    put(t, "dipole_skin_m", m.dipole_skin);
    put_int(t, "dipole_interval_steps", m.dipole_interval);
    put_int(t, "field_interval_steps", m.field_interval);
  }
  {
    auto& t = sub(root, "electric");
    const auto& e = c.electric;
    put_bool(t, "enabled", e.enabled);
    put_str(t, "model", electric::to_string(e.force.model));
    put(t, "approx_coefficient", e.force.approx_coefficient);
    put_bool(t, "dielectric_layer", e.dielectric_layer);
    put(t, "layer_thickness_m", e.layer_thickness);
    put(t, "layer_permittivity", e.layer_permittivity);
    put_str(t, "charge_preset", c.charge_preset);
    put(t, "R_tt_ohm", e.rc.R_tt_ohm);
    put(t, "R_ti_ohm", e.rc.R_ti_ohm);
    put(t, "C_td_F", e.rc.C_td_F);
    put(t, "R_td_ohm", e.rc.R_td_ohm);
    put(t, "range_m", e.rc.range_m);
    put(t, "corridor_fraction", e.corridor_fraction);
    put_int(t, "path_interval_steps", e.path_interval);
  }
  root.insert_or_assign("print", c.print);
  put_bool(sub(root, "output"), "vtk", c.vtk);
}
}  // namespace

void validate(NipConfig& c) {
  const std::string& file = c.file;
  {
    auto& e = c.electric;
    e.pattern = io::pattern_from_toml(c.print, file, std::filesystem::path(file).parent_path());
    if (e.enabled && !c.print_given) throw_input(file, "print", "", "[electric] enabled = true needs a [print] table (e.g. pattern = \"line\")");
    e.drum_speed = c.drum_speed;
    e.drum_centre = {c.nip_x, c.gap + c.drum_radius};
    e.drum_radius = c.drum_radius;
  }
  if (c.magnet.field != "none") make_magnet_field(c.magnet);  // reject a bad map now, naming the file

  // Cross-checks.
  if (c.gap <= c.size.d_max())
    throw_input(file, "geometry.gap_m", fmt::format("{:g}", c.gap), "gap smaller than the largest particle",
                fmt::format("> {:g} (toner d_max = d50 + 3 sigma)", c.size.d_max()));
  if (c.roughness && c.rough_height >= c.gap)
    throw_input(file, "geometry.roughness.height_m", fmt::format("{:g}", c.rough_height), "roughness deeper than the gap", fmt::format("< gap_m = {:g}", c.gap));
  if (c.layer_thickness > c.gap)
    throw_input(file, "inflow.layer_thickness_m", fmt::format("{:g}", c.layer_thickness), "layer thicker than the gap", fmt::format("[0, {:g}]", c.gap));
  if (c.x_max - c.nip_x > 0.5 * std::min(c.drum_radius, c.roller_radius) || c.nip_x - c.x_min > 0.5 * std::min(c.drum_radius, c.roller_radius))
    throw_input(file, "geometry.window_x_max_m", fmt::format("{:g}", c.x_max), "window reaches beyond half a roller radius from the nip");
  if (c.assembly.enabled) {
    if (!(c.assembly.x_max > c.assembly.x_min))
      throw_input(file, "initial_assembly.x_max_m", fmt::format("{:g}", c.assembly.x_max), "must exceed initial_assembly.x_min_m",
                  fmt::format("> {:g}", c.assembly.x_min));
    if (c.assembly.x_min < c.x_min || c.assembly.x_max > c.x_max)
      throw_input(file, "initial_assembly.x_min_m", fmt::format("[{:g}, {:g}]", c.assembly.x_min, c.assembly.x_max), "assembly outside the window",
                  fmt::format("within [{:g}, {:g}]", c.x_min, c.x_max));
  }
  {
    // config.toml of a run folder must work from there: file names become absolute (a pattern
    // file is relative to the config's folder, a cluster or map file to the working folder).
    // The resume key keeps the names as given.
    write_fields(c, c.table);
    toml::table resolved = c.table;
    auto absolute = [](toml::table* t, const char* key, const std::filesystem::path& base) {
      if (!t) return;
      const auto v = (*t)[key].value<std::string>();
      if (!v || v->empty() || std::filesystem::path(*v).is_absolute()) return;
      t->insert_or_assign(key, std::filesystem::absolute(base / *v).lexically_normal().string());
    };
    absolute(resolved["toner"].as_table(), "cluster_file", "");
    absolute(resolved["magnet"].as_table(), "map_file", "");
    absolute(resolved["print"].as_table(), "file", std::filesystem::path(file).parent_path());
    std::ostringstream ss;
    ss << "# Complete resolved configuration (preset + file + --set): `nipdem run THIS_FILE --out DIR` repeats the run.\n"
       << resolved << "\n";
    c.resolved_toml = ss.str();
  }
  // A resumed run may extend the end time and change the output cadence; nothing else
  // (e.g. the thread count changes the floating-point summation order).
  toml::table root = c.table;
  if (auto* run = root["run"].as_table()) {
    run->erase("end_time_s");
    run->erase("output_interval_s");
    run->erase("checkpoint_interval_s");
  }
  std::ostringstream rk;
  rk << root;
  c.resume_key = rk.str();
  if (auto* print = root["print"].as_table()) print->erase("voltage_V");
  std::ostringstream pk;
  pk << root;
  c.prefix_key = pk.str();
  check_resource_bounds(c, choose_time_step(c));  // refuses a time step above the stability bound
}

NipConfig parse_nip_config(const std::string& text, const std::string& file, const std::vector<std::string>& overrides) {
  NipConfig c = read_nip_config(text, file, overrides);
  validate(c);
  return c;
}

NipConfig load_nip_config(const std::string& path, const std::vector<std::string>& overrides) {
  return parse_nip_config(io::read_file(path), path, overrides);
}

void set_print_line(NipConfig& c, double start_m, double length_m, std::optional<double> voltage_V) {
  c.electric.enabled = true;
  c.print_given = true;
  c.print.insert_or_assign("pattern", "line");
  if (voltage_V) c.print.insert_or_assign("voltage_V", *voltage_V);
  c.print.insert_or_assign("start_m", start_m);
  c.print.insert_or_assign("length_m", length_m);
}

double toner_mass(const NipConfig& c, double d) { return c.density * pi * d * d * d / 6.0; }

std::vector<engine::Interaction> make_interactions(const NipConfig& c) {
  const double m50 = toner_mass(c, c.size.d50);
  models::HamakerParams base;
  base.distance = c.adhesion_distance;
  base.min_separation_m = c.min_separation;
  base.cutoff_m = c.adhesion_cutoff;
  const double r50 = 0.5 * c.size.d50;
  auto make = [&](const char* name, const CollisionType& t, double mred, double adh_force, bool wall) {
    engine::Interaction ia;
    ia.name = name;
    ia.contact = models::contact_params(t.k * c.stiffness_scale, t.restitution, mred, t.mu_s, t.mu_d, c.damping);
    ia.adhesion = base;
    // Hamaker coefficient from the force of a d50 toner at contact (eq. 2.3.2 inverted).
    ia.adhesion.hamaker_J = adh_force > 0.0 ? models::hamaker_for_contact_force(base, r50, wall ? kInf : r50, adh_force) : 0.0;
    return ia;
  };
  return {make("toner_toner", c.tt, m50 / 2, c.cohesion_ratio * c.adhesion_roller_force, false),
          make("toner_roller", c.ti, m50, c.adhesion_roller_force, true),
          make("toner_drum", c.td, m50, c.adhesion_drum_force, true)};
}

std::vector<CollisionReport> collision_report(const NipConfig& c) {
  const auto ia = make_interactions(c);
  const double m50 = toner_mass(c, c.size.d50);
  const CollisionType* types[3] = {&c.tt, &c.ti, &c.td};
  std::vector<CollisionReport> out;
  for (int i = 0; i < 3; ++i) {
    const double m = i == 0 ? m50 / 2 : m50;
    const auto& cp = ia[i].contact;
    out.push_back({ia[i].name, cp.k, cp.gamma, cp.ks, types[i]->restitution, models::contact_time(cp.k, cp.gamma, m),
                   models::newmark_dt_max(cp.k, cp.gamma, m), models::verlet_dt_max(cp.k, cp.gamma, m), m,
                   models::gamma_from_restitution(cp.k, m, types[i]->restitution, models::DampingConvention::thesis)});
  }
  return out;
}

nlohmann::json collision_json(const NipConfig& c) {
  const auto ts = choose_time_step(c);
  nlohmann::json j;
  for (const auto& r : collision_report(c)) {
    j[r.name] = {{"k_N_per_m", r.k}, {"gamma_Ns_per_m", r.gamma}, {"ks_N_per_m", r.ks}, {"restitution", r.restitution},
                 {"contact_time_s", r.contact_time}, {"dt_max_s", r.dt_max_newmark}, {"dt_max_verlet_s", r.dt_max_verlet},
                 {"gamma_thesis_convention_Ns_per_m", r.gamma_thesis}, {"reduced_mass_kg", r.m_red}};
  }
  j["stiffness_scale"] = c.stiffness_scale;
  j["dt_s"] = ts.dt;
  j["dt_bound_s"] = ts.bound;
  j["dt_limited_by"] = ts.limiting;
  return j;
}

TimeStep choose_time_step(const NipConfig& c) {
  const auto ia = make_interactions(c);
  // Smallest body: the smallest particle the size distribution can produce, with the
  // rotational coupling of the cluster (effective mass at a contact point off the centre).
  const ClusterTemplate& t = find_template(c.templates, c.cluster, c.file, "toner.cluster");
  const double dmin = c.size.d_min();
  const engine::BodySpec b = make_toner(t, dmin, c.density);
  const engine::MassProperties mp = engine::mass_properties(b);  // the engine's own mass and inertia
  const double m = mp.mass, I = mp.inertia;
  double lever = 0, rmax = 0;
  for (std::size_t k = 0; k < b.radii.size(); ++k) {
    lever = std::max(lever, norm(b.offsets[k] - mp.com));
    rmax = std::max(rmax, norm(b.offsets[k] - mp.com) + b.radii[k]);
  }
  const double m_n = 1.0 / (1.0 / m + lever * lever / I);  // normal direction, worst case
  const double m_t = 1.0 / (1.0 / m + rmax * rmax / I);    // tangential direction, worst case
  TimeStep ts{0.0, kInf, ""};
  double tmin = kInf;
  for (int i = 0; i < 3; ++i) {
    const double mn = i == 0 ? m_n / 2 : m_n, mt = i == 0 ? m_t / 2 : m_t;
    const auto& cp = ia[i].contact;
    tmin = std::min(tmin, models::contact_time(cp.k, cp.gamma, mn));
    double bound;
    if (c.integrator == engine::Integrator::newmark_explicit) {
      bound = models::newmark_dt_max(cp.k, cp.gamma, mn);  // eq. 4.2.25
    } else {
      // the stiffer of the normal and the tangential mode
      const double kn_over_m = std::max(cp.k / mn, cp.ks / mt);
      bound = models::verlet_dt_max(kn_over_m * mn, cp.gamma, mn);
    }
    if (bound < ts.bound) { ts.bound = bound; ts.limiting = ia[i].name; }
  }
  ts.dt = c.dt > 0.0 ? c.dt : c.dt_fraction * tmin;
  // A step far below the contact time resolves nothing more and never ends (issue 21): the same
  // lower limit as run.dt_fraction_of_contact_time.
  if (c.dt > 0.0 && c.dt < 1e-4 * tmin)
    throw_input(c.file, "run.dt_s", fmt::format("{:g}", c.dt),
                fmt::format("time step below 1e-4 of the shortest contact time ({:.3g} s): the run would take forever", tmin),
                fmt::format("[{:.4g}, {:.4g}] s", 1e-4 * tmin, ts.bound));
  if (ts.dt > ts.bound)
    throw_input(c.file, c.dt > 0.0 ? "run.dt_s" : "run.dt_fraction_of_contact_time", fmt::format("{:g}", c.dt > 0 ? c.dt : c.dt_fraction),
                fmt::format("time step {:.3g} s exceeds the stability bound of the {} integrator, set by the {} contact "
                            "of the smallest particle (d = {:.3g} m)",
                            ts.dt, c.integrator == engine::Integrator::newmark_explicit ? "Newmark explicit" : "velocity Verlet",
                            ts.limiting, dmin),
                fmt::format("dt_s <= {:.4g}", ts.bound));
  return ts;
}

namespace {
// Bounds for what a run may cost (issue 21, docs/reliability.md): at least one step, output and
// checkpoint intervals not below the step, and the particles the window can hold within the
// machine's memory, all refused before anything is allocated.
void check_resource_bounds(const NipConfig& c, const TimeStep& ts) {
  const std::string range_dt = fmt::format("[dt = {:.4g} s, 10 s]", ts.dt);
  if (c.end_time < ts.dt)
    throw_input(c.file, "run.end_time_s", fmt::format("{:g}", c.end_time), "end time below one time step: nothing would run", range_dt);
  if (c.output_interval < ts.dt)
    throw_input(c.file, "run.output_interval_s", fmt::format("{:g}", c.output_interval), "output interval below the time step", range_dt);
  if (c.checkpoint_interval < ts.dt)
    throw_input(c.file, "run.checkpoint_interval_s", fmt::format("{:g}", c.checkpoint_interval), "checkpoint interval below the time step", range_dt);
  // Upper bound of the particle count: the window between the two surfaces (their sag at the
  // window's ends and the pits included) filled with the smallest particles at 90 % area fraction.
  const double w = std::max(std::fabs(c.x_min - c.nip_x), std::fabs(c.x_max - c.nip_x));
  const double height = c.gap + (c.roughness ? c.rough_height : 0.0) + w * w / (2.0 * c.drum_radius) + w * w / (2.0 * c.roller_radius);
  const double dmin = c.size.d_min();
  const double n_max = 0.9 * (c.x_max - c.x_min) * height / (pi * dmin * dmin / 4.0);
  constexpr double kBytesPerParticle = 4096.0;  // bodies, their discs, histories, lists, output (measured ~2 kB)
  const double bytes = n_max * kBytesPerParticle;
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  const double ram = pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 64.0 * (1ull << 30);
  if (bytes > ram)
    throw_input(c.file, "geometry.window_x_min_m, geometry.window_x_max_m, geometry.gap_m",
                fmt::format("window [{:g}, {:g}] m, gap {:g} m", c.x_min, c.x_max, c.gap),
                fmt::format("the window can hold up to {:.3g} particles of d = {:.3g} m, about {:.3g} GiB, more than this "
                            "machine's memory ({:.3g} GiB)", n_max, dmin, bytes / (1ull << 30), ram / (1ull << 30)),
                fmt::format("a window holding at most {:.3g} particles", ram / kBytesPerParticle));
  // Output volume: a warning (the user may mean it), with the numbers.
  const double frames = c.end_time / c.output_interval;
  if (c.vtk && frames * n_max * 200.0 > 50.0 * (1ull << 30))
    std::fprintf(stderr, "nipdem: warning: %s: run.output_interval_s = %g gives %.3g frames of up to %.3g particles: up to %.3g GiB of "
                         "particle output\n", c.file.c_str(), c.output_interval, frames, n_max, frames * n_max * 200.0 / (1ull << 30));
}
}  // namespace

}  // namespace nipdem::nip
