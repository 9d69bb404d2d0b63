// The engine's arithmetic on many items at once, in flat arrays: the integration of the bodies,
// compiled for AVX-512, AVX2 and generic x86-64 and picked at load time (GCC target_clones),
// with identical results on every machine (no FMA contraction: src/CMakeLists.txt); and the
// contact law of one disc pair as the engine's pair loop evaluates it (pair_contact).
//
// The pair loop (Simulation::pair_rows) evaluates each interacting pair where it finds it
// (docs/performance.md, eleventh pass). Until then it collected the pairs into batches of 64
// and ran the law on a batch at once, so that the compiler could evaluate several pairs per
// instruction; GCC 12 left that loop scalar, and the stores and gathers of the batch cost more
// than a predicted branch (packing 1.047x, nip 1.01-1.04x without them).
#pragma once
#include <cmath>
#include <cstdint>

#include "nipdem/models/contact.hpp"
#include "nipdem/models/hamaker.hpp"

namespace nipdem::engine::detail {

// One disc pair within contact or adhesion range (thesis eqs. 2.2.5, 2.2.9-2.2.11 and 2.3.2
// through models::contact_force, the one contact law): the geometry of the contact, the law,
// and the force and torques on both discs. In: dx, dy the i - j centre vector, radii,
// body masses, disc-centre velocities v*, body spins w*; eta, slide the pair's tangential
// history (updated in place, slide as 0/1). Out: the force on i (j gets its negative), the
// torques about each centre, the adhesive part fax, fay of the force on i (written only with
// adhesion), 1 if the discs overlap.
template <bool kAdhesion>
[[gnu::always_inline]] inline void pair_contact(const models::ContactParams& cp, const models::HamakerParams& hp,
                                             double dt, double dx, double dy, double ri, double rj, double mi,
                                             double mj, double vix, double viy, double wi, double vjx, double vjy,
                                             double wj, double& eta, double& slide, double& fx_out, double& fy_out,
                                             double& ti, double& tj, double& fax, double& fay, double& touching_out) {
  const double d2 = dx * dx + dy * dy;
  const double dist = std::sqrt(d2);
  const double inv = 1.0 / dist;
  const double nx = dx * inv, ny = dy * inv;  // from j to i
  const double overlap = (ri + rj) - dist;
  const bool touching = overlap > 0.0;
  // centre to contact point, and the relative velocity of the contact points (read by the
  // contact law only while the discs overlap)
  const double li = ri - 0.5 * overlap, lj = rj - 0.5 * overlap;
  const double vrx = (vix + wi * li * ny) - (vjx - wj * lj * ny);
  const double vry = (viy - wi * li * nx) - (vjy + wj * lj * nx);
  const double vn = touching ? vrx * nx + vry * ny : 0.0;
  const double vt = touching ? -vrx * ny + vry * nx : 0.0;
  const double mred = (touching && cp.mass_proportional) ? mi * mj / (mi + mj) : 0.0;
  models::TangentialState st{eta, slide};
  const models::ContactForce c = models::contact_force<kAdhesion>(cp, hp, ri, rj, overlap, vn, vt, mred, dt, st);
  eta = st.eta;
  slide = st.sliding;
  double fx = touching ? c.fn * nx - c.ft * ny : 0.0;
  double fy = touching ? c.fn * ny + c.ft * nx : 0.0;
  ti = touching ? -li * c.ft : 0.0;
  tj = touching ? -lj * c.ft : 0.0;
  if constexpr (kAdhesion) {
    fx -= c.fa * nx;
    fy -= c.fa * ny;
    fax = c.fa * nx;
    fay = c.fa * ny;
  }
  fx_out = fx;
  fy_out = fy;
  touching_out = touching ? 1.0 : 0.0;
}

// Per-body arrays the integration reads and writes (the engine's BodyStore plus scratch).
struct BodyArrays {
  double *x, *y, *vx, *vy, *theta, *omega, *cth, *sth;  // pose and velocities, advanced
  const double *fx, *fy, *torque, *mass, *inertia;      // forces of the last evaluation
  double *inv_mass, *inv_inertia;                       // out: 1/m, 1/I (for the closing half-kick)
  double *dtheta;                                       // out: this step's rotation angle [rad]
};

struct DriftParams {
  double dt = 0.0;
  bool newmark = false;  // Newmark explicit (eq. 4.2.17) instead of velocity Verlet's first half
  bool periodic = false;
  double x_lo = 0.0, x_hi = 0.0;
};

// Bodies [b0, b1): velocity Verlet's half-kick and drift (or the Newmark explicit update), the
// accumulated angle, (cos, sin) of the angle rotated by the step's angle d where |d| <= 1e-2 rad,
// and the periodic wrap. Bodies with |d| > 1e-2 keep their (cos, sin) and are left to
// rotate_large() (rare: a DEM step turns a body by far less).
void drift_bodies(const DriftParams& p, std::size_t b0, std::size_t b1, const BodyArrays& a);

// The largest squared displacement of discs [k0, k1) from their reference positions (x0, y0),
// minimum image along x if periodic (box length L); NaN if a position is NaN.
double max_displacement2(const double* x, const double* y, const double* x0, const double* y0, std::size_t k0,
                         std::size_t k1, bool periodic, double L);

// The same with each disc's squared displacement weighted by w[k] >= 0 (e.g. 1 / its allowed
// displacement squared: the result exceeds 1 when some disc moved beyond what it may).
double max_weighted_displacement2(const double* x, const double* y, const double* x0, const double* y0,
                                  const double* w, std::size_t k0, std::size_t k1, bool periodic, double L);

// Rotates the unit vector (c, s) by the angle d (any size); the scalar form of the rotation in
// drift_bodies, bitwise the same for |d| <= 1e-2.
void rotate_by(double& c, double& s, double d);

}  // namespace nipdem::engine::detail
