// Adhesion calibration (thesis §4.4): the log-normal median and spread of the forward model are
// recovered from centrifugal detachment records (binomial counting noise) and AFM pull-off lists.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/calibrate_adhesion.hpp"

using namespace nipdem;
using namespace nipdem::calibrate;

namespace {
// Green toner on SiOx (fig. 4.18): most particles below a few nN, all off between 0.2 and 1 uN.
const LogNormal kTruth{std::log(2e-9), 1.6};
AdhesionOptions centrifuge() {
  AdhesionOptions o;
  o.particle_mass_kg = 1.3e-12;  // a 12 um sphere of 1400 kg/m^3
  o.rotor_radius_m = 0.05;
  o.initial_count = 500;
  return o;
}
std::vector<double> omegas() {  // F_c from 0.05 nN to 1 uN, log-spaced
  std::vector<double> w;
  for (int k = 0; k <= 20; ++k) w.push_back(std::sqrt(5e-11 * std::pow(2e4, k / 20.0) / (1.3e-12 * 0.05)));
  return w;
}
}  // namespace

TEST(AdhesionCalibration, LogNormalHelpersMatchHandValues) {
  const LogNormal d{std::log(1e-9), 0.5};
  EXPECT_NEAR(d.median(), 1e-9, 1e-24);
  EXPECT_NEAR(d.mean(), 1e-9 * std::exp(0.125), 1e-22);
  EXPECT_NEAR(d.survival(1e-9), 0.5, 1e-15);
  EXPECT_NEAR(d.survival(d.quantile(0.9)), 0.1, 1e-9);
  EXPECT_NEAR(centrifugal_force(2e-12, 1000.0, 0.1), 2e-7, 1e-20);  // m w^2 r
}

TEST(AdhesionCalibration, CentrifugalRecoversMedianAndSpread) {
  AdhesionOptions o = centrifuge();
  o.initial_count = 2000;
  const Record r = synthetic_centrifugal_record(kTruth, o, omegas(), 2000, 7);
  const AdhesionResult a = calibrate_adhesion(r, o);
  EXPECT_TRUE(a.converged);
  // 3 standard errors of the fit (seeded draw)
  EXPECT_NEAR(a.dist.mu_ln, kTruth.mu_ln, 3 * a.mu_ln_std);
  EXPECT_NEAR(a.dist.sigma_ln, kTruth.sigma_ln, 3 * a.sigma_ln_std);
  EXPECT_LT(a.mu_ln_std, 0.1);  // 2000 particles: the median to ~5 %
  EXPECT_EQ(a.config_key, "adhesion.drum_force_N");
  EXPECT_DOUBLE_EQ(a.config_value_N, a.median_N);
  EXPECT_LT(a.config_lo_N, a.median_N);
  EXPECT_GT(a.config_hi_N, a.median_N);
}

TEST(AdhesionCalibration, AfmRecoversMedianAndSpread) {
  AdhesionOptions o;
  o.method = AdhesionMethod::afm;
  const Record r = synthetic_afm_record(kTruth, 60, 3);
  const AdhesionResult a = calibrate_adhesion(r, o);
  // 3 standard errors (seeded draw)
  EXPECT_NEAR(a.dist.mu_ln, kTruth.mu_ln, 3 * a.mu_ln_std);
  EXPECT_NEAR(a.dist.sigma_ln, kTruth.sigma_ln, 3 * a.sigma_ln_std);
  EXPECT_NEAR(a.mu_ln_std, a.dist.sigma_ln / std::sqrt(60.0), 1e-12);  // s / sqrt(n)
}

TEST(AdhesionCalibration, StandardErrorsCoverTheTruth) {
  // 40 seeds each: the truth within 1 standard error 68.3 % of the time; accept 18-36 of 40
  // (+-3 binomial sd; errors off by a factor 2 either way fail, see the friction test).
  int c_mu = 0, c_s = 0, a_mu = 0;
  AdhesionOptions o = centrifuge();
  o.initial_count = 1000;
  AdhesionOptions afm;
  afm.method = AdhesionMethod::afm;
  for (int seed = 1; seed <= 40; ++seed) {
    const AdhesionResult c = calibrate_adhesion(synthetic_centrifugal_record(kTruth, o, omegas(), 1000, seed), o);
    c_mu += std::fabs(c.dist.mu_ln - kTruth.mu_ln) < c.mu_ln_std;
    c_s += std::fabs(c.dist.sigma_ln - kTruth.sigma_ln) < c.sigma_ln_std;
    const AdhesionResult a = calibrate_adhesion(synthetic_afm_record(kTruth, 30, seed), afm);
    a_mu += std::fabs(a.dist.mu_ln - kTruth.mu_ln) < a.mu_ln_std;
  }
  EXPECT_GE(c_mu, 18);
  EXPECT_LE(c_mu, 36);
  EXPECT_GE(c_s, 18);
  EXPECT_LE(c_s, 36);
  EXPECT_GE(a_mu, 18);
  EXPECT_LE(a_mu, 36);
}

TEST(AdhesionCalibration, ScalesToD50AndNamesTheRollerKey) {
  AdhesionOptions o;
  o.method = AdhesionMethod::afm;
  o.substrate = "roller";
  o.measured_diameter_m = 8e-6;
  o.d50_m = 10.5e-6;
  const AdhesionResult a = calibrate_adhesion(synthetic_afm_record(kTruth, 20, 1), o);
  EXPECT_EQ(a.config_key, "adhesion.roller_force_N");
  EXPECT_NEAR(a.config_value_N / a.median_N, 10.5 / 8.0, 1e-12);  // eq. 2.3.2: F ∝ R
  o.d50_m = 0;  // one of the pair alone is refused
  EXPECT_THROW(calibrate_adhesion(synthetic_afm_record(kTruth, 20, 1), o), InputError);
}

TEST(AdhesionCalibration, RejectsARecordWithoutDetachment) {
  AdhesionOptions o = centrifuge();
  const std::vector<double> low = {1.0, 2.0, 3.0, 4.0};  // F_c < 1e-12 N: nothing comes off
  const Record r = synthetic_centrifugal_record(kTruth, o, low, 500, 1);
  EXPECT_THROW(calibrate_adhesion(r, o), InputError);
}
