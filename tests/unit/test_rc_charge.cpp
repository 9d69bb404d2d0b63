// Charge model: exact RC update along the shortest conducting path (thesis §2.5.5).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "nipdem/core/error.hpp"
#include "nipdem/models/rc_charge.hpp"
#include "nipdem/solvers/conduction_path.hpp"

using namespace nipdem;
using namespace nipdem::charge;
using nipdem::conduction::ConductionPaths;
using nipdem::conduction::Contact;

// A particle at the drum connected to the roller through k toner–toner contacts: the path
// resistance from the path search is k R_tt + R_ti and the capacitor voltage follows
// u(t) = V (1 - exp(-t/tau)), tau = (k R_tt + R_ti) C_td (R_td = inf). Checked at t = tau, 3 tau
// with many small steps (the update is exact, so 1e-12 relative), and the time constant is
// recovered from the simulated curve by a log-slope to 1e-9.
TEST(RcCharge, ChargesWithChainTimeConstant) {
  RcChargeParams p;
  p.R_tt_ohm = 3.7e10;
  p.R_ti_ohm = 2.0e10;
  p.C_td_F = 3.9e-16;
  p.R_td_ohm = INFINITY;
  p.validate();
  for (int k : {1, 5, 15}) {
    std::vector<Contact> chain;
    for (int i = 0; i < k; ++i) chain.push_back({i, i + 1, p.R_tt_ohm});
    ConductionPaths cp(k + 1);
    cp.update(chain, {{0, p.R_ti_ohm}});
    const double Rp = cp.path_resistance(k);
    const double tau = (k * p.R_tt_ohm + p.R_ti_ohm) * p.C_td_F;
    ASSERT_NEAR(Rp * p.C_td_F / tau, 1.0, 1e-14);
    const double V = 40.0;
    const int steps = 1000;
    const double dt = tau / steps;
    double u = 0.0;
    for (int s = 0; s < steps; ++s) u = rc_update(u, V, Rp, DrumCoupling::capacitor, p, dt);
    EXPECT_NEAR(u / (V * (1 - std::exp(-1.0))), 1.0, 1e-12);
    const double u1 = u;
    for (int s = 0; s < 2 * steps; ++s) u = rc_update(u, V, Rp, DrumCoupling::capacitor, p, dt);
    EXPECT_NEAR(u / (V * (1 - std::exp(-3.0))), 1.0, 1e-12);
    // tau from the curve: (V - u1)/(V - u3) = exp(2 tau / tau)
    EXPECT_NEAR(2.0 * tau / std::log((V - u1) / (V - u)) / tau, 1.0, 1e-9);
    EXPECT_NEAR(rc_time_constant(Rp, DrumCoupling::capacitor, p) / tau, 1.0, 1e-14);

    // Break the path (remove the roller-side contact): the charge is kept exactly.
    chain.erase(chain.begin());
    cp.update(chain, {{0, p.R_ti_ohm}});
    ASSERT_FALSE(cp.connected(k));
    const double kept = u;
    for (int s = 0; s < 100; ++s) u = rc_update(u, V, cp.path_resistance(k), DrumCoupling::capacitor, p, 10 * tau);
    EXPECT_EQ(u, kept);
    // Also when the drum voltage goes back to 0: an isolated capacitor keeps its charge.
    EXPECT_EQ(rc_update(u, 0.0, conduction::ConductionPaths(1).path_resistance(0), DrumCoupling::capacitor, p, tau), kept);
  }
}

