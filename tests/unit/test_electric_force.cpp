// Tests of the sphere–plate electric force (thesis §2.5.3) against independent methods.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/models/electric_force.hpp"

using namespace nipdem;
using namespace nipdem::electric;

namespace {
constexpr double kR = 5e-6;  // thesis fig. 2.21: R = 5 um, V = 40 V
constexpr double kV = 40.0;

// Independent method: explicit image charges. Sphere (centre at distance D from the plate)
// at potential V relative to the grounded plate: q0 = 4 pi eps0 R V at the centre; each
// charge q_k at x_k (distance from the plate) has a plate image -q_k at -x_k, whose image
// in the sphere is q_{k+1} = q_k R / (D + x_k) at x_{k+1} = D - R^2 / (D + x_k). The force
// is the Coulomb attraction between all sphere charges and all plate images.
double image_charge_force(double R, double V, double d, int n_images) {
  const double D = R + d;
  std::vector<double> q{4.0 * constants::pi * constants::eps0 * R * V}, x{D};
  for (int k = 0; k < n_images; ++k) {
    const double s = D + x.back();
    q.push_back(q.back() * R / s);
    x.push_back(D - R * R / s);
  }
  double F = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i)
    for (std::size_t j = 0; j < q.size(); ++j)
      F += q[i] * q[j] / (4.0 * constants::pi * constants::eps0 * (x[i] + x[j]) * (x[i] + x[j]));
  return F;
}
}  // namespace

// Image charges converge geometrically with ratio ~exp(-alpha) per image; 4000 images give
// exp(-4000*alpha) < 1e-30 at d = 0.01R (alpha = 0.141). Both methods are exact, so they must
// agree to rounding: 1e-10 relative (accumulated rounding of ~1e7 summed terms is ~1e-12).
TEST(ElectricForce, ExactMatchesImageCharges) {
  for (double x : {0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0}) {
    const double fe = force_exact(kR, kV, x * kR);
    const double fi = image_charge_force(kR, kV, x * kR, 4000);
    EXPECT_NEAR(fe / fi, 1.0, 1e-10) << "d/R = " << x;
  }
}

// F = 1/2 V^2 |dC/dd|: the closed-form derivative must equal a central finite difference
// of the capacitance series. Step 1e-4 d gives truncation ~1e-8 relative and rounding
// ~1e-16/1e-4 ~ 1e-12; tolerance 1e-7.
TEST(ElectricForce, ExactEqualsHalfV2dCdd) {
  for (double x : {0.01, 0.1, 1.0, 10.0}) {
    const double d = x * kR, h = 1e-4 * d;
    const double dC = (sphere_plane_capacitance(kR, d + h) - sphere_plane_capacitance(kR, d - h)) / (2 * h);
    EXPECT_NEAR(force_exact(kR, kV, d) / (-0.5 * kV * kV * dC), 1.0, 1e-7) << "d/R = " << x;
  }
}

