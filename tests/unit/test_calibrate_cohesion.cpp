// Cohesion-ratio calibration (thesis §4.6, eq. 4.6.1, Table 4.3): the 1-D root search over
// reduction speeds, on analytic v(r) whose root is known.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/calibrate_cohesion.hpp"

using namespace nipdem;
using namespace nipdem::calibrate;

namespace {
// v(r) = a - b ln r: linear in ln r, so the interpolation is exact (tolerance: round-off).
double loglin(double r) { return 1e-3 - 2e-4 * std::log(r); }
std::vector<SpeedPoint> sample(const std::vector<double>& rs, double (*v)(double), double se = 0.0) {
  std::vector<SpeedPoint> p;
  for (double r : rs) p.push_back({r, v(r), se});
  return p;
}
}  // namespace

TEST(CohesionFit, LogLinearSpeedGivesTheExactRoot) {
  const double target = 7.6e-4;  // Table 4.3, black
  const double exact = std::exp((1e-3 - target) / 2e-4);
  auto pts = sample({0.1, 1.0, 10.0, 100.0}, loglin);
  std::reverse(pts.begin(), pts.end());  // any order
  const auto f = fit_cohesion_ratio(pts, target);
  ASSERT_TRUE(f.bracketed);
  EXPECT_EQ(f.crossings, 1u);
  EXPECT_DOUBLE_EQ(f.r_lo, 1.0);
  EXPECT_DOUBLE_EQ(f.r_hi, 10.0);
  EXPECT_NEAR(f.r_fit / exact, 1.0, 1e-12);
}

TEST(CohesionFit, OneSigmaRangeMapsTheSpeedErrorThroughTheSlope) {
  // |dv/d ln r| = 2e-4; a standard error of 2e-5 is 0.1 in ln r
  const auto f = fit_cohesion_ratio(sample({1.0, 10.0}, loglin, 2e-5), 8e-4);
  ASSERT_TRUE(f.bracketed);
  EXPECT_NEAR(std::log(f.r_1sigma_hi / f.r_fit), 0.1, 1e-12);
  EXPECT_NEAR(std::log(f.r_fit / f.r_1sigma_lo), 0.1, 1e-12);
}

TEST(CohesionFit, NotBracketedSaysWhichWayToExtendTheRange) {
  const auto above = fit_cohesion_ratio(sample({0.1, 1.0}, loglin), 1e-6);  // all speeds above
  EXPECT_FALSE(above.bracketed);
  EXPECT_NE(above.hint.find("--r-max"), std::string::npos) << above.hint;
  const auto below = fit_cohesion_ratio(sample({0.1, 1.0}, loglin), 5e-3);
  EXPECT_FALSE(below.bracketed);
  EXPECT_NE(below.hint.find("--r-min"), std::string::npos) << below.hint;
}

TEST(CohesionFit, NoisyDataWithSeveralCrossingsUsesTheLowestAndCountsThem) {
  const std::vector<SpeedPoint> p{{1, 3e-4, 0}, {2, 1e-4, 0}, {4, 3e-4, 0}, {8, 1e-4, 0}};
  const auto f = fit_cohesion_ratio(p, 2e-4);
  ASSERT_TRUE(f.bracketed);
  EXPECT_EQ(f.crossings, 3u);
  EXPECT_DOUBLE_EQ(f.r_lo, 1.0);
  EXPECT_DOUBLE_EQ(f.r_hi, 2.0);
  EXPECT_NEAR(f.r_fit, std::sqrt(2.0), 1e-12);  // halfway in ln r
}

TEST(CohesionFit, CountsPairsThatGoAgainstTheTrendBeyondTwoSigma) {
  // rising overall; 2 -> 3 falls by 3e-4 with a combined error of 1.4e-4 (> 2 sigma), 4 -> 5
  // falls by 1e-4 (< 2 sigma: noise)
  const std::vector<SpeedPoint> p{{1, 0.0, 1e-4}, {2, 1e-4, 1e-4}, {3, -2e-4, 1e-4}, {4, 4e-4, 1e-4}, {5, 3e-4, 1e-4}};
  EXPECT_EQ(fit_cohesion_ratio(p, 2.5e-4).against_trend, 1u);
  EXPECT_EQ(fit_cohesion_ratio(sample({0.1, 1.0, 10.0}, loglin, 1e-6), 8e-4).against_trend, 0u);
}

