// Binary collisions in the engine against eq. 2.2.7 (restitution and contact time), for every
// collision type of the black preset and both integrators.
#include <gtest/gtest.h>

#include <cmath>

#include "nipdem/engine/simulation.hpp"
#include "nipdem/models/collision_params.hpp"
#include "support/engine_fixtures.hpp"

using namespace nipdem;
using namespace nipdem::engine;
using namespace nipdem::models;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kR = 5.25e-6, kRho = 1700.0;
const double kMass = kRho * 4.0 / 3.0 * kPi * kR * kR * kR;

Interaction make(double k, double e, double m_red) {
  Interaction ia;
  ia.contact = contact_params(k, e, m_red, 0.5, 0.3);
  return ia;
}

BodySpec disc(Vec2 pos, Vec2 vel) { return test::disc_body(kR, kRho, pos, vel); }
}  // namespace

class CollisionTest : public ::testing::TestWithParam<Integrator> {};

TEST_P(CollisionTest, DiscDiscMatchesEq227) {
  // toner-toner: k = 56 N/m, e = 0.85 (Table 4.2 / §4.2.1)
  const double mred = kMass / 2, k = 56, e = 0.85;
  EngineParams p;
  p.integrator = GetParam();
  p.interactions = {make(k, e, mred)};
  const double tn = contact_time(k, p.interactions[0].contact.gamma, mred);
  p.dt = tn / 1000;  // 1000 steps per contact: Newmark (first order) error ~0.1 %
  Simulation sim(p, {});
  sim.add_body(disc({0, 0}, {0.003, 0}));
  sim.add_body(disc({2 * kR + 1e-8, 0}, {-0.003, 0}));
  auto ov = [&] { return 2 * kR - (sim.bodies().x[1] - sim.bodies().x[0]); };
  auto vn = [&] { return sim.bodies().vx[1] - sim.bodies().vx[0]; };
  const test::Collision r = test::measure_collision(sim, ov, vn, p.dt, 200000, 10);
  // 1 % tolerance (the issue's): both schemes are far more accurate at 1000 steps/contact.
  EXPECT_NEAR(r.e, e, 0.01 * e);
  EXPECT_NEAR(r.tn, tn, 0.01 * tn);
  // Momentum is conserved exactly by the pair force (Newton's third law).
  EXPECT_NEAR(sim.bodies().vx[0] + sim.bodies().vx[1], 0.0, 1e-15);
}

TEST_P(CollisionTest, DiscWallMatchesEq227ForRollerAndDrum) {
  struct Case { const char* name; double k, e; bool rough; };
  // toner-imaging roller (k = 117, e = 0.58; smooth cylinder and a land of the rough roller)
  // and toner-DI drum (k = 126, e = 0.95), Table 4.2 / §4.2.1.
  for (Case c : {Case{"roller", 117, 0.58, false}, Case{"roller_rough", 117, 0.58, true}, Case{"drum", 126, 0.95, false}}) {
    SCOPED_TRACE(c.name);
    EngineParams p;
    p.integrator = GetParam();
    p.interactions = {make(56, 0.85, kMass / 2), make(c.k, c.e, kMass)};
    const double tn = contact_time(c.k, p.interactions[1].contact.gamma, kMass);
    p.dt = tn / 1000;
    geometry::Wall w;
    w.kind = geometry::Wall::Kind::cylinder;
    w.name = c.name;
    w.radius = 0.02;
    w.centre = {0, -0.02};
    w.interaction = 1;
    double surface = 0.0;  // y of the surface below the disc
    if (c.rough) {
      geometry::set_pyramid_roughness(w, 15e-6, 50e-6, 20e-6);
      // put the middle of land 0 of period 0 at the top (angle pi/2)
      w.angle = kPi / 2;
      w.phase = -0.5 * w.profile[1].x;
    }
    Simulation sim(p, {w});
    sim.add_body(disc({0, surface + kR + 1e-8}, {0, -0.003}));
    // overlap with the surface feature under the disc (for the rough roller, a chord of the
    // base circle: it lies up to 2.5 nm below the circle, more than the 0.3 nm peak overlap)
    std::vector<geometry::WallHit> hits;
    auto ov = [&] {
      hits.clear();
      sim.walls()[0].query({sim.bodies().x[0], sim.bodies().y[0]}, kR, 1e-6, hits);
      double o = -1;
      for (auto& h : hits) o = std::max(o, -h.gap);
      return o;
    };
    auto vn = [&] { return sim.bodies().vy[0]; };
    const test::Collision r = test::measure_collision(sim, ov, vn, p.dt, 200000, 10);
    EXPECT_NEAR(r.e, c.e, 0.01 * c.e);
    EXPECT_NEAR(r.tn, tn, 0.01 * tn);
  }
}

INSTANTIATE_TEST_SUITE_P(Integrators, CollisionTest,
                         ::testing::Values(Integrator::velocity_verlet, Integrator::newmark_explicit),
                         [](const auto& info) {
                           return info.param == Integrator::velocity_verlet ? std::string("VelocityVerlet")
                                                                            : std::string("NewmarkExplicit");
                         });
