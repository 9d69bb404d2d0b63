// Hostile input to the field commands, `plot`, `experiment front-force` and `experiment vo-level`
// (issue 21, docs/reliability.md): every input below ended with exit 0 and null/NaN results, an
// empty picture, an overwritten output or a message without the option's range. Each must now end
// with exit 2, a message on stderr naming the option / file at fault, no signal, within a time
// bound. One test per class of defect; each case is one row (arguments, what stderr must name).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "../cli_run.hpp"
#include "support/hostile.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace {
constexpr int kBoundSeconds = 60;  // wall-clock bound of one refused input (they take < 1 s alone)

using nipdem::test::hostile::Case;

fs::path scratch(const std::string& name) { return nipdem::test::hostile::scratch("nipdem_hostile_field_", name); }
using nipdem::test::hostile::write;
// A regular 6 x 6 map (20 um spacing) whose node (i, j) = (2, 3) (file line 22) holds `bad`
// in column `column` (2: Bx, 3: By); every other value is ordinary.
std::string map_with(const fs::path& p, const std::string& header, int column, const std::string& bad) {
  std::string t = header + "\n";
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i) {
      const bool hit = i == 2 && j == 3;
      t += std::to_string(i * 2e-5) + "," + std::to_string(j * 2e-5) + "," + (hit && column == 2 ? bad : "0.1") + "," +
           (hit && column == 3 ? bad : "0.2") + "\n";
    }
  return write(p, t);
}

void expect_refused(const std::vector<Case>& cases, const std::string& tag) {
  nipdem::test::hostile::expect_cases(cases, tag, {.max_seconds = kBoundSeconds});
}
}  // namespace

// ---- points where the field is not one a toner feels (on / in the magnet, its singular corners),
// and maps holding flux densities no magnet makes: null / NaN results with exit 0 before ----
TEST(HostileField, PointsInTheMagnetAndNonPhysicalMapValuesAreRefused) {
  const fs::path d = scratch("points");
  const std::string huge_bx = map_with(d / "m6_bhuge.csv", "x_m,y_m,Bx_T,By_T", 2, "1e308");
  const std::string huge_by = map_with(d / "m6_byhuge.csv", "x_m,y_m,Bx_T,By_T", 3, "-2e5");
  const std::string huge_mt = map_with(d / "m6_mt.csv", "x_m,y_m,Bx_mT,By_mT", 2, "1e300");
  expect_refused({
      {"field probe --x 0 --y -1e-4 --json", {"--x", "--y", "magnet", "y > -0.0001"}},  // the knife edge (a corner)
      {"field probe --x 0 --y -1e-4", {"--x", "--y", "magnet"}},                         // text mode printed -nan
      {"field probe --preset color --x 0 --y -1e-4 --json", {"--x", "--y", "magnet"}},    // the pole's corner
      {"field probe --preset color --x -3e-4 --y -1e-4 --json", {"--x", "--y", "magnet"}},
      {"field probe --tip-depth 5e-5 --x 0 --y -5e-5 --json", {"--x", "--y", "y > -5e-05"}},
      {"field line --y -1e-4 --out " + (d / "fl.csv").string(), {"--y", "magnet"}},  // "F_x changes sign at nan m"
      {"field line --preset color --y -1e-4 --n 11 --out " + (d / "fl.csv").string() + " --json", {"--y", "magnet"}},
      {"field probe --x 5e-5 --y 5e-5 --map " + huge_bx + " --json", {"m6_bhuge.csv:22", "Bx (column 3)", "100 T"}},
      {"field probe --x 5e-5 --y 5e-5 --map " + huge_by + " --json", {"m6_byhuge.csv:22", "By (column 4)", "100 T"}},
      {"field line --y 5e-5 --x0 0 --x1 1e-4 --n 5 --map " + huge_mt + " --out " + (d / "fl.csv").string(),
       {"m6_mt.csv:22", "Bx (column 3)", "100 T"}},
  }, "hostile_field_points");
  EXPECT_FALSE(fs::exists(d / "fl.csv"));  // nothing written for a refused line
  fs::remove_all(d);
}