TEST(CohesionFit, BadInputIsAnInputError) {
  EXPECT_THROW(fit_cohesion_ratio({{1.0, 1e-4, 0}}, 1e-4), InputError);
  EXPECT_THROW(fit_cohesion_ratio({{0.0, 1e-4, 0}, {1.0, 2e-4, 0}}, 1e-4), InputError);
  EXPECT_THROW(fit_cohesion_ratio({{1.0, NAN, 0}, {2.0, 2e-4, 0}}, 1e-4), InputError);
  EXPECT_THROW(interior_log_points(2.0, 1.0, 3), InputError);
}

TEST(CohesionFit, InteriorPointsAreGeometricAndStrictlyInside) {
  const auto r = interior_log_points(1.0, 1000.0, 2);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_NEAR(r[0], 10.0, 1e-12);
  EXPECT_NEAR(r[1], 100.0, 1e-10);
}

TEST(CohesionSearch, ConvergesOnANonlinearMonotoneSpeed) {
  // v(r) = v0 / (1 + r): falls with r like fig. 4.25; root r* = v0/target - 1 = 3.
  auto v = [](double r) { return 1e-3 / (1.0 + r); };
  CohesionOptions c;
  c.target_speed_m_per_s = 2.5e-4;
  c.r_min = 0.01;
  c.r_max = 100.0;
  c.points = 3;
  c.rounds = 6;
  std::size_t evaluations = 0;
  const auto s = search_cohesion_ratio(
      [&](std::size_t, const std::vector<double>& rs) {
        std::vector<SpeedPoint> p;
        for (double r : rs) p.push_back({r, v(r), 0.0}), ++evaluations;
        return p;
      },
      c);
  ASSERT_TRUE(s.fit.bracketed);
  EXPECT_EQ(s.rounds_r.size(), 6u);
  EXPECT_EQ(evaluations, 18u);
  // the bracket shrinks by points + 1 = 4 per refinement in ln r: ln(1e4)/2 / 4^5 = 4.5e-3
  EXPECT_LT(std::log(s.fit.r_hi / s.fit.r_lo), 5e-3);
  EXPECT_NEAR(s.fit.r_fit, 3.0, 3.0 * 1e-5);  // interpolation error inside that bracket
  EXPECT_TRUE(std::is_sorted(s.points.begin(), s.points.end(), [](auto& a, auto& b) { return a.r < b.r; }));
}

TEST(CohesionSearch, StopsAfterRoundZeroWhenNotBracketed) {
  CohesionOptions c;
  c.target_speed_m_per_s = 1.0;  // unreachable
  c.rounds = 4;
  const auto s = search_cohesion_ratio(
      [&](std::size_t, const std::vector<double>& rs) {
        std::vector<SpeedPoint> p;
        for (double r : rs) p.push_back({r, loglin(r), 0.0});
        return p;
      },
      c);
  EXPECT_FALSE(s.fit.bracketed);
  EXPECT_EQ(s.rounds_r.size(), 1u);
}

// ---- r from the removed counts of a sweep (docs/reduction.md) ----
namespace {
// fig. 4.25's shape as the thesis describes it: linear fall from N0 at r = 0 to zero at r = 1
double fig425(double r, double n0) { return n0 * std::max(0.0, 1.0 - r); }
}  // namespace

TEST(CohesionCounts, TargetCountIsTheSpeedTimesTheLinearDensityOfThePile) {
  // 600 toner over 400 um: 1.5 per um; 0.76 mm/s over 100 ms = 76 um -> 114 toner (the thesis's
  // own conversion of Table 4.3 into "fewer than 200")
  std::vector<CountPoint> p{{0.0, 500, 600}, {2.0, 0, 600}};
  CountTarget t{7.6e-4, 7.4e-4, 7.8e-4, 0.1, 400e-6};
  const auto f = fit_cohesion_from_counts(p, t);
  EXPECT_NEAR(f.target, 114.0, 1e-9);
  EXPECT_NEAR(f.target_lo, 111.0, 1e-9);
  EXPECT_NEAR(f.target_hi, 117.0, 1e-9);
  ASSERT_TRUE(f.bracketed);
  EXPECT_NEAR(f.r_fit, 2.0 * (500.0 - 114.0) / 500.0, 1e-12);  // linear between the two points
}

