// The arithmetic of the disc-disc pair kernel on a batch of interacting pairs, in flat arrays,
// so that the compiler evaluates several contacts per instruction (docs/performance.md,
// "Batched pair kernel"). The engine's pair_rows() finds the interacting pairs of its rows
// (cheap distance tests), copies their data into a PairBatch, calls compute_pair_batch(), and
// adds the results to the discs in list order.
//
// Why it is bitwise the scalar kernel: each lane does exactly the scalar operations, in the
// same order, of models::contact_force (the one contact law); vector sqrt, divide, add and
// multiply are correctly rounded like their scalar forms; there is no fused multiply-add (none
// of the clones enables FMA); and the sums into the discs stay scalar and in list order.
// compute_pair_batch is compiled for AVX-512, AVX2 and generic x86-64 and picked at load
// time (GCC target_clones), so a generic Debian build uses the wide units where they exist,
// with identical results on every machine.
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

}  // namespace nipdem::engine::detail
