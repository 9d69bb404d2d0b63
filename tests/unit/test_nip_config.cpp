// One source of defaults (issue 19): the preset is the base of every nip config, the loader and
// NipConfig hold no competing defaults, and a run folder's config.toml is the complete resolved
// configuration, so running it again repeats the run.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "../cli_run.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/nip/nip_config.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/toml_reader.hpp"
#include "nipdem/models/hamaker.hpp"

using namespace nipdem;
using namespace nipdem::nip;
namespace fs = std::filesystem;

namespace {
void leaf_keys(const toml::table& t, const std::string& prefix, std::set<std::string>& out) {
  for (const auto& [k, v] : t) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = v.as_table()) leaf_keys(*sub, key, out);
    else out.insert(key);
  }
}
std::set<std::string> leaf_keys(const std::string& toml_text) {
  std::set<std::string> out;
  leaf_keys(io::parse_toml(toml_text, "test"), "", out);
  return out;
}
// Values the loader derives from other keys (not in the preset, recorded in config.toml).
const std::set<std::string> kDerived = {
    "magnet.saturation_magnetisation_A_per_m", "magnet.saturation_flux_T", "magnet.pigment_volume_fraction",
    "electric.R_tt_ohm", "electric.R_ti_ohm", "electric.C_td_F", "electric.R_td_ohm", "electric.range_m"};
}  // namespace

TEST(NipConfigDefaults, EveryKeyTheLoaderReadsIsInThePresetOrDerived) {
  // The loader has no fallback for a preset key: parsing the preset works only because the
  // preset holds every key (a key missing from it is "missing required key"), and the
  // resolved table has exactly the preset's keys plus the derived ones.
  for (const auto& p : preset_names()) {
    SCOPED_TRACE(p);
    const NipConfig c = parse_nip_config(preset_text(p), "preset:" + p);
    EXPECT_EQ(c.preset, p);
    std::set<std::string> expected = leaf_keys(preset_text(p));
    expected.insert(kDerived.begin(), kDerived.end());
    EXPECT_EQ(leaf_keys(c.resolved_toml), expected);
    // each preset key omitted from a config comes back from the preset, not from code
    for (const auto& key : leaf_keys(preset_text(p))) {
      if (key == "preset") continue;
      toml::table t = io::parse_toml(preset_text(p), "preset:" + p);
      const auto dot = key.rfind('.');
      toml::table* parent = dot == std::string::npos ? &t : t.at_path(key.substr(0, dot)).as_table();
      ASSERT_NE(parent, nullptr) << key;
      parent->erase(key.substr(dot + 1));
      std::ostringstream ss;
      ss << t;
      EXPECT_EQ(parse_nip_config(ss.str(), "omit").resolved_toml, c.resolved_toml) << "omitting " << key;
    }
  }
}

TEST(NipConfigDefaults, AnEmptyFileIsTheBlackPresetAndPresetSelectsTheBase) {
  EXPECT_EQ(parse_nip_config("", "empty.toml").resolved_toml, parse_nip_config(preset_text("black"), "b").resolved_toml);
  EXPECT_EQ(parse_nip_config("preset = \"color\"\n", "c.toml").resolved_toml,
            parse_nip_config(preset_text("color"), "c").resolved_toml);
  EXPECT_EQ(parse_nip_config("", "e.toml", {"preset=\"color\""}).preset, "color");
  try {
    parse_nip_config("preset = \"magenta\"\n", "bad.toml");
    FAIL() << "unknown preset accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("bad.toml"), std::string::npos) << m;
    EXPECT_NE(m.find("preset"), std::string::npos) << m;
    EXPECT_NE(m.find("black, color"), std::string::npos) << m;
  }
}

TEST(NipConfigDefaults, OmittedKeysTakeThePresetValues) {
  // The values issue 19 found disagreeing: the former struct defaults (drum 0.02 m, roller
  // 0.05 m, empty pits, 1 ms) against the preset (drum 0.05 m from 6.7 m/min at 2.23 rad/s,
  // roller 0.02 m from 30 m/min at 25 rad/s, thesis §4.1; filled pits; 2 ms).
  const NipConfig c = parse_nip_config("[run]\nseed = 3\n", "partial.toml");
  EXPECT_EQ(c.drum_radius, 0.05);
  EXPECT_EQ(c.roller_radius, 0.02);
  EXPECT_TRUE(c.roller_pits_filled);
  EXPECT_EQ(c.end_time, 2e-3);
  EXPECT_EQ(c.seed, 3u);
  const NipConfig col = parse_nip_config("preset = \"color\"\n", "partial.toml");
  EXPECT_EQ(col.size.d50, 12e-6);
  EXPECT_EQ(col.magnet.field, "color_pole");
  EXPECT_EQ(col.electric.rc.range_m, 12e-6);  // derived: d50 of the colour toner
}

