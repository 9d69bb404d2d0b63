// Magnetisation calibration (thesis §4.5, Table 2.2): Ms and the saturation flux of the
// linear-saturated curve are recovered from synthetic VSM loops, with and without demagnetisation.
#include <gtest/gtest.h>

#include <cmath>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/experiments/calibrate_magnetisation.hpp"

using namespace nipdem;
using namespace nipdem::calibrate;

namespace {
void expect_recovers(const magnet::MagnetisationParams& p, const MagnetisationOptions& o, double noise, std::uint64_t seed) {
  const Record r = synthetic_vsm_record(p, o, 3.0 * p.B_sat_T / constants::mu0, 80, noise, seed);
  const MagnetisationFit f = calibrate_magnetisation(r, o);
  EXPECT_TRUE(f.converged);
  // 3 standard errors of the fit (seeded draw)
  EXPECT_NEAR(f.Ms_A_per_m, p.Ms_A_per_m, 3 * f.Ms_std_A_per_m);
  EXPECT_NEAR(f.B_sat_T, p.B_sat_T, 3 * f.B_sat_std_T);
  EXPECT_LT(f.B_sat_std_T, 0.02 * p.B_sat_T);  // informative: 1 % noise on 160 rows
}
}  // namespace

TEST(MagnetisationCalibration, RecoversTable22Pigments) {
  expect_recovers(magnet::black_toner(), {}, 0.01 * 4.5e5, 1);   // FO2: 4.5e5 A/m, 0.15 T
  expect_recovers(magnet::color_toner(), {}, 0.01 * 1.65e6, 2);  // caFe: 1.65e6 A/m, 0.65 T
}

TEST(MagnetisationCalibration, DemagnetisationCorrectionRecoversTheIntrinsicCurve) {
  MagnetisationOptions o;
  o.demag_factor = 1.0 / 3.0;  // a spherical sample
  o.volume_fraction = 0.135;   // toner sample, eta of black toner
  const magnet::MagnetisationParams p = magnet::black_toner();
  expect_recovers(p, o, 0.01 * 0.135 * 4.5e5, 3);
  // Fitted against the applied field instead, B_sat moves up by mu0 N eta Ms (docs/calibration.md).
  MagnetisationOptions bulk = o;
  bulk.demag_factor = 0.0;
  const Record r = synthetic_vsm_record(p, o, 3.0 * p.B_sat_T / constants::mu0, 80, 0.0, 3);
  const MagnetisationFit f = calibrate_magnetisation(r, bulk);
  EXPECT_NEAR(f.B_sat_T, p.B_sat_T + constants::mu0 * o.demag_factor * 0.135 * p.Ms_A_per_m, 1e-6 * p.B_sat_T);  // noiseless: exact
  EXPECT_NEAR(f.Ms_A_per_m, p.Ms_A_per_m, 1e-6 * p.Ms_A_per_m);
}

TEST(MagnetisationCalibration, StandardErrorsCoverTheTruth) {
  // 40 seeds: truth within 1 standard error 68.3 %; accept 18-36 of 40 (see the friction test).
  const magnet::MagnetisationParams p = magnet::black_toner();
  int in_ms = 0, in_bs = 0;
  for (int seed = 1; seed <= 40; ++seed) {
    const Record r = synthetic_vsm_record(p, {}, 2.0 * p.B_sat_T / constants::mu0, 40, 0.02 * p.Ms_A_per_m, seed);
    const MagnetisationFit f = calibrate_magnetisation(r, {});
    in_ms += std::fabs(f.Ms_A_per_m - p.Ms_A_per_m) < f.Ms_std_A_per_m;
    in_bs += std::fabs(f.B_sat_T - p.B_sat_T) < f.B_sat_std_T;
  }
  EXPECT_GE(in_ms, 18);
  EXPECT_LE(in_ms, 36);
  EXPECT_GE(in_bs, 18);
  EXPECT_LE(in_bs, 36);
}

TEST(MagnetisationCalibration, RejectsARecordThatDoesNotSaturate) {
  const magnet::MagnetisationParams p = magnet::black_toner();
  const Record r = synthetic_vsm_record(p, {}, 0.5 * p.B_sat_T / constants::mu0, 20, 100.0, 1);
  EXPECT_THROW(calibrate_magnetisation(r, {}), InputError);
  MagnetisationOptions bad;
  bad.demag_factor = 1.5;
  EXPECT_THROW(bad.validate(), InputError);
}
