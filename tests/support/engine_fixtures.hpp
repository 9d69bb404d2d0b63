// Small fixtures the engine tests, the fault tests and the validation studies share: a body of
// one disc, a plane wall, the measurement of one binary collision (restitution and contact time,
// eq. 2.2.7) and a random cloud of discs for the neighbour list. One definition each, so that
// the collision tests and the time-step study measure the same way.
#pragma once
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "nipdem/core/rng.hpp"
#include "nipdem/engine/simulation.hpp"

namespace nipdem::test {

// A body of one disc of radius r [m] and density rho [kg/m^3] at `pos` [m] moving with `vel` [m/s].
inline engine::BodySpec disc_body(double r, double rho, Vec2 pos, Vec2 vel = {}) {
  engine::BodySpec s;
  s.offsets = {{0, 0}};
  s.radii = {r};
  s.density = rho;
  s.position = pos;
  s.velocity = vel;
  return s;
}

// A plane wall through `point` with the unit `normal` pointing into the domain, contact law
// `interaction` (index into EngineParams::interactions).
inline geometry::Wall plane_wall(Vec2 point, Vec2 normal, int interaction = 1, const std::string& name = "plane") {
  geometry::Wall w;
  w.kind = geometry::Wall::Kind::plane;
  w.name = name;
  w.point = point;
  w.normal = normal;
  w.interaction = interaction;
  return w;
}

struct Collision {
  double e;   // restitution |v_n after / v_n before|
  double tn;  // contact time [s]
};

// Steps `sim` (time step dt [s]) through one collision, at most `max_steps` steps, then
// `steps_after` more so the velocity after the contact is integrated. `overlap()` is positive
// in contact, `vn()` the normal relative velocity. The contact starts and ends where the
// overlap changes sign, located by linear interpolation between steps (error O(dt^2)).
inline Collision measure_collision(engine::Simulation& sim, const std::function<double()>& overlap,
                                   const std::function<double()>& vn, double dt, int max_steps, int steps_after) {
  const double v0 = vn();
  double t_in = -1, t_out = -1, prev = overlap(), t_prev = 0;
  for (int i = 0; i < max_steps && t_out < 0; ++i) {
    sim.step();
    const double ov = overlap();
    if (prev <= 0 && ov > 0) t_in = t_prev + dt * (-prev) / (ov - prev);
    if (prev > 0 && ov <= 0 && t_in >= 0) t_out = t_prev + dt * prev / (prev - ov);
    prev = ov;
    t_prev = sim.time();
  }
  for (int i = 0; i < steps_after; ++i) sim.step();
  return {std::fabs(vn() / v0), t_out - t_in};
}

// n discs uniform in [0, box)^2 with radii uniform in [2, 5] um; consecutive groups of
// `discs_per_body` share a body (pairs within a body are never listed).
struct DiscCloud {
  std::vector<double> x, y, r;
  std::vector<int> body;
};
inline DiscCloud random_discs(int n, double box, std::uint64_t seed, int discs_per_body = 1) {
  Rng rng(seed);
  DiscCloud c;
  for (int i = 0; i < n; ++i) {
    c.x.push_back(rng.uniform(0, box));
    c.y.push_back(rng.uniform(0, box));
    c.r.push_back(rng.uniform(2e-6, 5e-6));
    c.body.push_back(i / discs_per_body);
  }
  return c;
}

}  // namespace nipdem::test