TEST(NipConfigDefaults, StructDefaultsThatRemainEqualTheBlackPreset) {
  // NipConfig has no member defaults (value-initialised); the sub-structs that code builds
  // without a config keep theirs, and they must be the black preset's.
  const NipConfig z{};
  EXPECT_EQ(z.drum_radius, 0.0);
  EXPECT_EQ(z.roller_radius, 0.0);
  EXPECT_EQ(z.gap, 0.0);
  EXPECT_EQ(z.end_time, 0.0);
  EXPECT_FALSE(z.roller_pits_filled);
  EXPECT_EQ(z.tt.restitution, 0.0);

  const NipConfig b = parse_nip_config(preset_text("black"), "preset:black");
  const SizeDistribution s{};
  EXPECT_EQ(s.d_small, b.size.d_small);
  EXPECT_EQ(s.d50, b.size.d50);
  EXPECT_EQ(s.d_large, b.size.d_large);
  EXPECT_EQ(s.number_weighted, b.size.number_weighted);
  const MagnetConfig m{};
  EXPECT_EQ(m.field, b.magnet.field);
  EXPECT_EQ(m.map_file, b.magnet.map_file);
  EXPECT_EQ(m.toner.Ms_A_per_m, b.magnet.toner.Ms_A_per_m);
  EXPECT_EQ(m.toner.B_sat_T, b.magnet.toner.B_sat_T);
  EXPECT_EQ(m.toner.eta, b.magnet.toner.eta);
  EXPECT_EQ(m.dipole_dipole, b.magnet.dipole_dipole);
  EXPECT_EQ(m.dipole_cutoff, b.magnet.dipole_cutoff);
  EXPECT_EQ(m.dipole_interval, b.magnet.dipole_interval);
  EXPECT_EQ(m.dipole_skin, b.magnet.dipole_skin);
  EXPECT_EQ(m.field_interval, b.magnet.field_interval);
  const ElectricConfig e{};
  EXPECT_EQ(e.enabled, b.electric.enabled);
  EXPECT_EQ(e.force.model, b.electric.force.model);
  EXPECT_EQ(e.force.approx_coefficient, b.electric.force.approx_coefficient);
  EXPECT_EQ(e.dielectric_layer, b.electric.dielectric_layer);
  EXPECT_EQ(e.layer_thickness, b.electric.layer_thickness);
  EXPECT_EQ(e.layer_permittivity, b.electric.layer_permittivity);
  EXPECT_EQ(e.rc.R_tt_ohm, b.electric.rc.R_tt_ohm);
  EXPECT_EQ(e.rc.R_ti_ohm, b.electric.rc.R_ti_ohm);
  EXPECT_EQ(e.rc.C_td_F, b.electric.rc.C_td_F);
  EXPECT_EQ(e.rc.R_td_ohm, b.electric.rc.R_td_ohm);
  EXPECT_EQ(e.corridor_fraction, b.electric.corridor_fraction);
  EXPECT_EQ(e.path_interval, b.electric.path_interval);
}

TEST(NipConfigDefaults, ResolvedConfigurationIsAFixedPoint) {
  // Reading a resolved configuration gives the same configuration and the same resume key,
  // also for configs with --set overrides, a colour base and a print pattern.
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {preset_text("black"), {}},
      {"preset = \"color\"\n[geometry]\nwindow_x_min_m = -3e-4\n", {"collision.stiffness_scale=0.01"}},
      {"[electric]\nenabled = true\nR_tt_ohm = 2e10\n[print]\npattern = \"line\"\nstart_m = 1e-4\nlength_m = 1.5e-4\n", {"print.voltage_V=35"}},
  };
  for (const auto& [text, sets] : cases) {
    const NipConfig a = parse_nip_config(text, "a.toml", sets);
    const NipConfig b = parse_nip_config(a.resolved_toml, "b.toml");
    EXPECT_EQ(a.resolved_toml, b.resolved_toml);
    EXPECT_EQ(a.resume_key, b.resume_key);
    EXPECT_EQ(a.prefix_key, b.prefix_key);
  }
}

