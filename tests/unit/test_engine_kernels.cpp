// The engine's kernels (engine/kernels.hpp) against what they evaluate: the pair loop's contact
// of one disc pair must give, bit for bit, what models::contact_force gives for that pair with
// the contact geometry written out plainly (thesis eqs. 2.2.5, 2.2.9-2.2.11, 2.3.2); the body
// drift, whatever clone (AVX-512, AVX2, generic) the machine picks, must be velocity Verlet's
// half-kick and drift (or Newmark explicit, eq. 4.2.17) exactly, and its rotation must keep
// (cos, sin) a unit vector that follows the accumulated angle.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "nipdem/engine/kernels.hpp"
#include "nipdem/models/contact.hpp"
#include "nipdem/models/hamaker.hpp"

using namespace nipdem;
using namespace nipdem::engine::detail;

namespace {

// Bitwise equality (a tolerance would hide a fused multiply-add or a reordering).
::testing::AssertionResult same_bits(double a, double b) {
  if (std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " vs " << b << " (differ in the last bits)";
}

struct Disc { double x, y, r, m, vx, vy, w; };
struct Pair { Disc a, c; double dx, dy, eta, slide; };

// n pairs with every case the law distinguishes: overlapping (sticking, sliding, about to
// slide), in adhesion range, beyond it, and history carried or empty.
std::vector<Pair> make_pairs(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Pair> out;
  for (int k = 0; k < n; ++k) {
    const double ri = 3e-6 + 4e-6 * u(rng), rj = 3e-6 + 4e-6 * u(rng);
    // surface gap: overlapping by up to 40 nm (half the pairs), within the 4 nm adhesion
    // cut-off, or beyond it
    const double gap = k % 4 == 3 ? 3.9e-9 * u(rng) : k % 4 == 2 ? 4.1e-9 + 4e-9 * u(rng) : -40e-9 * u(rng);
    const double phi = 6.283185307179586 * u(rng);
    const double dist = ri + rj + gap;
    Disc a{1e-4 * u(rng), 1e-4 * u(rng), ri, 1e-12 * (0.5 + u(rng)), u(rng) - 0.5, u(rng) - 0.5, 1e5 * (u(rng) - 0.5)};
    Disc c{a.x - dist * std::cos(phi), a.y - dist * std::sin(phi), rj, 1e-12 * (0.5 + u(rng)), u(rng) - 0.5,
           u(rng) - 0.5, 1e5 * (u(rng) - 0.5)};
    const double h = u(rng);
    const double eta = h < 0.3 ? 0.0 : 2e-7 * (u(rng) - 0.5);  // empty, or a stretch near the Coulomb cap
    const double slide = u(rng) < 0.3 ? 1.0 : 0.0;
    out.push_back({a, c, a.x - c.x, a.y - c.y, eta, slide});
  }
  return out;
}

// The pair's geometry and law written out plainly, with branches (what the engine computed
// before its pair kernel was rewritten for speed).
struct Expect { double fx, fy, ti, tj, fax, fay, eta, slide, touching; };
Expect scalar_pair(const models::ContactParams& cp, const models::HamakerParams& hp, bool adhesion, double dt,
                   const Disc& pi, const Disc& pj, double dx, double dy, double eta, double slide) {
  const double dist = std::sqrt(dx * dx + dy * dy);
  const double inv = 1.0 / dist;
  const double nx = dx * inv, ny = dy * inv;
  const double overlap = (pi.r + pj.r) - dist;
  const bool touching = overlap > 0.0;
  double li = 0.0, lj = 0.0, vn = 0.0, vt = 0.0, mred = 0.0;
  if (touching) {
    li = pi.r - 0.5 * overlap;
    lj = pj.r - 0.5 * overlap;
    const double vrx = (pi.vx + pi.w * li * ny) - (pj.vx - pj.w * lj * ny);
    const double vry = (pi.vy - pi.w * li * nx) - (pj.vy + pj.w * lj * nx);
    vn = vrx * nx + vry * ny;
    vt = -vrx * ny + vry * nx;
    mred = cp.mass_proportional ? pi.m * pj.m / (pi.m + pj.m) : 0.0;
  }
  models::TangentialState st{eta, slide};
  const models::ContactForce c = adhesion
                                     ? models::contact_force<true>(cp, hp, pi.r, pj.r, overlap, vn, vt, mred, dt, st)
                                     : models::contact_force<false>(cp, hp, pi.r, pj.r, overlap, vn, vt, mred, dt, st);
  Expect x{};
  if (touching) {
    x.fx = c.fn * nx - c.ft * ny;
    x.fy = c.fn * ny + c.ft * nx;
    x.ti = -li * c.ft;
    x.tj = -lj * c.ft;
  }
  if (adhesion) {
    x.fx -= c.fa * nx; x.fy -= c.fa * ny;
    x.fax = c.fa * nx; x.fay = c.fa * ny;
  }
  x.eta = st.eta;
  x.slide = st.sliding;
  x.touching = touching ? 1.0 : 0.0;
  return x;
}

Expect engine_pair(const models::ContactParams& cp, const models::HamakerParams& hp, bool adhesion, double dt,
                   const Pair& p) {
  Expect x{};
  x.eta = p.eta;
  x.slide = p.slide;
  const Disc &a = p.a, &c = p.c;
  if (adhesion)
    pair_contact<true>(cp, hp, dt, p.dx, p.dy, a.r, c.r, a.m, c.m, a.vx, a.vy, a.w, c.vx, c.vy, c.w, x.eta, x.slide, x.fx,
                       x.fy, x.ti, x.tj, x.fax, x.fay, x.touching);
  else
    pair_contact<false>(cp, hp, dt, p.dx, p.dy, a.r, c.r, a.m, c.m, a.vx, a.vy, a.w, c.vx, c.vy, c.w, x.eta, x.slide, x.fx,
                        x.fy, x.ti, x.tj, x.fax, x.fay, x.touching);
  return x;
}

void check_pairs(bool adhesion, bool mass_prop, int n) {
  models::ContactParams cp{.k = 50.0, .gamma = 3e-5, .ks = 100.0 / 7.0, .mu_s = 0.5, .mu_d = 0.3};
  if (mass_prop) { cp.gamma = 2e6; cp.gamma_t = 1e6; cp.mass_proportional = true; }
  const models::HamakerParams hp{.hamaker_J = 1e-19, .min_separation_m = 4e-10, .cutoff_m = 4e-9};
  const double dt = 2e-9;
  std::mt19937_64 rng(1234 + n + 2 * adhesion + mass_prop);
  const std::vector<Pair> pairs = make_pairs(rng, n);
  int touching = 0, sliding = 0, in_range = 0;
  for (int k = 0; k < n; ++k) {
    SCOPED_TRACE("pair " + std::to_string(k));
    const Pair& p = pairs[k];
    const Expect want = scalar_pair(cp, hp, adhesion, dt, p.a, p.c, p.dx, p.dy, p.eta, p.slide);
    touching += want.touching != 0.0;
    sliding += want.slide != 0.0;
    in_range += want.fax != 0.0 || want.fay != 0.0;
    const Expect got = engine_pair(cp, hp, adhesion, dt, p);
    EXPECT_TRUE(same_bits(got.fx, want.fx));
    EXPECT_TRUE(same_bits(got.fy, want.fy));
    EXPECT_TRUE(same_bits(got.ti, want.ti));
    EXPECT_TRUE(same_bits(got.tj, want.tj));
    EXPECT_TRUE(same_bits(got.eta, want.eta));
    EXPECT_TRUE(same_bits(got.slide, want.slide));
    EXPECT_TRUE(same_bits(got.touching, want.touching));
    if (adhesion) {
      EXPECT_TRUE(same_bits(got.fax, want.fax));
      EXPECT_TRUE(same_bits(got.fay, want.fay));
    }
  }
  // the sample covers the cases (else the comparison proves little)
  EXPECT_GT(touching, n / 4);
  EXPECT_GT(sliding, 0);
  EXPECT_LT(touching, n);
  if (adhesion) {
    EXPECT_GT(in_range, touching);
  }
}

}  // namespace

TEST(EngineKernels, PairContactIsTheScalarLawBitwise) {
  check_pairs(false, false, 64);
  check_pairs(true, false, 64);
  check_pairs(true, true, 64);
}

TEST(EngineKernels, PairContactOfTwoApproachingDiscs) {
  const models::ContactParams cp{.k = 50.0, .gamma = 3e-5, .ks = 100.0 / 7.0, .mu_s = 0.5, .mu_d = 0.3};
  const models::HamakerParams hp{};
  const Disc a{0, 0, 5e-6, 1e-12, -0.1, 0, 0}, c{-9.99e-6, 0, 5e-6, 1e-12, 0, 0, 0};  // approaching
  const Pair p{a, c, a.x - c.x, a.y - c.y, 0.0, 0.0};
  const Expect x = scalar_pair(cp, hp, false, 1e-9, a, c, p.dx, p.dy, 0.0, 0.0);
  const Expect got = engine_pair(cp, hp, false, 1e-9, p);
  EXPECT_EQ(got.touching, 1.0);
  // overlap 10 nm, approaching at 0.1 m/s: k xi + gamma v = 0.5 N + 3e-6 N, along +x on i
  EXPECT_NEAR(got.fx, 50.0 * 1e-8 + 3e-5 * 0.1, 1e-12);
  EXPECT_TRUE(same_bits(got.fx, x.fx));
}

TEST(EngineKernels, DriftIsVelocityVerletAndNewmarkExactly) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 203;  // not a multiple of any vector width
  for (const bool newmark : {false, true}) {
    std::vector<double> x(n), y(n), vx(n), vy(n), th(n), om(n), c(n), s(n), fx(n), fy(n), tq(n), m(n), I(n);
    for (int b = 0; b < n; ++b) {
      x[b] = 5e-4 * u(rng); y[b] = 1e-4 * u(rng); vx[b] = u(rng); vy[b] = u(rng);
      th[b] = 3 * u(rng); c[b] = std::cos(th[b]); s[b] = std::sin(th[b]);
      om[b] = b == 5 ? 2e7 : 1e5 * u(rng);  // body 5 turns by 4e-2 rad: the large-angle path
      fx[b] = 1e-6 * u(rng); fy[b] = 1e-6 * u(rng); tq[b] = 1e-17 * u(rng);
      m[b] = 1e-12 * (1.5 + u(rng)); I[b] = 1e-23 * (1.5 + u(rng));
    }
    auto x0 = x, y0 = y, vx0 = vx, vy0 = vy, th0 = th, om0 = om, c0 = c, s0 = s;
    std::vector<double> im(n), iI(n), dth(n);
    const BodyArrays a{x.data(), y.data(), vx.data(), vy.data(), th.data(), om.data(), c.data(), s.data(),
                       fx.data(), fy.data(), tq.data(), m.data(), I.data(), im.data(), iI.data(), dth.data()};
    const double dt = 2e-9, xlo = -5e-4, xhi = 5e-4;
    drift_bodies(DriftParams{dt, newmark, true, xlo, xhi}, 0, n, a);
    for (int b = 0; b < n; ++b) {
      SCOPED_TRACE("body " + std::to_string(b));
      const double imb = 1.0 / m[b], iIb = 1.0 / I[b];
      double X, Y, VX, VY, W, d;
      if (newmark) {  // eq. 4.2.17
        const double ax = fx[b] * imb, ay = fy[b] * imb, al = tq[b] * iIb;
        X = x0[b] + (dt * vx0[b] + 0.5 * dt * dt * ax);
        Y = y0[b] + (dt * vy0[b] + 0.5 * dt * dt * ay);
        d = dt * om0[b] + 0.5 * dt * dt * al;
        VX = vx0[b] + dt * ax; VY = vy0[b] + dt * ay; W = om0[b] + dt * al;
      } else {
        VX = vx0[b] + 0.5 * dt * fx[b] * imb; VY = vy0[b] + 0.5 * dt * fy[b] * imb; W = om0[b] + 0.5 * dt * tq[b] * iIb;
        X = x0[b] + dt * VX; Y = y0[b] + dt * VY;
        d = dt * W;
      }
      X = X >= xhi ? X - (xhi - xlo) : X;
      X = X < xlo ? X + (xhi - xlo) : X;
      EXPECT_TRUE(same_bits(x[b], X)); EXPECT_TRUE(same_bits(y[b], Y));
      EXPECT_TRUE(same_bits(vx[b], VX)); EXPECT_TRUE(same_bits(vy[b], VY)); EXPECT_TRUE(same_bits(om[b], W));
      EXPECT_TRUE(same_bits(dth[b], d));
      EXPECT_TRUE(same_bits(th[b], th0[b] + d));
      EXPECT_TRUE(same_bits(im[b], imb)); EXPECT_TRUE(same_bits(iI[b], iIb));
      if (std::fabs(d) > 1e-2) {  // left for rotate_by
        EXPECT_TRUE(same_bits(c[b], c0[b])); EXPECT_TRUE(same_bits(s[b], s0[b]));
        rotate_by(c[b], s[b], d);
      }
      // (cos, sin) follows the angle: one step's rotation within a few ulp (2.2e-16) of libm's
      EXPECT_NEAR(c[b], std::cos(th[b]), 1e-15);
      EXPECT_NEAR(s[b], std::sin(th[b]), 1e-15);
    }
  }
}

TEST(EngineKernels, RotationKeepsAUnitVectorOverAMillionSteps) {
  // A body spinning at 1e5 rad/s for 1e6 steps of 2 ns (200 rad): the Newton step keeps
  // c^2 + s^2 - 1 at rounding level, and (c, s) follows cos/sin of the angle 1e6 d: each step's
  // rotation is exact to a few ulp of 1 (the Taylor truncation is below 3e-21), so the angle
  // error grows at most ~4e-16 a step, 4e-10 after 1e6 steps.
  double c = 1.0, s = 0.0;
  const double d = 1e5 * 2e-9;
  const int steps = 1000000;
  for (int k = 0; k < steps; ++k) rotate_by(c, s, d);
  const double theta = steps * d;
  EXPECT_NEAR(c * c + s * s, 1.0, 4e-16);
  EXPECT_NEAR(c, std::cos(theta), 1e-9);
  EXPECT_NEAR(s, std::sin(theta), 1e-9);
}
