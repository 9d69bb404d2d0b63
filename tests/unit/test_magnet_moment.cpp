// Tests of the magnetisation curve and eq. 4.5.1 (models/magnetisation.hpp).
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/models/magnetisation.hpp"

using namespace nipdem;
using namespace nipdem::magnet;

TEST(MagnetMoment, BlackTonerSaturationMomentIsEq451) {
  // Eq. 4.5.1 by hand: (4/3) pi (5.25e-6)^3 * 0.135 * 4.5e5 = 3.6822e-11 A m^2; §2.4.2 quotes
  // 3.7e-11 (two digits). Exact formula: 1e-12 relative; thesis rounding: 1 %.
  const auto p = black_toner();
  const double R = 5.25e-6;
  const double hand = 4.0 / 3.0 * constants::pi * R * R * R * 0.135 * 4.5e5;
  EXPECT_NEAR(saturation_moment(p, R), hand, 1e-12 * hand);
  EXPECT_NEAR(saturation_moment(p, R), 3.7e-11, 0.01 * 3.7e-11);
  // At and above B_sat the induced moment equals the saturation moment.
  EXPECT_NEAR(norm(induced_moment(p, R, {0.0, 0.15})), hand, 1e-12 * hand);
  EXPECT_NEAR(norm(induced_moment(p, R, {0.3, -0.4})), hand, 1e-12 * hand);
}

TEST(MagnetMoment, CurveIsLinearThenSaturatedAndAlongB) {
  // M = Ms |B|/B_sat below B_sat, Ms above, direction of B; continuous at B_sat. Exact: 1e-12.
  const auto p = color_toner();
  const Vec2 e{0.6, 0.8};
  for (double b : {0.0, 0.1, 0.325, 0.649999, 0.65, 0.9, 2.0}) {
    const Vec2 M = magnetisation(p, b * e);
    const double expect = p.Ms_A_per_m * std::min(b / p.B_sat_T, 1.0);
    EXPECT_NEAR(norm(M), expect, 1e-12 * p.Ms_A_per_m) << b;
    if (b > 0) {
      EXPECT_NEAR(cross(M, e), 0.0, 1e-9) << b;
      EXPECT_GT(dot(M, e), 0.0);
    }
  }
  // Colour toner d50 (R = 6 um) at saturation: 4/3 pi R^3 * 0.025 * 1.65e6 = 3.73e-11 A m^2.
  EXPECT_NEAR(saturation_moment(p, 6e-6), 3.7322e-11, 1e-4 * 3.7322e-11);
}

TEST(MagnetMoment, ClusterEqualVolumeRadius) {
  // Three equal spheres of radius r have the volume of one sphere of radius 3^(1/3) r; unequal
  // members: (sum r^3)^(1/3). Exact: 1e-15 relative.
  const std::array<double, 3> eq{3e-6, 3e-6, 3e-6};
  EXPECT_NEAR(equal_volume_radius(eq), std::cbrt(3.0) * 3e-6, 1e-15 * 3e-6);
  const std::array<double, 3> un{2e-6, 3e-6, 4e-6};
  EXPECT_NEAR(equal_volume_radius(un), std::cbrt(8.0 + 27.0 + 64.0) * 1e-6, 1e-15 * 5e-6);
  const std::array<double, 2> bad{3e-6, -1e-6};
  EXPECT_THROW(equal_volume_radius(bad), InputError);
  EXPECT_THROW(equal_volume_radius(std::span<const double>{}), InputError);
}

TEST(MagnetMoment, ValidateRejectsOutOfRange) {
  MagnetisationParams p = black_toner();
  EXPECT_NO_THROW(validate(p));
  p.eta = 1.5;
  EXPECT_THROW(validate(p), InputError);
  p = black_toner();
  p.B_sat_T = 0.0;
  EXPECT_THROW(validate(p), InputError);
  p = black_toner();
  p.Ms_A_per_m = -1.0;
  try {
    validate(p, "toner.black");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Ms_A_per_m"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("toner.black"), std::string::npos);
  }
}
