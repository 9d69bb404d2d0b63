// The one contact evaluator (models::contact_force: eq. 2.2.5 + eqs. 2.2.9-2.2.11 + eq. 2.3.2)
// and the contact's stored elastic energy (models::contact_energy), by hand-computed values,
// against its parts, by force = -dE/dx, and as the engine's pair and wall loops use them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "nipdem/engine/simulation.hpp"
#include "nipdem/models/collision_params.hpp"
#include "nipdem/models/contact.hpp"
#include "nipdem/models/hamaker.hpp"
#include "support/engine_fixtures.hpp"

using namespace nipdem;
using namespace nipdem::models;

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
// k = 100 N/m, gamma = 2e-3 N s/m, ks = 2k/7, mu_s = 0.5, mu_d = 0.3 (not mass-proportional).
const ContactParams kCp{.k = 100.0, .gamma = 2e-3, .ks = 200.0 / 7.0, .mu_s = 0.5, .mu_d = 0.3};
// A = 1e-19 J, D0 = 0.4 nm, cut-off 4 nm, surface separation.
const HamakerParams kHp{.hamaker_J = 1e-19, .min_separation_m = 4e-10, .cutoff_m = 4e-9};
constexpr double kR1 = 5e-6, kR2 = 3e-6, kDt = 1e-9;
// Relative tolerance for hand values: a few roundings of double arithmetic.
constexpr double kRel = 1e-13;
}  // namespace

TEST(ContactEvaluator, StickingContactByHand) {
  // xi = 10 nm, approaching at 1 cm/s, slipping at 2 cm/s, stretch 1 nm from before.
  TangentialState st{.eta = 1e-9, .sliding = false};
  const ContactForce f = contact_force<true>(kCp, kHp, kR1, kR2, 1e-8, -0.01, 0.02, 0.0, kDt, st);
  // F_n = k xi - gamma v_n = 100 * 1e-8 + 2e-3 * 0.01 = 2.1e-5 N.
  EXPECT_NEAR(f.fn, 2.1e-5, kRel * 2.1e-5);
  // eta = 1e-9 + 0.02 * 1e-9 = 1.02e-9 m; |ks eta| = 2.914e-8 N <= mu_s F_n = 1.05e-5 N: sticks.
  EXPECT_NEAR(f.ft, -200.0 / 7.0 * 1.02e-9, kRel * 200.0 / 7.0 * 1.02e-9);
  EXPECT_NEAR(st.eta, 1.02e-9, kRel * 1.02e-9);
  EXPECT_FALSE(st.sliding);
  // Overlapping: d = D0, F = A R1 R2 / ((R1 + R2) 12 D0^2) = 1e-19 * 1.875e-6 / 1.92e-18 = 9.765625e-8 N.
  EXPECT_NEAR(f.fa, 9.765625e-8, kRel * 9.765625e-8);
}

TEST(ContactEvaluator, SlidingContactByHand) {
  // As above but the spring already holds 1 um: the trial force 2.857e-5 N exceeds mu_s F_n.
  TangentialState st{.eta = 1e-6, .sliding = false};
  const ContactForce f = contact_force<true>(kCp, kHp, kR1, kR2, 1e-8, -0.01, 0.02, 0.0, kDt, st);
  EXPECT_NEAR(f.fn, 2.1e-5, kRel * 2.1e-5);
  // Slides with the dynamic force against the stretch: F_t = -mu_d F_n = -6.3e-6 N; the spring
  // is held at the stretch that carries it: eta = 6.3e-6 / ks = 2.205e-7 m.
  EXPECT_NEAR(f.ft, -6.3e-6, kRel * 6.3e-6);
  EXPECT_NEAR(st.eta, 6.3e-6 * 7.0 / 200.0, kRel * 2.205e-7);
  EXPECT_TRUE(st.sliding);
  EXPECT_NEAR(f.fa, 9.765625e-8, kRel * 9.765625e-8);
  // A wall (R2 = inf): F = A R1 / (12 D0^2) = 1e-19 * 5e-6 / 1.92e-18 = 2.6041666e-7 N.
  TangentialState sw{};
  const ContactForce w = contact_force<true>(kCp, kHp, kR1, kInf, 1e-8, 0.0, 0.0, 0.0, kDt, sw);
  EXPECT_NEAR(w.fa, 5e-25 / 1.92e-18, kRel * 5e-25 / 1.92e-18);
  EXPECT_NEAR(w.fn, 1e-6, kRel * 1e-6);
}

