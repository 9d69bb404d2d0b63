// Cohesion-ratio calibration (thesis §4.6, eq. 4.6.1, Table 4.3): the 1-D root search over
// reduction speeds, on analytic v(r) whose root is known.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

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