// The exponential update is exact for any step: one step of 5 tau equals 5000 small ones, and
// with a leak (contact) it matches an RK4 integration of C du/dt = (V-u)/R - u/R_td
// (RK4 with dt = tau/200 has error ~1e-11; tolerance 1e-9).
TEST(RcCharge, ExactUpdateAndLeak) {
  RcChargeParams p;
  p.C_td_F = 3.9e-16;
  p.R_td_ohm = 2e11;  // a strong leak to make it visible
  const double Rp = 5.9e11, V = 40.0;
  const double tau = rc_time_constant(Rp, DrumCoupling::contact, p);
  EXPECT_NEAR(tau, p.C_td_F * Rp * p.R_td_ohm / (Rp + p.R_td_ohm), 1e-25);
  double big = rc_update(0.0, V, Rp, DrumCoupling::contact, p, 5 * tau);
  double small = 0.0;
  for (int s = 0; s < 5000; ++s) small = rc_update(small, V, Rp, DrumCoupling::contact, p, tau / 1000);
  EXPECT_NEAR(big / small, 1.0, 1e-11);
  auto f = [&](double u) { return ((V - u) / Rp - u / p.R_td_ohm) / p.C_td_F; };
  double u = 0.0;
  const double h = tau / 200;
  for (int s = 0; s < 1000; ++s) {
    const double k1 = f(u), k2 = f(u + 0.5 * h * k1), k3 = f(u + 0.5 * h * k2), k4 = f(u + h * k3);
    u += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  EXPECT_NEAR(u / big, 1.0, 1e-9);
  EXPECT_NEAR(rc_steady_voltage(V, Rp, DrumCoupling::contact, p), V * p.R_td_ohm / (Rp + p.R_td_ohm), 1e-12);
  // No path but touching the drum: discharges through the leak with tau = C R_td.
  const double u0 = 30.0;
  EXPECT_NEAR(rc_update(u0, V, kNoPath, DrumCoupling::contact, p, p.C_td_F * p.R_td_ohm), u0 * std::exp(-1.0), 1e-12);
  // Beyond d50: not a capacitor, state unchanged.
  EXPECT_EQ(rc_update(u0, V, Rp, DrumCoupling::none, p, tau), u0);
}

// Per-contact calibration: a chain with <k> contacts reproduces the calibrated R exactly.
TEST(RcCharge, ContactCalibrationReproducesR) {
  RcChargeParams p;
  calibrate_contacts(p, 5.9e11, 15.0, 1.0);
  EXPECT_NEAR(chain_resistance(15, p) / 5.9e11, 1.0, 1e-14);
  calibrate_contacts(p, 6.3e11, 12.0, 3.0);
  EXPECT_NEAR(p.R_ti_ohm / p.R_tt_ohm, 3.0, 1e-14);
  EXPECT_NEAR(chain_resistance(12, p) / 6.3e11, 1.0, 1e-14);
  const auto b = RcChargeParams::black();
  EXPECT_NEAR(chain_resistance(15, b) * b.C_td_F, 5.9e11 * 3.9e-16, 1e-18);  // RC = 0.23 ms
  EXPECT_NO_THROW(b.validate());
}

// The batch form equals the scalar one element by element.
TEST(RcCharge, BatchEqualsScalar) {
  const auto p = RcChargeParams::black();
  std::vector<double> u{0.0, 10.0, 20.0, 5.0};
  const std::vector<double> R{5.9e11, kNoPath, 1e11, 3e11};
  const std::vector<DrumCoupling> c{DrumCoupling::capacitor, DrumCoupling::capacitor, DrumCoupling::none, DrumCoupling::contact};
  std::vector<double> ref = u;
  for (std::size_t i = 0; i < u.size(); ++i) ref[i] = rc_update(u[i], 40.0, R[i], c[i], p, 1e-4);
  rc_update_all(u, R, c, 40.0, p, 1e-4);
  EXPECT_EQ(u, ref);
  std::vector<double> shorter{1.0};
  EXPECT_THROW(rc_update_all(shorter, R, c, 40.0, p, 1e-4), InputError);
}

TEST(RcCharge, BadValues) {
  RcChargeParams p;
  p.R_tt_ohm = -1;
  EXPECT_THROW(p.validate(), InputError);
  p = {};
  p.C_td_F = 0;
  EXPECT_THROW(p.validate(), InputError);
  p = {};
  EXPECT_THROW(rc_update(0, 40, 1e11, DrumCoupling::capacitor, p, -1e-9), InputError);
  EXPECT_THROW(rc_update(0, 40, -1e11, DrumCoupling::capacitor, p, 1e-9), InputError);
  EXPECT_THROW(calibrate_contacts(p, 0.0, 10), InputError);
  EXPECT_THROW(chain_resistance(-1, p), InputError);
}
