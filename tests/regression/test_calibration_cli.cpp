// Chapter-4 calibration commands and experiment front-force at the CLI level: each runs on its
// shipped example (examples/calibration/, synthetic) with --json and writes its CSV, plot and
// JSON; bad CSV input exits 2 naming the file and the line.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "../cli_run.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace {
using Res = nipdem::test::CliResult;
Res cli(const std::string& args) { return nipdem::test::run_cli(args, "cal"); }
const std::string kEx = std::string(NIPDEM_SOURCE_DIR) + "/examples/calibration/";
fs::path fresh(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_cal_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
}  // namespace

TEST(CalibrationCli, ExamplesRunAndWriteTheirFiles) {
  const fs::path d = fresh("run");
  struct C { std::string args, name; std::vector<std::string> keys, files; };
  const std::vector<C> cases = {
      {"calibrate friction --data " + kEx + "friction_plate.csv", "friction", {"mu_s", "mu_s_std", "mu_d", "mu_d_std"},
       {"friction.csv", "friction_peaks.csv", "friction.png", "friction.json"}},
      {"calibrate friction --setup capstan --weight-mass-kg 0.1 --data " + kEx + "friction_capstan.csv", "friction",
       {"mu_s", "mu_d", "hanging_force_N"}, {"friction.csv", "friction.png"}},
      {"calibrate adhesion --data " + kEx + "adhesion_centrifugal.csv --particle-mass-kg 1.3e-12 --rotor-radius-m 0.05 "
       "--initial-count 1000", "adhesion", {"median_N", "median_interval_N", "sigma_ln", "config", "config_interval_N"},
       {"adhesion.csv", "adhesion.png", "adhesion.json"}},
      {"calibrate adhesion --method afm --substrate roller --data " + kEx + "adhesion_afm.csv", "adhesion",
       {"median_N", "config"}, {"adhesion.csv", "adhesion.png"}},
      {"calibrate magnetisation --data " + kEx + "vsm_black.csv", "magnetisation",
       {"saturation_magnetisation_A_per_m", "saturation_flux_T", "saturation_flux_std_T", "config"},
       {"magnetisation.csv", "magnetisation.png", "magnetisation.json"}},
      {"experiment front-force --preset black --dx 50e-6", "front_force",
       {"l_cross_max_exact_m", "l_cross_max_printed_m", "voltage_V", "gap_m"},
       {"front_force.csv", "front_force_map.csv", "front_force.png", "front_force_map.png", "front_force_crossing.png"}}};
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const C& c = cases[k];
    SCOPED_TRACE(c.args);
    const fs::path out = d / std::to_string(k);
    const Res r = cli(c.args + " --json --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);  // --json: one object on stdout, nothing else
    for (const auto& key : c.keys) EXPECT_TRUE(j.contains(key)) << key;
    for (const auto& f : c.files) EXPECT_TRUE(fs::exists(out / f)) << f;
    EXPECT_TRUE(fs::exists(out / (c.name + ".json")));
  }
  // The AFM roller run names the roller key; the friction plate example gives back its mu_d.
  const auto a = nlohmann::json::parse(nipdem::io::read_file(d / "3" / "adhesion.json"));
  EXPECT_TRUE(a["config"].contains("adhesion.roller_force_N"));
  const auto f = nlohmann::json::parse(nipdem::io::read_file(d / "0" / "friction.json"));
  EXPECT_NEAR(f["mu_d"].get<double>(), 0.19, 3 * f["mu_d_std"].get<double>());  // 3 standard errors
  fs::remove_all(d);
}

TEST(CalibrationCli, BadCsvExitsTwoNamingFileAndLine) {
  const fs::path d = fresh("bad");
  auto write = [&](const std::string& name, const std::string& text) {
    nipdem::io::write_file_atomic(d / name, text);
    return (d / name).string();
  };
  const std::string cen = " --particle-mass-kg 1e-12 --rotor-radius-m 0.05 --initial-count 100";
  struct C { std::string cmd, file, text, needle; };
  const std::vector<C> cases = {
      // missing column: the header line
      {"calibrate friction --data ", "f1.csv", "x_m,F_N\n0,1\n1,1\n", "f1.csv:1"},
      // NaN on line 3
      {"calibrate friction --data ", "f2.csv", "x_m,force_N\n0,1\n1e-3,nan\n", "f2.csv:3"},
      // unsorted x on line 4
      {"calibrate friction --data ", "f3.csv", "x_m,force_N\n0,1\n2e-3,1\n1e-3,1\n3e-3,1\n4e-3,1\n5e-3,1\n6e-3,1\n7e-3,1\n",
       "f3.csv:4"},
      // empty file
      {"calibrate friction --data ", "f4.csv", "", "f4.csv"},
      // one row
      {"calibrate friction --data ", "f5.csv", "x_m,force_N\n0,1\n", "last data line 2"},
      {"calibrate adhesion" + cen + " --data ", "a1.csv", "omega_rad_per_s,fraction_remaining\n100,0.9\n50,0.5\n200,0.1\n",
       "a1.csv:3"},  // omega goes back on line 3
      {"calibrate adhesion" + cen + " --data ", "a2.csv", "omega_rad_per_s,fraction_remaining\n100,0.9\n200,1.5\n300,0.1\n",
       "a2.csv:3"},  // fraction above 1
      {"calibrate adhesion --method afm --data ", "a3.csv", "force_N\n1e-9\n", "a3.csv"},  // one row
      {"calibrate adhesion --method afm --data ", "a4.csv", "force_N\n1e-9\n-2e-9\n3e-9\n", "a4.csv:3"},  // negative
      {"calibrate magnetisation --data ", "m1.csv", "H_A_per_m,M_A_per_m\n0,0\n1e5,inf\n2e5,1\n3e5,1\n", "m1.csv:3"},
      {"calibrate magnetisation --data ", "m2.csv", "H,M_A_per_m\n0,0\n", "m2.csv:1"},
      {"calibrate magnetisation --data ", "m3.csv", "# only a comment\n", "m3.csv"}};
  for (const C& c : cases) {
    SCOPED_TRACE(c.file + ": " + c.text);
    const Res r = cli(c.cmd + write(c.file, c.text) + " --out " + (d / "out").string());
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  // A missing file and bad options exit 2 too, naming what is wrong.
  for (const auto& [args, needle] : std::vector<std::pair<std::string, std::string>>{
           {"calibrate friction --data " + (d / "nope.csv").string(), "nope.csv"},
           {"calibrate friction --setup wedge --data " + kEx + "friction_plate.csv", "--setup"},
           {"calibrate adhesion --data " + kEx + "adhesion_centrifugal.csv", "--particle-mass-kg"},
           {"calibrate adhesion --data " + kEx + "adhesion_centrifugal.csv --particle-mass-kg 1.3e-12 --rotor-radius-m 0.05",
            "--initial-count"},
           {"calibrate magnetisation --demag-factor 2 --data " + kEx + "vsm_black.csv", "--demag-factor"},
           {"experiment front-force --gap -1", "--gap"},
           {"experiment front-force --set geometry.gap_m=1e-4", "use --gap instead"},
           {"experiment front-force --l 2e-6,x", "--l"}}) {
    SCOPED_TRACE(args);
    const Res r = cli(args + " --out " + (d / "out").string());
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  }
  fs::remove_all(d);
}
