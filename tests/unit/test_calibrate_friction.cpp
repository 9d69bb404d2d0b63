// Friction calibration (thesis §4.3.1, eqs. 4.3.1-4.3.3): the forward model's mu_s, mu_d are
// recovered from noisy synthetic records within the stated standard errors, for both set-ups.
#include <gtest/gtest.h>

#include <cmath>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/calibrate_friction.hpp"

using namespace nipdem;
using namespace nipdem::calibrate;

TEST(FrictionCalibration, LoadForceAndCoefficientsFollowEqs431To433) {
  FrictionOptions o;  // thesis: 26 g sample, 211 g weight
  EXPECT_NEAR(load_force(o), 0.237 * 9.81, 1e-12);  // eq. 4.3.1
  EXPECT_NEAR(friction_coefficient(o, 0.19 * 0.237 * 9.81, load_force(o)), 0.19, 1e-12);  // eq. 4.3.2
  o.setup = FrictionSetup::capstan;
  o.weight_mass_kg = 0.1;
  EXPECT_NEAR(load_force(o), 0.981, 1e-12);
  // eq. 4.3.3: F_t / F_z = exp(mu pi/2); mu = 0.4 -> ratio 1.8745...
  EXPECT_NEAR(friction_force(o, 0.4, 1.0), std::exp(0.4 * M_PI / 2), 1e-12);
  EXPECT_NEAR(friction_coefficient(o, friction_force(o, 0.34, 0.981), 0.981), 0.34, 1e-12);
}

TEST(FrictionCalibration, PlateRecoversThesisResinValues) {
  FrictionOptions o;
  FrictionSynth s;  // mu_s 0.47, mu_d 0.19 (§4.3.1 toner-toner)
  const Record r = synthetic_friction_record(s, o, 11);
  const FrictionResult f = calibrate_friction(r, o);
  EXPECT_EQ(f.peaks.size(), 6u);  // 5 mm of stick-slip at 0.8 mm per stick: 6 complete sticks
  // 3 standard errors: a seeded draw, a 0.3 % chance to fail if the errors are right
  EXPECT_NEAR(f.mu_s, s.mu_s, 3 * f.mu_s_std);
  EXPECT_NEAR(f.mu_d, s.mu_d, 3 * f.mu_d_std);
  // the error bars are informative, not vacuous: below 3 % of the value
  EXPECT_LT(f.mu_s_std, 0.03 * s.mu_s);
  EXPECT_LT(f.mu_d_std, 0.03 * s.mu_d);
  EXPECT_NEAR(f.noise_N, s.noise_N, 0.2 * s.noise_N);  // MAD estimate of 4000 differences: ~2 % spread
}

TEST(FrictionCalibration, CapstanRecoversImagingRollerValues) {
  FrictionOptions o;
  o.setup = FrictionSetup::capstan;
  o.weight_mass_kg = 0.1;
  FrictionSynth s;
  s.mu_s = 0.58;  // §4.3.1 toner-imaging roller
  s.mu_d = 0.40;
  const Record r = synthetic_friction_record(s, o, 5);
  const FrictionResult f = calibrate_friction(r, o);
  // 3 standard errors, as above
  EXPECT_NEAR(f.mu_s, s.mu_s, 3 * f.mu_s_std);
  EXPECT_NEAR(f.mu_d, s.mu_d, 3 * f.mu_d_std);
  EXPECT_LT(f.mu_d_std, 0.02);
}

TEST(FrictionCalibration, StandardErrorsCoverTheTruth) {
  // Over 40 seeds the truth should lie within 1 standard error 68.3 % of the time (27.3 of 40,
  // binomial sd 2.9); we accept 18-36, i.e. +-3 sd: errors 2x too small (38 % coverage, ~15 of 40)
  // or 2x too large (95 %, ~38 of 40) fail.
  FrictionOptions o;
  FrictionSynth s;
  int in_s = 0, in_d = 0;
  const int n = 40;
  for (int seed = 100; seed < 100 + n; ++seed) {
    const FrictionResult f = calibrate_friction(synthetic_friction_record(s, o, seed), o);
    in_s += std::fabs(f.mu_s - s.mu_s) < f.mu_s_std;
    in_d += std::fabs(f.mu_d - s.mu_d) < f.mu_d_std;
  }
  EXPECT_GE(in_s, 18);
  EXPECT_LE(in_s, 36);
  EXPECT_GE(in_d, 18);
  EXPECT_LE(in_d, 36);
}

TEST(FrictionCalibration, MassUncertaintyPropagates) {
  FrictionOptions o;
  FrictionSynth s;
  const Record r = synthetic_friction_record(s, o, 3);
  const FrictionResult a = calibrate_friction(r, o);
  o.mass_std_kg = 0.0237;  // 10 % of the load
  const FrictionResult b = calibrate_friction(r, o);
  EXPECT_DOUBLE_EQ(a.mu_d, b.mu_d);
  EXPECT_NEAR(b.mu_d_std, std::hypot(a.mu_d_std, 0.1 * a.mu_d), 1e-12);  // relative errors add in quadrature
}

TEST(FrictionCalibration, RejectsRecordsItCannotRead) {
  FrictionOptions o;
  FrictionSynth s;
  s.x_end_m = 6e-3;  // no sliding plateau
  EXPECT_THROW(calibrate_friction(synthetic_friction_record(s, o, 1), o), InputError);
  FrictionSynth flat;
  flat.slip_rel = 1.0;  // no stick-slip drops at all
  flat.peak_jitter = 0.0;
  EXPECT_THROW(calibrate_friction(synthetic_friction_record(flat, o, 1), o), InputError);
  o.setup = FrictionSetup::capstan;
  o.weight_mass_kg = 10.0;  // the plateau force is below the hanging weight: not a capstan record
  FrictionOptions plate;
  EXPECT_THROW(calibrate_friction(synthetic_friction_record(FrictionSynth{}, plate, 1), o), InputError);
  EXPECT_THROW(parse_friction_setup("wedge"), InputError);
}