// Small gaps: F -> pi eps0 R V^2 / d. The next terms (derived in docs/electric.md by a Mellin
// expansion of the csch series) are -(1/3) ln(R/d) - c0, so the leading-order relative error
// is bounded by (d/R)(ln(R/d)/3 + 1): 0.33 % at d = 0.001R, 2.5 % at d = 0.01R (measured
// 0.28 % and 2.1 %). With the two correction terms the neglected terms are O((d/R) ln(R/d))
// absolute, i.e. O((d/R)^2 ln(R/d)) relative; bound (d/R)^2 ln(R/d) (measured 3e-7 at 0.001R,
// 2e-5 at 0.01R, i.e. ~0.2x the bound -- a wrong log coefficient or c0 would fail by 100x).
TEST(ElectricForce, SmallGapAsymptote) {
  for (double x : {0.001, 0.002, 0.005, 0.01}) {
    const double d = x * kR;
    const double fe = force_exact(kR, kV, d);
    const double lead = force_small_gap_asymptote(kR, kV, d, true);
    EXPECT_LT(std::fabs(lead / fe - 1.0), x * (std::log(1.0 / x) / 3.0 + 1.0)) << "d/R = " << x;
    EXPECT_GT(lead, fe);  // the log correction is negative
    const double two = force_small_gap_asymptote(kR, kV, d, false);
    EXPECT_NEAR(two / fe, 1.0, x * x * std::log(1.0 / x)) << "d/R = " << x;
  }
  // Even very small gaps converge (about 37/alpha ~ 12000 terms at d = 1e-5 R).
  const double d = 1e-5 * kR;
  EXPECT_NEAR(force_small_gap_asymptote(kR, kV, d) / force_exact(kR, kV, d), 1.0, 1e-8);
  // Below d = 1e-6 R force_exact switches to the asymptote; the series just above the switch
  // must agree with it (continuity, 1e-11) so the switch is invisible.
  const double d1 = 1.0001e-6 * kR, d0 = 0.9999e-6 * kR;
  EXPECT_NEAR(force_small_gap_asymptote(kR, kV, d1) / force_exact(kR, kV, d1), 1.0, 1e-11);
  EXPECT_NEAR(force_exact(kR, kV, d0) * d0 / (force_exact(kR, kV, d1) * d1), 1.0, 1e-6);
}

// Large gaps: grounded sphere, plate at V  <=>  sphere at -V, plate grounded. The sphere
// carries q = C V with C = 4 pi eps0 R (1 + R/(2D) + O(R^2/D^2)) and is attracted by its
// image at distance 2D: F = q^2 / (4 pi eps0 (2D)^2) -> pi eps0 R^2 V^2 / D^2 (1 + R/D).
// The neglected terms are O((R/D)^2), so the tolerance is 2 (R/D)^2.
TEST(ElectricForce, LargeGapLimit) {
  for (double x : {10.0, 30.0, 100.0, 1000.0}) {
    const double d = x * kR, D = kR + d;
    const double fe = force_exact(kR, kV, d);
    EXPECT_NEAR(force_large_gap_asymptote(kR, kV, d) / fe, 1.0, 2.0 * (kR / D) * (kR / D)) << "d/R = " << x;
    // Point charge and image only, to leading order: error O(R/D).
    const double point = constants::pi * constants::eps0 * kR * kR * kV * kV / (D * D);
    EXPECT_NEAR(point / fe, 1.0, 1.5 * kR / D);
  }
}

// The thesis series as printed is exactly -2 x the force (missing 1/2 in eq. 2.5.24 and the
// sign convention of the x-component). After the correction it must agree with the exact
// force to summation accuracy over the requested gap range; the brief asks 0.5 %, we test
// 1e-9 because the corrected series is an exact representation too.
TEST(ElectricForce, ThesisSeriesMisprintAndCorrection) {
  for (double x : {0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0}) {
    const double d = x * kR;
    const double fe = force_exact(kR, kV, d);
    EXPECT_NEAR(force_series_as_printed(kR, kV, d) / fe, -2.0, 2e-9) << "d/R = " << x;
    EXPECT_NEAR(force_series(kR, kV, d) / fe, 1.0, 1e-9) << "d/R = " << x;
  }
}

