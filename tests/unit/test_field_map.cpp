// Tests of the imported field map (io/field_map.hpp) and of the field CLI.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <string>

#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/field_map.hpp"
#include "nipdem/models/magnet_field.hpp"

using namespace nipdem;
using namespace nipdem::magnet;
using nipdem::io::FieldMap;

namespace {

FieldMap sampled_map(const MagnetField& f, double x0, double x1, double y0, double y1, double h) {
  const int nx = static_cast<int>(std::lround((x1 - x0) / h)) + 1, ny = static_cast<int>(std::lround((y1 - y0) / h)) + 1;
  std::vector<double> bx, by;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const auto s = f.at({x0 + i * h, y0 + j * h});
      bx.push_back(s.B.x);
      by.push_back(s.B.y);
    }
  return FieldMap(x0, y0, h, h, nx, ny, bx, by, "test map");
}

// Max errors of B and grad B at fixed random points.
std::array<double, 2> map_errors(const MagnetField& exact, const FieldMap& map, int npts) {
  Rng rng(17);
  double eb = 0, eg = 0;
  for (int k = 0; k < npts; ++k) {
    const Vec2 p{rng.uniform(-400e-6, 400e-6), rng.uniform(100e-6, 500e-6)};
    const auto a = exact.at(p), m = map.at(p);
    eb = std::max(eb, norm(a.B - m.B));
    eg = std::max(eg, std::abs(a.dB.xx - m.dB.xx) + std::abs(a.dB.xy - m.dB.xy) + std::abs(a.dB.yx - m.dB.yx) +
                          std::abs(a.dB.yy - m.dB.yy));
  }
  return {eb, eg};
}

int run_cli(const std::string& args, std::string* out = nullptr) {
  const std::string cmd = std::string(NIPDEM_CLI_PATH) + " " + args + " 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  std::string s;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) s += buf;
  const int st = pclose(p);
  if (out) *out = s;
  return WEXITSTATUS(st);
}

std::string tmp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / fmt::format("nipdem_fieldmap_{}_{}", getpid(), name)).string();
}

}  // namespace

TEST(FieldMap, ReproducesAnalyticKnifeField) {
  // Map sampled from the analytic knife at h = 10 um over x in [-0.5, 0.5] mm, y in [0.05, 0.55] mm
  // (>= 150 um from the magnet corners, field length scale L >= 150 um): the bicubic Hermite error is
  // ~ (h/L)^4 |B| ~ 2e-5 |B|. Tolerance: 1e-4 T on B (|B| ~ 0.4 T), and 1 % of |grad B| (~1e3 T/m)
  // on the gradient (error ~ (h/L)^3). Also the force on a d50 black toner within 1 %.
  const auto knife = make_knife();
  const auto map = sampled_map(knife, -500e-6, 500e-6, 50e-6, 550e-6, 10e-6);
  Rng rng(2);
  const auto toner = black_toner();
  for (int k = 0; k < 300; ++k) {
    const Vec2 p{rng.uniform(-400e-6, 400e-6), rng.uniform(100e-6, 500e-6)};
    const auto a = knife.at(p), m = map.at(p);
    EXPECT_LT(norm(a.B - m.B), 1e-4);
    const double g = std::sqrt(a.dB.xx * a.dB.xx + a.dB.xy * a.dB.xy + a.dB.yx * a.dB.yx + a.dB.yy * a.dB.yy);
    EXPECT_LT(std::abs(a.dB.xx - m.dB.xx) + std::abs(a.dB.xy - m.dB.xy) + std::abs(a.dB.yx - m.dB.yx) +
                  std::abs(a.dB.yy - m.dB.yy),
              0.01 * g);
    const Vec2 Fa = induced_dipole_force(toner, 5.25e-6, a), Fm = induced_dipole_force(toner, 5.25e-6, m);
    EXPECT_LT(norm(Fa - Fm), 0.01 * norm(Fa));
  }
  // Grid nodes are reproduced exactly (Hermite interpolation): 1e-14 T.
  EXPECT_NEAR(map.at({0, 100e-6}).B.x, knife.at({0, 100e-6}).B.x, 1e-14);
  // FieldMap::sample builds the same map (same nodes, same values): identical to 1e-15 T.
  const auto s = FieldMap::sample(knife, -500e-6, 500e-6, 101, 50e-6, 550e-6, 51);
  for (Vec2 p : {Vec2{-123e-6, 234e-6}, Vec2{300e-6, 77e-6}})
    EXPECT_NEAR(norm(s.at(p).B - map.at(p).B), 0.0, 1e-15);
}