// ---- plot: nothing to draw, or values the scaling takes beyond what an axis can show: an empty
// picture with exit 0 before ----
TEST(HostileField, PlotsWithNothingToDrawAreRefused) {
  const fs::path d = scratch("plot");
  const std::string g = write(d / "g.csv", "a_m,b_N\n1,2\n2,3\n3,1\n");
  const std::string hdr = write(d / "hdr.csv", "a_m,b_N\n");
  const std::string wide = write(d / "wide.csv", "a_m,b_N\n-1e308,2\n1e308,3\n");
  const std::string nan = write(d / "nan.csv", "a_m,b_N\n1,nan\n2,nan\n");
  const std::string err = write(d / "err.csv", "a_m,b_N,e_N\n1,2,0.1\n2,3,1e299\n");
  const std::string out = " --out " + (d / "p.png").string();
  expect_refused({
      {"plot " + g + " --x a_m --y b_N --xscale 1e308 --yscale 1e308" + out, {"--xscale"}},
      {"plot " + g + " --x a_m --y b_N --yscale 1e308" + out, {"--yscale", "1e+30"}},
      {"plot " + g + " --x a_m --y b_N --xscale 0" + out, {"--xscale"}},     // every x at 0: axis "[inf m]"
      {"plot " + g + " --x a_m --y b_N --yscale -1e-40" + out, {"--yscale"}},
      {"plot " + hdr + " --x a_m --y b_N" + out, {"hdr.csv", "no data rows"}},
      {"plot " + wide + " --x a_m --y b_N" + out, {"wide.csv:2", "a_m"}},    // the axis span overflows
      {"plot " + err + " --x a_m --y b_N --yerr e_N --yscale 1e10" + out, {"err.csv:3", "e_N", "--yscale"}},
      {"plot " + nan + " --x a_m --y b_N" + out, {"nan.csv", "b_N", "nothing to plot"}},
  }, "hostile_field_plot");
  EXPECT_FALSE(fs::exists(d / "p.png"));
  fs::remove_all(d);
}

// ---- field line: the picture goes to --out with .png; an --out ending in .png was overwritten
// by it (the CSV lost, exit 0) ----
TEST(HostileField, FieldLineOutputsThatWouldCollideAreRefused) {
  const fs::path d = scratch("collide");
  expect_refused({
      {"field line --out " + (d / "fl.png").string(), {"--out", "fl.png", "fl.csv"}},
      {"field line --n 11 --json --out " + (d / "sub.dir" / "line.png").string(), {"--out", "line.png"}},
  }, "hostile_field_collide");
  EXPECT_FALSE(fs::exists(d / "fl.png"));
  fs::remove_all(d);
}

// ---- integer options beyond int: "Could not convert", no range, before ----
TEST(HostileField, IntegerOptionsBeyondIntNameTheirRange) {
  const fs::path d = scratch("ints");
  const std::string csv = " --out " + (d / "x.csv").string();
  expect_refused({
      {"field line --n 2147483648" + csv, {"--n", "2 to 1000000"}},
      {"field line --n -2147483649" + csv, {"--n", "2 to 1000000"}},
      {"field line --n 99999999999999999999" + csv, {"--n", "2 to 1000000"}},
      {"field export --nx 2147483648" + csv, {"--nx", "5 to 100000"}},
      {"field export --ny 4294967296" + csv, {"--ny", "5 to 100000"}},
  }, "hostile_field_ints");
  fs::remove_all(d);
}

// ---- experiment front-force: a voltage whose forces overflow (null results), a front region
// outside the x range (all zeros) or partly outside it (reported from a smaller region) ----
TEST(HostileField, FrontForceOptionsOutOfRangeAreRefused) {
  const fs::path d = scratch("front");
  const std::string run = "experiment front-force --json --out " + (d / "ff").string();
  expect_refused({
      {run + " --voltage 1e308", {"--voltage", "10000"}},
      {run + " --voltage 1e5", {"--voltage", "10000"}},
      {run + " --front-x-min 1 --front-x-max 2", {"--front-x-min", "-0.0005, 0.0001"}},
      {run + " --front-x-min -2e-3 --front-x-max -1e-3", {"--front-x-min", "--x-min"}},
      {run + " --front-x-min -1e-4 --front-x-max 5e-4", {"--front-x-max", "--x-max"}},
      {run + " --x-min -1e-4", {"--front-x-min", "-0.0001, 0.0001"}},  // the default front region [-300, 0] um
      {run + " --front-x-min 1.01e-5 --front-x-max 1.02e-5", {"--front-x-min, --front-x-max", "--dx"}},
  }, "hostile_field_front");
  EXPECT_FALSE(fs::exists(d / "ff" / "front_force.json"));
  fs::remove_all(d);
}

// ---- experiment vo-level: voltages whose step count overflows (nothing run, found false, exit 0)
// or that the search refused without naming the option ----
TEST(HostileField, VoLevelVoltagesOutOfRangeAreRefused) {
  const fs::path d = scratch("vo");
  const std::string run = "experiment vo-level --json --quiet --out " + (d / "vo").string();
  expect_refused({
      {run + " --v0 -1e308", {"--v0", "10000"}},
      {run + " --vmax 1e308", {"--vmax", "10000"}},
      {run + " --v0 1e308", {"--v0", "10000"}},
      {run + " --vmax 1e5", {"--vmax", "10000"}},
      {run + " --v0 30 --vmax 20", {"--vmax", "[30, 10000]"}},
      {run + " --coarse-step 1e20", {"--coarse-step", "20000"}},
      {run + " --step 1e-3 --vmax 1000", {"--step", "steps"}},
  }, "hostile_field_vo");
  EXPECT_FALSE(fs::exists(d / "vo" / "vo-level.json"));
  fs::remove_all(d);
}
