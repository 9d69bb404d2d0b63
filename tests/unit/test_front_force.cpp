// Front-particle force balance (thesis §2.5.4): each part of the net force equals its model
// evaluated independently, and the crossing distance separates drum-ward from roller-ward.
#include <gtest/gtest.h>

#include <cmath>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/front_force.hpp"
#include "nipdem/models/electric_force.hpp"
#include "nipdem/models/magnet_field.hpp"

using namespace nipdem;
using namespace nipdem::experiments;
using namespace nipdem::nip;

TEST(FrontForce, PartsEqualTheirModels) {
  ExperimentOptions e;  // black preset
  FrontForceOptions f;
  const FrontForceModel m = make_front_force_model(e, f);
  EXPECT_DOUBLE_EQ(m.radius_m, 3.5e-6);  // d95/2 of Table 2.1 black (preset toner.d_small_m)
  EXPECT_DOUBLE_EQ(m.voltage_V, 40.0);   // no [print] in the preset: the §2.5.1 voltage
  EXPECT_DOUBLE_EQ(m.cfg.gap, 240e-6);
  const double x = -150e-6, l = 4e-6;
  const FrontForcePoint p = m.at(x, l);
  // Centre at distance R_drum + l + R from the drum centre.
  const Vec2 c = m.cfg.electric.drum_centre;
  EXPECT_NEAR(std::hypot(x - c.x, p.y_m - c.y), m.cfg.drum_radius + l + m.radius_m, 1e-12);
  const double d = electric::effective_gap(l, 600e-9, 5.0);  // eq. 2.5.43 with the SiOx layer
  const double ny = (c.y - p.y_m) / (m.cfg.drum_radius + l + m.radius_m);
  EXPECT_NEAR(p.electric_exact_N, electric::force_exact(3.5e-6, 40.0, d) * ny, 1e-20);
  EXPECT_NEAR(p.electric_printed_N / p.electric_exact_N, 2.0, 1e-6);  // docs/electric.md: printed = 2x
  const magnet::Sample s = m.field->at({x, p.y_m});
  EXPECT_DOUBLE_EQ(p.magnetic_N, magnet::induced_dipole_force(m.cfg.magnet.toner, 3.5e-6, s).y);
  EXPECT_LT(p.magnetic_N, 0.0);  // the knife pulls towards the roller
  EXPECT_DOUBLE_EQ(p.net_exact_N(), p.electric_exact_N + p.magnetic_N);
}

TEST(FrontForce, CrossingSeparatesDrumwardFromRollerward) {
  ExperimentOptions e;
  e.preset = "color";
  const FrontForceModel m = make_front_force_model(e, {});
  for (double x : {-300e-6, -150e-6, 0.0}) {
    const double l = m.crossing(x, false);
    ASSERT_TRUE(std::isfinite(l));
    EXPECT_GT(m.at(x, 0.99 * l).net_exact_N(), 0.0);
    EXPECT_LT(m.at(x, 1.01 * l).net_exact_N(), 0.0);
    EXPECT_GT(m.crossing(x, true), l);  // the doubled (printed) force wins further out
  }
}

TEST(FrontForce, RefusesTheGapThroughSetAndBadOptions) {
  ExperimentOptions e;
  e.sets = {"geometry.gap_m=1e-4"};
  EXPECT_THROW(make_front_force_model(e, {}), InputError);
  FrontForceOptions f;
  f.x_max_m = f.x_min_m;
  EXPECT_THROW(make_front_force_model({}, f), InputError);
  FrontForceOptions g;
  g.voltage_V = std::nan("");
  EXPECT_THROW(make_front_force_model({}, g), InputError);
}