TEST(FieldMap, InterpolationConvergesAtFourthAndThirdOrder) {
  // Errors at h = 40, 20, 10 um: bicubic Hermite with 4th-order nodal derivatives gives O(h^4) in B
  // and O(h^3) in grad B. Observed order from the last two halvings must be within 0.5 of the
  // expected value (pre-asymptotic effects at h/L ~ 0.25 are a few tenths).
  const auto knife = make_knife();
  std::array<double, 3> eb{}, eg{};
  const double hs[3] = {40e-6, 20e-6, 10e-6};
  for (int i = 0; i < 3; ++i) {
    const auto map = sampled_map(knife, -560e-6, 560e-6, 40e-6, 600e-6, hs[i]);
    const auto e = map_errors(knife, map, 400);
    eb[static_cast<std::size_t>(i)] = e[0];
    eg[static_cast<std::size_t>(i)] = e[1];
  }
  const double ob1 = std::log2(eb[0] / eb[1]), ob2 = std::log2(eb[1] / eb[2]);
  const double og1 = std::log2(eg[0] / eg[1]), og2 = std::log2(eg[1] / eg[2]);
  std::printf("[map order] B errors %.3g %.3g %.3g T -> orders %.2f %.2f; grad errors %.3g %.3g %.3g T/m -> %.2f %.2f\n",
              eb[0], eb[1], eb[2], ob1, ob2, eg[0], eg[1], eg[2], og1, og2);
  EXPECT_NEAR(ob2, 4.0, 0.5);
  EXPECT_NEAR(og2, 3.0, 0.5);
  EXPECT_GT(ob1, 3.0);
  EXPECT_GT(og1, 2.0);
}

TEST(FieldMap, FieldAndGradientAreContinuousAcrossCells) {
  // C1 interpolation: approaching a cell boundary from both sides, B and grad B agree to rounding
  // (the patches share nodal values and derivatives). Tolerance 1e-9 relative.
  const auto knife = make_knife();
  const auto map = sampled_map(knife, -200e-6, 200e-6, 50e-6, 250e-6, 20e-6);
  const double eps = 1e-13;
  for (double x : {-100e-6, 0.0, 60e-6}) {
    const auto l = map.at({x - eps, 133e-6}), r = map.at({x + eps, 133e-6});
    EXPECT_NEAR(l.B.x, r.B.x, 1e-9 * norm(l.B));
    EXPECT_NEAR(l.dB.xx, r.dB.xx, 1e-9 * std::abs(l.dB.xx) + 1e-6);
    EXPECT_NEAR(l.dB.yx, r.dB.yx, 1e-9 * std::abs(l.dB.yx) + 1e-6);
    EXPECT_NEAR(l.dB.xy, r.dB.xy, 1e-9 * std::abs(l.dB.xy) + 1e-6);
  }
  for (double y : {70e-6, 150e-6}) {
    const auto l = map.at({17e-6, y - eps}), r = map.at({17e-6, y + eps});
    EXPECT_NEAR(l.B.y, r.B.y, 1e-9 * norm(l.B));
    EXPECT_NEAR(l.dB.yy, r.dB.yy, 1e-9 * std::abs(l.dB.yy) + 1e-6);
    EXPECT_NEAR(l.dB.xy, r.dB.xy, 1e-9 * std::abs(l.dB.xy) + 1e-6);
  }
}

TEST(FieldMap, CsvRoundTripWithUnitsAndShuffledRows) {
  // field_to_csv -> from_csv gives the same map; a header in mm/mT with the rows in another order
  // gives the same values after unit conversion (1e-12 relative: decimal round trip of %.17g).
  const auto pole = make_color_pole();
  const std::string csv = io::field_to_csv(pole, -300e-6, 300e-6, 7, 0.0, 200e-6, 6, "colour pole test");
  const auto a = FieldMap::from_csv(csv, "roundtrip.csv");
  EXPECT_EQ(a.nx(), 7);
  EXPECT_EQ(a.ny(), 6);
  std::string mm = "# same grid in mm and mT, reversed row order\nx_mm, y_mm, Bx_mT, By_mT\n";
  std::vector<std::string> rows;
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 7; ++i) {
      const double x = -300e-6 + 100e-6 * i, y = 40e-6 * j;
      const auto s = pole.at({x, y});
      rows.push_back(fmt::format("{:.17g},{:.17g},{:.17g},{:.17g}\r\n", x * 1e3, y * 1e3, s.B.x * 1e3, s.B.y * 1e3));
    }
  for (auto it = rows.rbegin(); it != rows.rend(); ++it) mm += *it;
  const auto b = FieldMap::from_csv(mm, "mm.csv");
  // An export with 6 significant digits (typical of FEM packages) is still a regular grid.
  std::string six = "x_um,y_um,Bx_T,By_T\n";
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 7; ++i) six += fmt::format("{:.6g},{:.6g},0.1,0.2\n", -333.3333333 + 111.1111111 * i, 1.234567 + 40.1234567 * j);
  EXPECT_NO_THROW(FieldMap::from_csv(six, "six.csv"));
  for (Vec2 p : {Vec2{-250e-6, 30e-6}, Vec2{0, 0}, Vec2{123e-6, 177e-6}}) {
    EXPECT_NEAR(a.at(p).B.x, b.at(p).B.x, 1e-12);
    EXPECT_NEAR(a.at(p).B.y, b.at(p).B.y, 1e-12);
    EXPECT_NEAR(a.at(p).dB.xy, b.at(p).dB.xy, 1e-12 * std::abs(a.at(p).dB.xy) + 1e-9);
  }
}