TEST(ContactEvaluator, OpenContactHasOnlyAdhesionAndLosesItsHistory) {
  // A gap of 1 nm: no spring, no friction, d = 1e-9 + 4e-10 m; the history ends (eq. 2.2.11).
  TangentialState st{.eta = 3e-9, .sliding = true};
  const ContactForce f = contact_force<true>(kCp, kHp, kR1, kR2, -1e-9, -0.5, 0.7, 0.0, kDt, st);
  EXPECT_EQ(f.fn, 0.0);
  EXPECT_EQ(f.ft, 0.0);
  EXPECT_NEAR(f.fa, 1.875e-25 / (12 * 1.4e-9 * 1.4e-9), kRel * f.fa);
  EXPECT_EQ(st.eta, 0.0);
  EXPECT_FALSE(st.sliding);
  // Beyond the cut-off: nothing at all.
  const ContactForce far = contact_force<true>(kCp, kHp, kR1, kR2, -5e-9, 0.0, 0.0, 0.0, kDt, st);
  EXPECT_EQ(far.fa, 0.0);
}

TEST(ContactEvaluator, WithoutAdhesionIsThePlainLawOfItsParts) {
  // contact_force<false> and contact_force<true> with A = 0 both equal normal_force +
  // tangential_force, bit for bit, over a sequence that sticks, slides and re-sticks, with
  // mass-proportional damping (the reduced mass is passed through).
  ContactParams cp = kCp;
  cp.mass_proportional = true;
  cp.gamma = 3e5;    // [1/s]
  cp.gamma_t = 1e4;  // [1/s]
  HamakerParams off = kHp;
  off.hamaker_J = 0.0;
  const double m = 7e-13;
  TangentialState a{}, b{}, ref{};
  bool slid = false, stuck_again = false;
  for (int s = 0; s < 60; ++s) {
    const double xi = 1e-8 * (1.0 + 0.3 * std::sin(0.2 * s)), vn = 0.01 * std::cos(0.3 * s);
    const double vt = s < 40 ? 3.0 : -3.0;  // slides after a few steps, reverses at 40
    const ContactForce fa = contact_force<false>(cp, kHp, kR1, kR2, xi, vn, vt, m, kDt, a);
    const ContactForce fb = contact_force<true>(cp, off, kR1, kR2, xi, vn, vt, m, kDt, b);
    const bool was_sliding = ref.sliding;
    const double fn = normal_force(cp, xi, vn, m);
    const double ft = tangential_force(cp, ref, vt, fn, kDt, m);
    slid = slid || ref.sliding;
    stuck_again = stuck_again || (was_sliding && !ref.sliding);
    SCOPED_TRACE(s);
    EXPECT_EQ(fa.fn, fn);
    EXPECT_EQ(fa.ft, ft);
    EXPECT_EQ(fa.fa, 0.0);
    EXPECT_EQ(fb.fn, fn);
    EXPECT_EQ(fb.ft, ft);
    EXPECT_EQ(fb.fa, 0.0);
    EXPECT_EQ(a.eta, ref.eta);
    EXPECT_EQ(b.eta, ref.eta);
    EXPECT_EQ(a.sliding, ref.sliding);
    EXPECT_EQ(b.sliding, ref.sliding);
  }
  // The sequence covered both branches of the Coulomb cap and the return to sticking.
  EXPECT_TRUE(slid);
  EXPECT_TRUE(stuck_again);
}

TEST(ContactEvaluator, EnergyByHand) {
  // 1/2 k xi^2 + 1/2 ks eta^2 = 0.5*100*(2e-8)^2 + 0.5*(200/7)*(3e-9)^2 = 2e-14 + 1.2857142857e-16 J.
  const double e = 0.5 * 100 * 4e-16 + 0.5 * 200.0 / 7.0 * 9e-18;
  EXPECT_NEAR(contact_energy(kCp, 2e-8, 3e-9), e, kRel * e);
  EXPECT_EQ(contact_energy(kCp, 0.0, 3e-9), 0.0);    // touching, no overlap: nothing stored
  EXPECT_EQ(contact_energy(kCp, -1e-9, 3e-9), 0.0);  // open
}