TEST(CohesionCounts, RecoversTheRootOfTheLinearFallFromNoisySeeds) {
  // 4 seeds per r with Gaussian scatter of 15 toner (the scatter seen between seeds of the
  // 10 ms screens); the truth r* solves N0 (1 - r*) = target. Over 40 synthetic sweeps the
  // 1-sigma interval must contain r* in most of them (the interval is built from the mean's
  // standard error at each r: ~68 % coverage expected; we require >= 50 % and the fit within
  // 0.1 of r* every time, 0.1 = 6 standard errors of the mean curve's crossing).
  const double n0 = 400.0, target = 114.0, rstar = 1.0 - target / n0;
  const std::vector<double> rs{0, 0.25, 0.5, 0.75, 1, 1.5, 2, 3};
  std::uint64_t state = 12345;
  auto normal = [&] {  // Box-Muller on a 64-bit LCG: deterministic
    auto u = [&] { state = state * 6364136223846793005ULL + 1442695040888963407ULL; return ((state >> 11) + 0.5) * 0x1.0p-53; };
    return std::sqrt(-2.0 * std::log(u())) * std::cos(6.283185307179586 * u());
  };
  int covered = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<CountPoint> p;
    for (double r : rs)
      for (int s = 0; s < 4; ++s) p.push_back({r, fig425(r, n0) + 15.0 * normal(), 600.0});
    const auto f = fit_cohesion_from_counts(p, {7.6e-4, 7.6e-4, 7.6e-4, 0.1, 400e-6});
    ASSERT_TRUE(f.bracketed);
    EXPECT_NEAR(f.r_fit, rstar, 0.1);
    ASSERT_TRUE(f.in_band);
    if (f.r_lo <= rstar && rstar <= f.r_hi) ++covered;
    EXPECT_FALSE(f.single_seed);
  }
  EXPECT_GE(covered, 20);
}

TEST(CohesionCounts, ReportsWhenTheTargetIsOutsideTheSweep) {
  std::vector<CountPoint> p{{0.0, 10, 600}, {1.0, 5, 600}, {1.0, 7, 600}};
  const auto f = fit_cohesion_from_counts(p, {7.6e-4, 7.6e-4, 7.6e-4, 0.1, 400e-6});
  EXPECT_FALSE(f.bracketed);
  EXPECT_NE(f.hint.find("smaller r"), std::string::npos);
  EXPECT_TRUE(f.single_seed);  // r = 0 has one seed
  ASSERT_EQ(f.rows.size(), 2u);
  EXPECT_DOUBLE_EQ(f.rows[1].mean, 6.0);
  EXPECT_NEAR(f.rows[1].stderr_, 1.0, 1e-12);  // sd sqrt(2) over sqrt(2)
}