TEST(FieldMap, BadMapsThrowInputErrorWithClearMessages) {
  const auto pole = make_color_pole();
  const std::string good = io::field_to_csv(pole, -300e-6, 300e-6, 6, 0.0, 200e-6, 5);
  auto expect_error = [](const std::string& text, const std::string& needle) {
    try {
      FieldMap::from_csv(text, "bad.csv");
      ADD_FAILURE() << "no error for: " << needle;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.csv"), std::string::npos) << e.what();
    }
  };
  // Missing header (data first) and wrong/missing units.
  expect_error(good.substr(good.find('\n') + 1), "unexpected column");
  expect_error("x_in,y_m,Bx_T,By_T\n" + good.substr(good.find('\n') + 1), "unknown unit");
  expect_error("x,y_m,Bx_T,By_T\n" + good.substr(good.find('\n') + 1), "missing unit suffix");
  expect_error("x_m,y_m,Bx_G,By_T\n" + good.substr(good.find('\n') + 1), "unknown unit");
  expect_error("x_m,y_m,Bx_T\n1,2,3\n", "expected 4 columns");
  expect_error("", "missing header");
  expect_error("# only a comment\nx_m,y_m,Bx_T,By_T\n", "no data rows");
  // NaN value and non-number.
  std::string nan = good;
  nan.replace(nan.rfind(','), std::string::npos, ",nan\n");
  expect_error(nan, "NaN");
  std::string word = good;
  word.replace(word.rfind(','), std::string::npos, ",abc\n");
  expect_error(word, "not a number");
  // Ragged grid: drop one row.
  std::string ragged = good;
  const auto cut = ragged.find('\n', ragged.find('\n', ragged.find('\n') + 1) + 1);
  ragged.erase(ragged.find('\n') + 1, cut - ragged.find('\n'));
  expect_error(ragged, "missing");
  // Short row.
  expect_error(good + "1e-4,2e-4,0.1\n", "expected 4 values");
  // Non-regular spacing: 5 x values with one off-grid.
  std::string irr = "x_m,y_m,Bx_T,By_T\n";
  for (double x : {0.0, 1.0, 2.0, 3.5, 4.0})
    for (double y : {0.0, 1.0, 2.0, 3.0, 4.0}) irr += fmt::format("{},{},0.1,0.2\n", x * 1e-5, y * 1e-5);
  expect_error(irr, "not regular");
  // Too small grid and duplicates.
  expect_error(io::field_to_csv(pole, -3e-4, 3e-4, 4, 0.0, 2e-4, 5), "grid too small");
  std::string dup = good;
  const std::string line2 = dup.substr(dup.find('\n') + 1, dup.find('\n', dup.find('\n') + 1) - dup.find('\n'));
  expect_error(dup + line2, "given twice");
  // Points outside the map.
  const auto map = FieldMap::from_csv(good, "ok.csv");
  EXPECT_THROW(map.at({1e-3, 0.0}), InputError);
  EXPECT_THROW(map.at({0.0, -1e-6}), InputError);
  EXPECT_FALSE(map.contains({0.0, 201e-6}));
  EXPECT_TRUE(map.contains({300e-6, 200e-6}));
  EXPECT_NO_THROW(map.at({300e-6, 200e-6}));
  EXPECT_THROW(FieldMap(0, 0, 1e-5, 1e-5, 5, 5, std::vector<double>(25, NAN), std::vector<double>(25, 0.0)), InputError);
}

