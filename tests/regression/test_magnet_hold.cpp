// How much the magnet forces change while they are held between re-evaluations (the field
// force and the dipole-dipole pass are re-evaluated every 10 steps by default): measured on an
// assembly in a running nip, as the rms change over N steps relative to the rms force.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "nipdem/nip/nip.hpp"
#include "nipdem/nip/presets.hpp"

using namespace nipdem;
using namespace nipdem::nip;

namespace {
// rms |F(now) - F(then)| / rms |F(now)| over bodies present at both times.
double relative_change(const std::vector<std::int64_t>& ids0, const std::vector<double>& fx0, const std::vector<double>& fy0,
                       const BodyStore& b, const std::vector<double>& fx1, const std::vector<double>& fy1) {
  double num = 0, den = 0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < b.id.size(); ++i) {
    while (j < ids0.size() && ids0[j] < b.id[i]) ++j;
    if (j == ids0.size() || ids0[j] != b.id[i]) continue;
    num += std::pow(fx1[i] - fx0[j], 2) + std::pow(fy1[i] - fy0[j], 2);
    den += fx1[i] * fx1[i] + fy1[i] * fy1[i];
  }
  return std::sqrt(num / den);
}
}  // namespace

TEST(MagnetHold, ForcesChangeLittleOverTheHoldInterval) {
  // Softened contacts (stiffness_scale 0.01, so dt is 10x the real one: the change per step is
  // an upper bound for real stiffness). Assembly after 0.2 ms of the magnet pulling the layer.
  const std::vector<std::string> o = {"geometry.window_x_min_m=-150e-6", "geometry.window_x_max_m=150e-6",
                                      "collision.stiffness_scale=0.01", "output.vtk=false", "inflow.layer_thickness_m=60e-6",
                                      "magnet.field_interval_steps=1", "magnet.dipole_interval_steps=1"};
  NipRun run(parse_nip_config(preset_text("black"), "preset:black", o));
  run.advance_to(2e-4);
  auto& sim = run.sim();
  const auto& mf = dynamic_cast<const MagnetForce&>(*sim.forces()[0]);
  // bodies keep their order between exchanges (every 200 steps); stay inside one interval
  const std::vector<std::int64_t> ids0 = sim.bodies().id;
  const std::vector<double> dx0 = mf.dipole_fx(), dy0 = mf.dipole_fy();
  const std::vector<double> tx0 = sim.provider_fx(0), ty0 = sim.provider_fy(0);
  for (int n = 1; n <= 30; ++n) {
    sim.step();
    if (n != 10 && n != 30) continue;
    const double d = relative_change(ids0, dx0, dy0, sim.bodies(), mf.dipole_fx(), mf.dipole_fy());
    const double t = relative_change(ids0, tx0, ty0, sim.bodies(), sim.provider_fx(0), sim.provider_fy(0));
    std::printf("after %d steps: dipole-dipole force changed by %.3g (rms, relative), total magnet force by %.3g\n", n, d, t);
    // Measured 2026-11-23: after 10 steps 1.2 % (total) and 1.3 % (dipole part), after 30 steps
    // 3.4 % / 3.8 %: the change grows linearly with the hold. These are 10 steps of the softened
    // run (dt 10x the real one); at real stiffness the same 10 steps change the force ~10x less.
    // Bounds with margin for the chaotic flow: 3 % and 5 % at 10 steps.
    if (n == 10) {
      EXPECT_LT(t, 3e-2);
      EXPECT_LT(d, 5e-2);
    }
  }
}