TEST(CohesionCounts, BadInputIsRefusedNamingTheKey) {
  const CountTarget t{7.6e-4, 7.4e-4, 7.8e-4, 0.1, 400e-6};
  auto msg = [&](std::vector<CountPoint> p, CountTarget tt) {
    try {
      fit_cohesion_from_counts(p, tt);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(msg({{1.0, 5, 600}, {1.0, 6, 600}}, t).find("distinct r"), std::string::npos);
  EXPECT_NE(msg({{-1.0, 5, 600}, {1.0, 6, 600}}, t).find("r"), std::string::npos);
  EXPECT_NE(msg({{0.0, NAN, 600}, {1.0, 6, 600}}, t).find("removed"), std::string::npos);
  EXPECT_NE(msg({{0.0, 5, 0}, {1.0, 6, 600}}, t).find("initial_particles"), std::string::npos);
  CountTarget bad = t;
  bad.speed_lo = 9e-4;  // above the speed
  EXPECT_NE(msg({{0.0, 5, 600}, {1.0, 6, 600}}, bad).find("--target-range"), std::string::npos);
}

// Sweeps run separately (one per seed) are pooled by --from-sweep A,B: the rows then hold both
// seeds; sweeps of another preset or model are refused naming the file.
TEST(CohesionCounts, FromSweepPoolsSeveralFilesOfOneModelAndRefusesMixedOnes) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("nipdem_cohesion_pool_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto sweep = [&](const char* name, const char* preset, std::vector<std::pair<double, double>> r_removed) {
    nlohmann::json pts = nlohmann::json::array();
    for (auto [r, n] : r_removed) pts.push_back({{"r", r}, {"removed", n}, {"initial_particles", 600}, {"time_s", 0.1}});
    nlohmann::json j{{"experiment", "reduction"}, {"pile_width_m", 400e-6}, {"points", pts},
                     {"meta", {{"preset", preset}, {"set", {"adhesion.roller_force_N=1e-8"}}, {"config", ""}}}};
    std::ofstream(dir / name) << j.dump();
    return (dir / name).string();
  };
  const std::string a = sweep("a.json", "black", {{0, 200}, {1, 150}, {3, 60}});
  const std::string b = sweep("b.json", "black", {{0, 180}, {1, 130}, {3, 80}});
  const std::string c = sweep("c.json", "color", {{0, 50}, {1, 20}, {3, 0}});
  experiments::ExperimentOptions o;
  o.out = dir / "out";
  o.progress = false;
  fs::create_directories(o.out);
  const CountTarget t{7.6e-4, 7.4e-4, 7.8e-4, 0.1, 400e-6};
  const auto j = calibrate_cohesion_from_sweep(o, a + "," + b, t);
  ASSERT_EQ(j["rows"].size(), 3u);
  EXPECT_EQ(j["rows"][1]["seeds"].get<int>(), 2);
  EXPECT_DOUBLE_EQ(j["rows"][1]["removed_mean"].get<double>(), 140.0);
  EXPECT_NEAR(j["rows"][1]["removed_stderr"].get<double>(), 10.0, 1e-12);  // sd 10 sqrt(2) / sqrt(2)
  ASSERT_TRUE(j.contains("r_fit"));
  EXPECT_NEAR(j["r_fit"].get<double>(), 1.0 + 2.0 * (140.0 - 114.0) / (140.0 - 70.0), 1e-9);  // linear 1 -> 3
  EXPECT_EQ(j["sweeps"].size(), 2u);
  try {
    calibrate_cohesion_from_sweep(o, a + "," + c, t);
    ADD_FAILURE() << "a colour sweep was pooled with a black one";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("c.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("preset"), std::string::npos) << e.what();
  }
  EXPECT_THROW(calibrate_cohesion_from_sweep(o, a + ",", t), InputError);
  fs::remove_all(dir);
}

// One r for several units (§4.6: the thesis chose one r for black and colour).
namespace {
// A unit whose mean count falls linearly, mean(r) = a - b r, with a constant standard error.
JointUnit linear_unit(const char* name, double a, double b, double se, double target, double halfband) {
  JointUnit u;
  u.name = name;
  for (double r : {0.0, 1.0, 2.0, 3.0}) u.rows.push_back({r, 2, a - b * r, se});
  u.target = target;
  u.target_lo = target - halfband;
  u.target_hi = target + halfband;
  return u;
}
}  // namespace

TEST(CohesionJoint, TwoUnitsCrossingAtTheSameRGiveThatRAndTheAnalyticInterval) {
  // Both units reach their target at r = 1; chi2(r) = 2 (50 (r - 1))^2 / (6^2 + 8^2), so
  // chi2 = min + 1 at |r - 1| = 10 / (50 sqrt 2) = 0.14142. Tolerance: the grid step, 3/2e4.
  const auto f = fit_joint_cohesion({linear_unit("black", 200, 50, 6, 150, 8), linear_unit("color", 160, 50, 8, 110, 6)});
  const double h = 3.0 / 2e4;
  EXPECT_NEAR(f.r_fit, 1.0, h);
  EXPECT_NEAR(f.chi2_min, 0.0, 1e-6);
  EXPECT_NEAR(f.r_lo, 1.0 - 0.1414214, h);
  EXPECT_NEAR(f.r_hi, 1.0 + 0.1414214, h);
  EXPECT_FALSE(f.open_lo);
  EXPECT_FALSE(f.open_hi);
  EXPECT_EQ(f.dof, 1u);
  ASSERT_EQ(f.chi2_unit.size(), 2u);
}

TEST(CohesionJoint, DisagreeingUnitsMeetAtTheInverseVarianceWeightedRoot) {
  // Unit A wants r = 1 with sigma_r = 10/50 = 0.2, unit B r = 2 with sigma_r = 0.1: the chi2
  // minimum of two parabolas is the weighted mean (1/0.04 + 2/0.01) / (1/0.04 + 1/0.01) = 1.8,
  // chi2_min = (2 - 1)^2 / (0.04 + 0.01) = 20, and the interval is 1.8 +- 1/sqrt(1/0.04 + 1/0.01).
  const auto f = fit_joint_cohesion({linear_unit("a", 200, 50, 0, 150, 10), linear_unit("b", 200, 50, 0, 100, 5)});
  const double h = 3.0 / 2e4;
  EXPECT_NEAR(f.r_fit, 1.8, h);
  EXPECT_NEAR(f.chi2_min, 20.0, 1e-2);
  EXPECT_NEAR(f.r_hi - f.r_fit, 1.0 / std::sqrt(125.0), 2 * h);
  EXPECT_NEAR(f.r_fit - f.r_lo, 1.0 / std::sqrt(125.0), 2 * h);
  EXPECT_NEAR(f.chi2_unit[0], 0.64 / 0.04, 1e-2);  // (1.8 - 1)^2 / 0.2^2
  EXPECT_NEAR(f.chi2_unit[1], 0.04 / 0.01, 1e-2);
}

TEST(CohesionJoint, BadInputIsRefusedNamingTheUnit) {
  auto msg = [](std::vector<JointUnit> u) {
    try {
      fit_joint_cohesion(u);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const auto a = linear_unit("black", 200, 50, 6, 150, 8);
  EXPECT_NE(msg({a}).find("at least two units"), std::string::npos);
  auto nan_row = linear_unit("color", 160, 50, 8, 110, 6);
  nan_row.rows[1].mean = NAN;
  EXPECT_NE(msg({a, nan_row}).find("color"), std::string::npos);
  auto no_error = linear_unit("color", 160, 50, 0, 110, 0);
  EXPECT_NE(msg({a, no_error}).find("no error estimate"), std::string::npos);
  auto apart = linear_unit("color", 160, 50, 8, 110, 6);
  for (auto& r : apart.rows) r.r += 10.0;  // sweeps that do not overlap in r
  EXPECT_NE(msg({a, apart}).find("overlap"), std::string::npos);
  auto outside = linear_unit("color", 160, 50, 8, 110, 6);
  outside.target = 50;  // outside [104, 116]
  EXPECT_NE(msg({a, outside}).find("target_removed"), std::string::npos);
}

// The command reads `calibrate cohesion --from-sweep` reports; it reproduces the joint r of the
// committed F10nN calibration (docs/results/2026-12-04-reduction-sweep-F10nN/joint_r.json,
// made by joint_fit.py on a 1e-3 grid: r = 1.768, interval 1.514-2.026, chi2 0.616).
TEST(CohesionJoint, ReproducesTheCommittedPresetCalibration) {
  namespace fs = std::filesystem;
  const fs::path src = fs::path(NIPDEM_SOURCE_DIR) / "docs/results/2026-12-04-reduction-sweep-F10nN/calibration";
  const fs::path dir = fs::temp_directory_path() / ("nipdem_cohesion_joint_" + std::to_string(::getpid()));
  experiments::ExperimentOptions o;
  o.out = dir;
  o.progress = false;
  const auto j = calibrate_cohesion_joint(o, (src / "black.json").string() + "," + (src / "color.json").string());
  EXPECT_NEAR(j["r_fit"].get<double>(), 1.768, 2e-3);  // 2e-3: the Python grid's step plus ours
  EXPECT_NEAR(j["r_interval_dchi2_1"][0].get<double>(), 1.514, 2e-3);
  EXPECT_NEAR(j["r_interval_dchi2_1"][1].get<double>(), 2.026, 2e-3);
  EXPECT_NEAR(j["chi2_min"].get<double>(), 0.616, 2e-3);
  EXPECT_TRUE(j["units"].contains("black"));
  EXPECT_TRUE(j["units"].contains("color"));
  EXPECT_TRUE(fs::exists(dir / "removed_vs_r.png"));
  EXPECT_TRUE(fs::exists(dir / "cohesion_joint.csv"));
  // a reduction sweep JSON is not a cohesion report
  const fs::path sweep = fs::path(NIPDEM_SOURCE_DIR) / "docs/results/2026-12-04-reduction-sweep-F10nN/color_s1/reduction.json";
  try {
    calibrate_cohesion_joint(o, (src / "black.json").string() + "," + sweep.string());
    ADD_FAILURE() << "a sweep was read as a report";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reduction.json"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}
