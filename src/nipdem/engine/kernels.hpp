// The engine's arithmetic that runs on many items at once, in flat arrays, so that the compiler
// evaluates several per instruction (docs/performance.md, "Batched pair kernel"): the contact
// law on a batch of disc pairs, and the integration of the bodies.
//
// Pairs: the engine's pair_rows() finds the interacting pairs of its rows
// (cheap distance tests), copies their data into a PairBatch, calls compute_pair_batch(), and
// adds the results to the discs in list order.
//
// Why it is bitwise the scalar kernel: each lane does exactly the scalar operations, in the
// same order, of models::contact_force (the one contact law); vector sqrt, divide, add and
// multiply are correctly rounded like their scalar forms; there is no fused multiply-add (none
// of the clones enables FMA); and the sums into the discs stay scalar and in list order.
// The functions here are compiled for AVX-512, AVX2 and generic x86-64 and picked at load
// time (GCC target_clones), with identical results on every machine (no FMA contraction:
// src/CMakeLists.txt). GCC 12 vectorises drift_bodies in its clones but leaves the pair loop
// scalar in every clone ("no vectype"); written out per target it vectorises and gains nothing
// measurable, since the law is a small part of the pair kernel (docs/performance.md, fifth pass).
#pragma once
#include <cstdint>

#include "nipdem/models/contact.hpp"
#include "nipdem/models/hamaker.hpp"

namespace nipdem::engine::detail {

struct PairBatch {
  static constexpr int kN = 64;
  // inputs: i - j centre vector (minimum image), radii, body masses, disc-centre velocities and
  // body spins of both discs, and the pair's tangential history (slide as 0/1)
  alignas(64) double dx[kN], dy[kN], ri[kN], rj[kN], mi[kN], mj[kN];
  alignas(64) double vix[kN], viy[kN], wi[kN], vjx[kN], vjy[kN], wj[kN];
  alignas(64) double eta[kN], slide[kN];
  // outputs: force on i (j gets its negative), torques about each centre, the adhesive part
  // (its vector fax, fay on i), the history to store, and 1 where the discs overlap
  alignas(64) double fx[kN], fy[kN], ti[kN], tj[kN], fax[kN], fay[kN], touching[kN];
  // which pair: list entry and the two discs
  int e[kN], i[kN], j[kN];
};

// Evaluates pairs [0, n) of b; `adhesion` adds the Hamaker term (hp is not read without it).
void compute_pair_batch(const models::ContactParams& cp, const models::HamakerParams& hp, double dt, bool adhesion,
                        int n, PairBatch& b);

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

// Rotates the unit vector (c, s) by the angle d (any size); the scalar form of the rotation in
// drift_bodies, bitwise the same for |d| <= 1e-2.
void rotate_by(double& c, double& s, double d);

}  // namespace nipdem::engine::detail