TEST(FieldMapCli, ProbeLineAndErrorsExitCodes) {
  // Through the CLI binary: probe JSON equals the library value; line writes the CSV; bad map file,
  // bad preset, missing file, point outside the map and out-of-range parameters exit 2.
  std::string out;
  ASSERT_EQ(run_cli("field probe --preset black --x 0 --y 100e-6 --json", &out), 0);
  const auto knife = make_knife();
  const auto s = knife.at({0, 100e-6});
  const Vec2 F = induced_dipole_force(black_toner(), 5.25e-6, s);
  const auto pos = out.find("\"Fy_N\":");
  ASSERT_NE(pos, std::string::npos) << out;
  EXPECT_NEAR(std::stod(out.substr(pos + 7)), F.y, 1e-6 * std::abs(F.y));

  const std::string csv = tmp_path("line.csv");
  ASSERT_EQ(run_cli("field line --preset color --n 11 --out " + csv + " --json", &out), 0);
  const std::string text = io::read_file(csv);
  EXPECT_NE(text.find("x_m,y_m,Bx_T,By_T,B_T"), std::string::npos);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 13);  // comment + header + 11 rows
  std::filesystem::remove(csv);

  const std::string bad = tmp_path("bad.csv");
  io::write_file_atomic(bad, "x_m,y_m,Bx_T\n1,2,3\n");
  EXPECT_EQ(run_cli("field probe --map " + bad + " --x 0 --y 1e-4 --json"), 2);
  std::filesystem::remove(bad);
  EXPECT_EQ(run_cli("field probe --map /nonexistent/map.csv --x 0 --y 1e-4 --json"), 2);
  EXPECT_EQ(run_cli("field probe --preset magenta --x 0 --y 1e-4 --json"), 2);
  EXPECT_EQ(run_cli("field probe --preset black --x 5 --y 1e-4 --json"), 2);
  EXPECT_EQ(run_cli("field probe --preset black --x 0 --y 1e-4 --radius -1 --json"), 2);
  // Out-of-range magnet parameters: remanence 5 T, negative tip depth.
  EXPECT_EQ(run_cli("field probe --preset black --x 0 --y 1e-4 --br 5 --json"), 2);
  EXPECT_EQ(run_cli("field probe --preset color --x 0 --y 1e-4 --tip-depth 0.5 --json"), 2);
  ASSERT_EQ(run_cli("field probe --preset black --x 0 --y 1e-4 --br 0.6 --json", &out), 0);
  EXPECT_NE(out.find("\"Fy_N\""), std::string::npos);
  const std::string small = tmp_path("small.csv");
  io::write_file_atomic(small, io::field_to_csv(knife, -1e-4, 1e-4, 5, 0, 1e-4, 5));
  EXPECT_EQ(run_cli("field probe --map " + small + " --x 0 --y 5e-5 --json"), 0);
  EXPECT_EQ(run_cli("field probe --map " + small + " --x 0 --y 5e-4 --json"), 2);
  std::filesystem::remove(small);
  EXPECT_EQ(run_cli("field line --preset black --x0 1e-4 --x1 -1e-4 --out /tmp/never.csv"), 2);
}

TEST(FieldMapCli, ForceDipoleJsonAndExitCodes) {
  // Cherry pit at theta = 0: 6 mu0/(4 pi) m^2/d^4 = 28.76 nN (hand value, 1e-3 relative for the
  // printed digits); d <= 2R and a missing required option exit 2.
  std::string out;
  ASSERT_EQ(run_cli("force dipole --moment 3.7e-11 --distance 13e-6 --angle 0 --json", &out), 0);
  const auto pos = out.find("\"force_N\":");
  ASSERT_NE(pos, std::string::npos) << out;
  EXPECT_NEAR(std::stod(out.substr(pos + 10)), 2.876e-8, 1e-3 * 2.876e-8);
  EXPECT_EQ(out.find("force_std_N"), std::string::npos);
  ASSERT_EQ(run_cli("force dipole --moment 3.7e-11 --distance 13e-6 --angle 90 --pigments 13 --samples 200 --seed 3 --json", &out), 0);
  EXPECT_NE(out.find("\"force_std_N\""), std::string::npos) << out;
  std::string again;
  ASSERT_EQ(run_cli("force dipole --moment 3.7e-11 --distance 13e-6 --angle 90 --pigments 13 --samples 200 --seed 3 --json", &again), 0);
  EXPECT_EQ(out, again);  // same seed, same output
  EXPECT_EQ(run_cli("force dipole --moment 3.7e-11 --distance 11e-6 --angle 0 --json"), 2);
  EXPECT_EQ(run_cli("force dipole --moment 3.7e-11 --angle 0 --json"), 2);
  EXPECT_EQ(run_cli("force dipole --moment -1 --distance 13e-6 --angle 0 --json"), 2);
}