TEST(NipConfigDefaults, RerunningARunFoldersConfigReproducesItsSummary) {
  // `nipdem run RUN/config.toml --out OTHER` of a finished run repeats it: the same summary
  // (all physics fields; wall times, paths and the version stamp excluded).
  const fs::path d = fs::temp_directory_path() / ("nipdem_rerun_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string ex = std::string(NIPDEM_SOURCE_DIR) + "/examples/nip_black_small.toml";
  auto a = test::run_cli("run " + ex + " --out " + (d / "a").string() +
                             " --quiet --set run.end_time_s=1e-4 --set output.vtk=false --set geometry.window_x_min_m=-150e-6"
                             " --set geometry.window_x_max_m=150e-6",
                         "rerun");
  ASSERT_EQ(a.status, 0) << a.err;
  auto b = test::run_cli("run " + (d / "a" / "config.toml").string() + " --out " + (d / "b").string() + " --quiet", "rerun");
  ASSERT_EQ(b.status, 0) << b.err;
  auto sa = nlohmann::json::parse(io::read_file(d / "a" / "summary.json"));
  auto sb = nlohmann::json::parse(io::read_file(d / "b" / "summary.json"));
  EXPECT_GT(sa["steps"].get<long long>(), 100);
  EXPECT_GT(sa["particles_in_window"].get<long long>(), 10);
  for (auto* s : {&sa, &sb})
    for (const char* k : {"config_file", "wall_time_s", "disc_steps_per_s", "wall_s_per_simulated_ms", "nipdem_version", "git_hash"})
      s->erase(k);
  EXPECT_EQ(sa.dump(1), sb.dump(1));
  // the run folder's config is complete: it names every key of the preset it was laid over
  const auto keys = leaf_keys(io::read_file(d / "a" / "config.toml"));
  for (const auto& k : leaf_keys(preset_text("black"))) EXPECT_TRUE(keys.count(k)) << k;
  EXPECT_EQ(io::read_file(d / "a" / "timeseries.csv"), io::read_file(d / "b" / "timeseries.csv"));
  fs::remove_all(d);
}

TEST(NipInteractions, TangentialSpringIsTwoSeventhsAndCohesionIsRTimesAdhesion) {
  // eq. 4.3.11 (ks = 2k/7) and eq. 4.6.1 (F_coh = r F_adh for two d50 toners at contact).
  const NipConfig c = parse_nip_config("", "e.toml", {"adhesion.cohesion_ratio=3", "collision.stiffness_scale=0.5"});
  const auto ia = make_interactions(c);
  ASSERT_EQ(ia.size(), 3u);
  EXPECT_DOUBLE_EQ(ia[0].contact.k, 0.5 * 56);
  for (const auto& i : ia) EXPECT_DOUBLE_EQ(i.contact.ks, 2.0 * i.contact.k / 7.0) << i.name;
  const double r50 = 0.5 * c.size.d50;
  const double f_coh = std::fabs(models::hamaker_force(ia[0].adhesion, r50, r50, 0.0));
  const double f_adh = std::fabs(models::hamaker_force(ia[1].adhesion, r50, std::numeric_limits<double>::infinity(), 0.0));
  EXPECT_NEAR(f_adh, c.adhesion_roller_force, 1e-12 * c.adhesion_roller_force);
  EXPECT_NEAR(f_coh / f_adh, 3.0, 1e-9);
}

namespace {
// Leaf values of two resolved configurations, numbers compared as numbers (1 == 1.0).
void expect_same_leaves(const toml::table& a, const toml::table& b, const std::string& prefix = "") {
  std::set<std::string> ka, kb;
  for (const auto& [k, v] : a) ka.insert(std::string(k.str()));
  for (const auto& [k, v] : b) kb.insert(std::string(k.str()));
  EXPECT_EQ(ka, kb) << "in [" << prefix << "]";
  for (const auto& k : ka) {
    if (!kb.count(k)) continue;
    const toml::node& va = *a.get(k);
    const toml::node& vb = *b.get(k);
    const std::string key = prefix.empty() ? k : prefix + "." + k;
    if (va.is_table() && vb.is_table()) {
      expect_same_leaves(*va.as_table(), *vb.as_table(), key);
    } else if (va.value<double>() && vb.value<double>() && !va.is_boolean()) {
      EXPECT_EQ(*va.value<double>(), *vb.value<double>()) << key;
    } else {
      std::ostringstream sa, sb;
      sa << toml::node_view<const toml::node>(&va);
      sb << toml::node_view<const toml::node>(&vb);
      EXPECT_EQ(sa.str(), sb.str()) << key;
    }
  }
}
}  // namespace

TEST(NipConfigTyped, TheFieldsAloneGiveTheWholeResolvedConfiguration) {
  // validate() writes every field into the table: a configuration whose table is emptied still
  // serializes every key with the same value (no key lives only in the table).
  for (const auto& p : preset_names()) {
    SCOPED_TRACE(p);
    const NipConfig a = parse_nip_config(preset_text(p), "preset:" + p, {"electric.enabled=true", "print.pattern=\"line\"",
                                                                          "print.start_m=1e-4", "print.length_m=2e-4"});
    NipConfig b = a;
    b.table = toml::table{};
    validate(b);
    expect_same_leaves(io::parse_toml(b.resolved_toml, "b"), io::parse_toml(a.resolved_toml, "a"));
  }
}

TEST(NipConfigTyped, EditingFieldsEqualsTheSameOverrides) {
  // What an experiment does to a point (typed edits + validate) gives the configuration, the
  // resume key and the print-prefix key that the same values as --set overrides give.
  const std::string text = preset_text("color");
  const NipConfig base = read_nip_config(text, "preset:color", {"collision.stiffness_scale=0.01"});
  NipConfig c = base;
  c.gap = 1.2e-4;
  c.roller_speed = 0.25;
  c.cohesion_ratio = 2.5;
  c.roller_pits_filled = false;
  c.x_min = -2.5e-4;
  c.x_max = 2.5e-4;
  c.vtk = false;
  c.seed = 7;
  set_print_line(c, 1e-5, 2e-5, 35.5);
  validate(c);
  const NipConfig s = parse_nip_config(
      text, "preset:color",
      {"collision.stiffness_scale=0.01", "geometry.gap_m=1.2e-4", "geometry.roller_surface_speed_m_per_s=0.25",
       "adhesion.cohesion_ratio=2.5", "inflow.roller_pits=\"empty\"", "geometry.window_x_min_m=-2.5e-4", "geometry.window_x_max_m=2.5e-4",
       "output.vtk=false", "run.seed=7", "electric.enabled=true", "print.pattern=\"line\"", "print.start_m=1e-5", "print.length_m=2e-5",
       "print.voltage_V=35.5"});
  EXPECT_EQ(c.resolved_toml, s.resolved_toml);
  EXPECT_EQ(c.resume_key, s.resume_key);
  EXPECT_EQ(c.prefix_key, s.prefix_key);
  ASSERT_EQ(c.electric.pattern.segments().size(), 1u);
  EXPECT_EQ(c.electric.pattern.segments()[0].voltage_V, 35.5);
  EXPECT_EQ(c.electric.drum_centre.y, c.gap + c.drum_radius);  // derived from the edited gap
  // the base is untouched, and its own validation still gives the unedited configuration
  NipConfig b = base;
  validate(b);
  EXPECT_EQ(b.resolved_toml, parse_nip_config(text, "preset:color", {"collision.stiffness_scale=0.01"}).resolved_toml);
  EXPECT_NE(b.resume_key, c.resume_key);
}

TEST(NipConfigTyped, ValidateChecksAnEditedConfiguration) {
  NipConfig c = read_nip_config(preset_text("black"), "preset:black");
  c.gap = 0.5 * c.size.d_max();
  try {
    validate(c);
    FAIL() << "a gap below the largest particle passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("geometry.gap_m"), std::string::npos) << e.what();
  }
  NipConfig d = read_nip_config("", "empty.toml");  // the black preset, no [print] of its own
  d.electric.enabled = true;
  EXPECT_THROW(validate(d), InputError);
  set_print_line(d, 0.0, 1e-4);
  EXPECT_NO_THROW(validate(d));
  EXPECT_EQ(d.electric.pattern.segments().size(), 1u);
}

// fuzz_config found `run.seed = -2e291`: toml++'s value<int64_t>() converts a float node, which
// is undefined for |x| >= 2^63. Every integer key must be refused by type before any conversion.
TEST(NipConfigIntegers, FloatsForIntegerKeysAreRefusedByTypeWhateverTheirSize) {
  for (const std::string v : {"-2e291", "1e300", "9.3e18", "-inf", "nan", "1.0"}) {
    for (const std::string key : {"seed", "threads"}) {
      const std::string text = "[run]\n" + key + " = " + v + "\n";
      try {
        parse_nip_config(text, "f.toml");
        ADD_FAILURE() << "accepted " << text;
      } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("f.toml"), std::string::npos) << m;
        EXPECT_NE(m.find("run." + key), std::string::npos) << m;
        EXPECT_NE(m.find("must be an integer"), std::string::npos) << m;
      }
    }
  }
}