TEST(ContactEvaluator, ForceIsMinusEnergyDerivative) {
  // Two discs on the x axis, i at x, j at 0: xi = R1 + R2 - x, n = +x. The undamped spring
  // force on i along x must be -dE/dx; the sticking tangential force on i along t must be
  // -dE/du for a tangential displacement u of the contact points (eta grows by u).
  // E is quadratic in x and u, so central differences carry no truncation error for any step h;
  // what is left is rounding: x ~ 8e-6 m carries ~2e-21 m, which is ~2e-11 of h = 0.1 xi at the
  // smallest xi (1 nm), and the energies' own relative rounding ~1e-16 grows by E/(E(x+h) -
  // E(x-h)) ~ xi/(4h) to ~1e-16. A tolerance of 1e-9 leaves a wide margin while catching any wrong
  // factor or sign.
  ContactParams cp = kCp;
  cp.gamma = 0.0;  // elastic part only (v_n = 0 anyway)
  for (const double xi : {1e-9, 1e-8, 5e-8}) {
    const double x = kR1 + kR2 - xi;
    const double eta0 = 2e-10;
    const double h = 0.1 * xi;
    auto E = [&](double xx, double eta) { return contact_energy(cp, kR1 + kR2 - xx, eta); };
    TangentialState st{.eta = eta0, .sliding = false};
    const double u = 1e-11;  // this step's tangential displacement: v_t dt
    const ContactForce f = contact_force<false>(cp, kHp, kR1, kR2, xi, 0.0, u / kDt, 0.0, kDt, st);
    const double dEdx = (E(x + h, st.eta) - E(x - h, st.eta)) / (2 * h);
    EXPECT_NEAR(f.fn, -dEdx, 1e-9 * f.fn) << "xi " << xi;
    const double hu = 0.1 * (eta0 + u);
    const double dEdu = (E(x, eta0 + u + hu) - E(x, eta0 + u - hu)) / (2 * hu);
    EXPECT_NEAR(f.ft, -dEdu, 1e-9 * std::fabs(f.ft)) << "xi " << xi;
  }
}

TEST(ContactEvaluator, ContactParamsDeriveGammaAndTangentialStiffness) {
  const ContactParams p = contact_params(56.0, 0.85, 2.6e-13, 0.5, 0.3);
  EXPECT_EQ(p.k, 56.0);
  EXPECT_EQ(p.ks, 2.0 * 56.0 / 7.0);  // eq. 4.3.11
  EXPECT_EQ(p.gamma, gamma_from_restitution(56.0, 2.6e-13, 0.85));
  EXPECT_NEAR(restitution(p.k, p.gamma, 2.6e-13), 0.85, 1e-12);
  EXPECT_EQ(p.mu_s, 0.5);
  EXPECT_EQ(p.mu_d, 0.3);
  EXPECT_EQ(p.gamma_t, 0.0);
  EXPECT_FALSE(p.mass_proportional);
  const ContactParams t = contact_params(56.0, 0.85, 2.6e-13, 0.5, 0.3, DampingConvention::thesis);
  EXPECT_NEAR(restitution(t.k, t.gamma, 2.6e-13, DampingConvention::thesis), 0.85, 1e-12);
}