// Locating the misprint: a direct quadrature of eq. 2.5.32 (with V1, V2 of eq. 2.5.30) gives
// the same value as the closed forms 2.5.40/2.5.41, so those are faithful and the factor
// -2 comes from eqs. 2.5.24/2.5.28 (missing 1/2 of the Maxwell stress, x-component sign).
// Gauss–Legendre would be nicer; the midpoint rule with 20000 panels on a smooth integrand
// (d >= 0.3R) is accurate to ~1e-8; tolerance 1e-6.
TEST(ElectricForce, ThesisIntegralEqualsItsClosedForm) {
  for (double x : {0.3, 1.0, 3.0}) {
    const double d = x * kR;
    const double eta = std::acosh(1.0 + x), c = std::cosh(eta);
    const double V1 = std::sinh(eta) / (2.0 * std::sqrt(2.0));
    const int nmax = static_cast<int>(40.0 / eta) + 10, N = 20000;
    double sum = 0.0;
    for (int i = 0; i < N; ++i) {
      const double t = -1.0 + (i + 0.5) * 2.0 / N;
      double p0 = 1.0, p1 = t, series = 0.0;
      for (int n = 0; n <= nmax; ++n) {
        double Pn = n == 0 ? 1.0 : t;
        if (n >= 2) {
          Pn = ((2 * n - 1) * t * p1 - (n - 1) * p0) / n;
          p0 = p1;
          p1 = Pn;
        }
        const double m = n + 0.5;
        series += m / std::tanh(m * eta) * std::exp(-m * eta) * Pn;  // v_n P_n, eq. 2.5.36
      }
      const double V2 = std::pow(c - t, 1.5) * series;
      sum += (t * c - 1.0) / std::pow(c - t, 3) * (V1 + V2) * (V1 + V2) * (2.0 / N);
    }
    const double F_integral = 4.0 * constants::pi * constants::eps0 * kV * kV * sum;  // eq. 2.5.31/2.5.32
    EXPECT_NEAR(F_integral / force_series_as_printed(kR, kV, d), 1.0, 1e-6) << "d/R = " << x;
  }
}

// Eq. 2.5.42 with a = 0.45 is 1.8 x the small-gap limit (0.45 * 4 = 1.8 vs 1). Its ratio to
// the exact force grows monotonically with d: measured 1.805 at 0.001R, 1.837 at 0.01R,
// 2.06 at 0.1R, 3.73 at R (table in docs/electric.md). We check the documented range
// [1.80, 2.10] on 0.001R..0.1R and monotonic growth, and that a = 0.25 reproduces the
// leading small-gap limit within the bound of SmallGapAsymptote.
TEST(ElectricForce, ApproxErrorRange) {
  double prev = 0.0;
  for (double x : {0.001, 0.003, 0.01, 0.03, 0.1}) {
    const double r = force_approx(kR, kV, x * kR) / force_exact(kR, kV, x * kR);
    EXPECT_GE(r, 1.80);
    EXPECT_LE(r, 2.10);
    EXPECT_GT(r, prev);
    prev = r;
  }
  EXPECT_NEAR(force_approx(kR, kV, 1e-3 * kR, 0.25) / force_exact(kR, kV, 1e-3 * kR), 1.0, 0.0033);
  ElectricForceParams p;
  p.model = ForceModel::approx;
  EXPECT_DOUBLE_EQ(force(p, kR, kV, kR), force_approx(kR, kV, kR));
}

// Scale invariance: F depends on d/R only and on V^2 (dimensional analysis, exact).
TEST(ElectricForce, ScalingAndSymmetry) {
  EXPECT_NEAR(force_exact(2 * kR, kV, 0.2 * kR) / force_exact(kR, kV, 0.1 * kR), 1.0, 1e-13);
  EXPECT_NEAR(force_exact(kR, 2 * kV, kR) / force_exact(kR, kV, kR), 4.0, 1e-13);
  EXPECT_DOUBLE_EQ(force_exact(kR, -kV, kR), force_exact(kR, kV, kR));
}

