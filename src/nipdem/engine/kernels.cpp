#include "nipdem/engine/kernels.hpp"

#include <cmath>
#include <cstring>

#include "nipdem/core/target_clones.hpp"

namespace nipdem::engine::detail {

namespace {

// cos d and sin d by their Taylor polynomials to d^6 and d^7 (truncation below 3e-21 for
// |d| <= 1e-2 rad, i.e. exact in double precision), Horner form, constant coefficients (no
// divide); then the rotation of (c, s) and one Newton step towards c^2 + s^2 = 1, so rounding
// does not accumulate in the length. Inlined into the scalar and the vector loop alike.
[[gnu::always_inline]] inline void rotate_small(double& c, double& s, double d) {
  constexpr double c2 = -1.0 / 2.0, c4 = 1.0 / 24.0, c6 = -1.0 / 720.0;
  constexpr double s3 = -1.0 / 6.0, s5 = 1.0 / 120.0, s7 = -1.0 / 5040.0;
  const double d2 = d * d;
  const double cd = 1.0 + d2 * (c2 + d2 * (c4 + d2 * c6));
  const double sd = d + d * d2 * (s3 + d2 * (s5 + d2 * s7));
  const double c1 = c * cd - s * sd, s1 = s * cd + c * sd;
  const double f = 1.5 - 0.5 * (c1 * c1 + s1 * s1);
  c = c1 * f;
  s = s1 * f;
}

template <bool kNewmark, bool kPeriodic>
[[gnu::always_inline]] inline void drift(const DriftParams& p, std::size_t b0, std::size_t b1, const BodyArrays& a) {
  const double dt = p.dt, h = 0.5 * dt, L = p.x_hi - p.x_lo;
#pragma omp simd
  for (std::size_t b = b0; b < b1; ++b) {
    // One division per mass and inertia, kept for the closing half-kick.
    const double im = 1.0 / a.mass[b], iI = 1.0 / a.inertia[b];
    a.inv_mass[b] = im;
    a.inv_inertia[b] = iI;
    double dth;
    if constexpr (kNewmark) {
      // eq. 4.2.17: x += dt v + dt^2/2 a_n ; v += dt a_n
      const double ax = a.fx[b] * im, ay = a.fy[b] * im, al = a.torque[b] * iI;
      a.x[b] += dt * a.vx[b] + 0.5 * dt * dt * ax;
      a.y[b] += dt * a.vy[b] + 0.5 * dt * dt * ay;
      dth = dt * a.omega[b] + 0.5 * dt * dt * al;
      a.vx[b] += dt * ax; a.vy[b] += dt * ay; a.omega[b] += dt * al;
    } else {
      // velocity Verlet, first half: kick by dt/2, drift by dt
      a.vx[b] += h * a.fx[b] * im; a.vy[b] += h * a.fy[b] * im; a.omega[b] += h * a.torque[b] * iI;
      a.x[b] += dt * a.vx[b]; a.y[b] += dt * a.vy[b];
      dth = dt * a.omega[b];
    }
    a.theta[b] += dth;
    a.dtheta[b] = dth;
    double c = a.cth[b], s = a.sth[b];
    rotate_small(c, s, dth);
    const bool small = std::fabs(dth) <= 1e-2;
    a.cth[b] = small ? c : a.cth[b];
    a.sth[b] = small ? s : a.sth[b];
    if constexpr (kPeriodic) {  // a body moves far less than L per step
      double x = a.x[b];
      x = x >= p.x_hi ? x - L : x;
      x = x < p.x_lo ? x + L : x;
      a.x[b] = x;
    }
  }
}

}  // namespace

void rotate_by(double& c, double& s, double d) {
  if (std::fabs(d) <= 1e-2) {
    rotate_small(c, s, d);
    return;
  }
  const double cd = std::cos(d), sd = std::sin(d);
  const double c1 = c * cd - s * sd, s1 = s * cd + c * sd;
  const double f = 1.5 - 0.5 * (c1 * c1 + s1 * s1);
  c = c1 * f;
  s = s1 * f;
}

namespace {
template <bool kPeriodic, bool kWeighted>
double max_disp2(const double* __restrict x, const double* __restrict y, const double* __restrict x0,
                 const double* __restrict y0, const double* __restrict w, std::size_t k0, std::size_t k1, double L) {
  const double hL = 0.5 * L;
  std::int64_t m = 0;  // the bits of 0.0
  for (std::size_t k = k0; k < k1; ++k) {
    double dx = x[k] - x0[k];
    const double dy = y[k] - y0[k];
    if constexpr (kPeriodic) {
      dx = dx > hL ? dx - L : dx;
      dx = dx < -hL ? dx + L : dx;
    }
    // d2 >= 0 (or NaN), and non-negative doubles order as their bit patterns do: an integer
    // max, which vectorises (a floating max does not without -ffinite-math-only). A NaN's bits
    // exceed every finite value's and infinity's, so it comes out as the max.
    std::int64_t b;
    double d2 = dx * dx + dy * dy;
    if constexpr (kWeighted) d2 *= w[k];
    std::memcpy(&b, &d2, sizeof b);
    m = b > m ? b : m;
  }
  double r;
  std::memcpy(&r, &m, sizeof r);
  return r;
}
}  // namespace

NIPDEM_TARGET_CLONES
double max_displacement2(const double* x, const double* y, const double* x0, const double* y0, std::size_t k0,
                         std::size_t k1, bool periodic, double L) {
  return periodic ? max_disp2<true, false>(x, y, x0, y0, nullptr, k0, k1, L)
                  : max_disp2<false, false>(x, y, x0, y0, nullptr, k0, k1, L);
}

NIPDEM_TARGET_CLONES
double max_weighted_displacement2(const double* x, const double* y, const double* x0, const double* y0,
                                  const double* w, std::size_t k0, std::size_t k1, bool periodic, double L) {
  return periodic ? max_disp2<true, true>(x, y, x0, y0, w, k0, k1, L) : max_disp2<false, true>(x, y, x0, y0, w, k0, k1, L);
}

NIPDEM_TARGET_CLONES
void drift_bodies(const DriftParams& p, std::size_t b0, std::size_t b1, const BodyArrays& a) {
  if (p.newmark) {
    if (p.periodic) drift<true, true>(p, b0, b1, a);
    else drift<true, false>(p, b0, b1, a);
  } else {
    if (p.periodic) drift<false, true>(p, b0, b1, a);
    else drift<false, false>(p, b0, b1, a);
  }
}

}  // namespace nipdem::engine::detail