TEST(ContactEvaluator, EnginePairAndWallLoopsApplyTheEvaluator) {
  // Two discs overlapping at rest above a plane wall that one of them presses into, with
  // adhesion: the engine's forces are the evaluator's magnitudes along the normals (the disc
  // forces are summed from one pair and one wall contact), and energy() is contact_energy.
  engine::EngineParams p;
  engine::Interaction tt{.name = "tt", .contact = kCp, .adhesion = kHp};
  engine::Interaction tw{.name = "tw", .contact = kCp, .adhesion = kHp};
  tw.contact.k = 150.0;
  tw.contact.ks = 300.0 / 7.0;
  tw.adhesion.hamaker_J = 2e-19;
  p.interactions = {tt, tw};
  p.dt = kDt;
  engine::Simulation sim(p, {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
  const double xi_w = 4e-9, xi_p = 6e-9;  // wall overlap of disc 0, pair overlap
  sim.add_body(test::disc_body(kR1, 1700, {0, kR1 - xi_w}));
  sim.add_body(test::disc_body(kR2, 1700, {0, kR1 - xi_w + kR1 + kR2 - xi_p}));
  sim.compute_forces();
  sim.update_adhesive_parts();
  EXPECT_EQ(sim.contacts(), 2);
  TangentialState s0{}, s1{};
  const ContactForce pair = contact_force<true>(kCp, kHp, kR1, kR2, xi_p, 0.0, 0.0, 0.0, kDt, s0);
  const ContactForce wall = contact_force<true>(tw.contact, tw.adhesion, kR1, kInf, xi_w, 0.0, 0.0, 0.0, kDt, s1);
  const auto& d = sim.discs();
  // Disc 1 (on top): pushed up by the pair spring, pulled down by cohesion.
  // The engine's overlaps are differences of positions ~1e-5 m (rounding ~2e-21 m), a relative
  // ~1e-12 of these nm overlaps: 1e-9 of the largest force term covers it.
  EXPECT_NEAR(d.fy[1], pair.fn - pair.fa, 1e-9 * pair.fn);
  EXPECT_NEAR(d.fay[1], -pair.fa, 1e-9 * pair.fa);
  // Disc 0: the pair pushes it down, the wall up; both pull it towards the other surface.
  EXPECT_NEAR(d.fy[0], -(pair.fn - pair.fa) + (wall.fn - wall.fa), 1e-9 * wall.fn);
  EXPECT_NEAR(d.fay[0], pair.fa - wall.fa, 1e-9 * wall.fa);
  EXPECT_EQ(d.fx[0], 0.0);
  EXPECT_EQ(d.tq[0], 0.0);
  const double e = contact_energy(kCp, xi_p, 0.0) + contact_energy(tw.contact, xi_w, 0.0);
  EXPECT_NEAR(sim.energy().elastic, e, 1e-9 * e);  // overlaps from positions again: as above
}

// Simulation::update_adhesive_parts (the Hamaker part of each disc's force, filled on request,
// not by each step): at rest, the part equals the force with adhesion minus the force of the
// same state without it (the springs and dashpots are the same, eq. 2.3.2 is the difference),
// for pairs overlapping, apart within the cut-off and beyond it, across a periodic seam, against
// a wall, on 1 and 2 threads; the pairs' parts sum to zero (actio = reactio).
TEST(ContactEvaluator, AdhesivePartsAreTheForceWithAdhesionMinusWithout) {
  // A row of 15 discs (radius 3 um) 2 nm above a floor, with surface gaps cycling over overlaps,
  // gaps within the 4 nm cut-off and beyond it, in a periodic box that closes the row across the
  // seam with a 1 nm gap.
  const double gaps[] = {-4e-9, -1e-9, 0.5e-9, 2e-9, 3.9e-9, 5e-9};
  const double r = 3e-6;
  std::vector<double> xs{1e-6};
  for (int k = 0; k < 14; ++k) xs.push_back(xs.back() + 2 * r + gaps[k % 6]);
  const double box = xs.back() + 2 * r + 1e-9 - xs.front();  // x_lo = 0: the seam gap is 1 nm
  for (int threads : {1, 2}) {
    auto make = [&](double hamaker_J) {
      engine::EngineParams p;
      engine::Interaction tt{.name = "tt", .contact = kCp, .adhesion = kHp};
      tt.adhesion.hamaker_J = hamaker_J;
      engine::Interaction tw = tt;
      tw.name = "tw";
      p.interactions = {tt, tw};
      p.dt = kDt;
      p.threads = threads;
      p.periodic_x = true;
      p.x_lo = 0.0;
      p.x_hi = box;
      return engine::Simulation(p, {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
    };
    engine::Simulation on = make(kHp.hamaker_J), off = make(0.0);
    for (std::size_t k = 0; k < xs.size(); ++k) {
      const double y = r + 2e-9;
      on.add_body(test::disc_body(r, 1700, {xs[k], y}));
      off.add_body(test::disc_body(r, 1700, {xs[k], y}));
    }
    on.compute_forces();
    off.compute_forces();
    on.update_adhesive_parts();
    const auto& a = on.discs();
    const auto& b = off.discs();
    double fmax = 0.0, sum_x = 0.0;
    int nonzero = 0;
    for (std::size_t i = 0; i < a.x.size(); ++i) fmax = std::max({fmax, std::fabs(a.fx[i]), std::fabs(a.fy[i])});
    for (std::size_t i = 0; i < a.x.size(); ++i) {
      // each force is a sum of at most 3 terms of size <= fmax: a few roundings of it
      EXPECT_NEAR(a.fax[i], a.fx[i] - b.fx[i], 1e-14 * fmax) << "disc " << i << ", " << threads << " threads";
      EXPECT_NEAR(a.fay[i], a.fy[i] - b.fy[i], 1e-14 * fmax) << "disc " << i << ", " << threads << " threads";
      sum_x += a.fax[i];
      nonzero += a.fax[i] != 0.0 ? 1 : 0;
    }
    EXPECT_NEAR(sum_x, 0.0, 1e-14 * fmax * static_cast<double>(a.x.size()));  // the floor pulls along y only
    EXPECT_GE(nonzero, 12);              // 13 of the 15 discs have a partner within the cut-off
    // disc 0: pulled to +x by disc 1 (overlapping: at D0) and to -x across the seam (1 nm); the
    // gaps are differences of positions ~1e-4 m (rounding ~1e-20 m, 1e-11 of the nm distances)
    const double want = hamaker_force(kHp, r, r, -4e-9) - hamaker_force(kHp, r, r, 1e-9);
    EXPECT_NEAR(a.fax.front(), want, 1e-9 * want);
    const double floor = hamaker_force(kHp, r, kInf, 2e-9);  // the floor pulls each disc down
    for (std::size_t i = 0; i < a.x.size(); ++i) EXPECT_NEAR(a.fay[i], -floor, 1e-9 * floor) << "disc " << i;
  }
}