// Eq. 2.5.43 and 2.5.10 by hand: d = l + 600 nm / 5; F_bulk = 5 eps0 alpha R^2 V^2 / dl^2.
TEST(ElectricForce, EffectiveGapAndBulk) {
  EXPECT_DOUBLE_EQ(effective_gap(0.0), 120e-9);
  EXPECT_DOUBLE_EQ(effective_gap(1e-6), 1.12e-6);
  const double fb = force_bulk(kR, kV, 4.0);
  EXPECT_NEAR(fb, 5.0 * constants::eps0 * 4.0 * kR * kR * kV * kV / (600e-9 * 600e-9), 1e-20);
  EXPECT_THROW(effective_gap(-1e-6), InputError);
  EXPECT_THROW(force_exact(-kR, kV, kR), InputError);
  EXPECT_THROW(force_exact(kR, kV, 0.0), InputError);
  EXPECT_THROW(parse_force_model("exactly"), InputError);
  EXPECT_EQ(parse_force_model("series"), ForceModel::series);
}

// Independent check of the bulk force by the energy method: the toner layer on the SiOx layer
// is a parallel-plate capacitor C(x) = eps_r eps0 A / x per particle area A = alpha R^2; at
// fixed V the force is F = 1/2 V^2 |dC/dx| at x = d_l (central difference, 1e-8). The printed
// eq. 2.5.10 is twice that (sigma E instead of sigma E / 2), like eq. 2.5.24.
TEST(ElectricForce, BulkByEnergyMethod) {
  const double alpha = 2.0 * std::sqrt(3.0), A = alpha * kR * kR, dl = 600e-9, er = 5.0;
  auto C = [&](double x) { return er * constants::eps0 * A / x; };
  const double h = 1e-6 * dl;
  const double F_energy = 0.5 * kV * kV * (C(dl - h) - C(dl + h)) / (2 * h);
  EXPECT_NEAR(force_bulk_corrected(kR, kV) / F_energy, 1.0, 1e-8);
  EXPECT_NEAR(force_bulk(kR, kV) / F_energy, 2.0, 2e-8);
}

// The table reproduces the exact series; Hermite interpolation with O(h^4) derivatives on a
// 0.004 log-spacing has error ~1e-10; tolerance 1e-9. Also reports the speed-up.
TEST(ElectricForce, TableMatchesExact) {
  const ElectricForceTable table;
  double worst = 0.0;
  for (int i = 0; i < 997; ++i) {
    const double x = std::exp(std::log(1e-4) + (std::log(1e3) - std::log(1e-4)) * (i + 0.37) / 997.0);
    worst = std::max(worst, std::fabs(table.force(kR, kV, x * kR) / force_exact(kR, kV, x * kR) - 1.0));
  }
  EXPECT_LT(worst, 1e-9);
  std::printf("[ElectricForce] table worst relative error %.2e\n", worst);
}

// CLI contract (CLI.md): force electric --json prints force_N; bad input exits 2.
TEST(ElectricForce, Cli) {
  const std::string cli = NIPDEM_CLI_PATH;
  FILE* p = popen((cli + " force electric --radius 5e-6 --voltage 40 --gap 5e-6 --model exact --json").c_str(), "r");
  ASSERT_NE(p, nullptr);
  char buf[4096];
  std::string out;
  while (fgets(buf, sizeof buf, p)) out += buf;
  EXPECT_EQ(pclose(p), 0);
  EXPECT_NE(out.find("\"force_N\""), std::string::npos) << out;
  const auto pos = out.find("\"force_N\":");
  const double f = std::stod(out.substr(pos + 10));
  EXPECT_NEAR(f / force_exact(kR, kV, kR), 1.0, 1e-12);
  auto rc = [&](const std::string& args) {
    const int s = std::system((cli + " " + args + " >/dev/null 2>&1").c_str());
    return WEXITSTATUS(s);
  };
  EXPECT_EQ(rc("force electric --radius -5e-6 --voltage 40 --gap 1e-6 --json"), 2);
  EXPECT_EQ(rc("force electric --radius 5e-6 --voltage 40 --gap 0 --json"), 2);
  EXPECT_EQ(rc("force electric --radius 5e-6 --voltage 40 --gap 1e-6 --model bogus --json"), 2);
  EXPECT_EQ(rc("force electric --radius 5e-6 --voltage 40 --gap 1e-6 --model series --json"), 0);
}
