#include "nipdem/engine/pair_batch.hpp"

#include <cmath>

namespace nipdem::engine::detail {

namespace {

// One lane = the scalar pair kernel's arithmetic for one interacting pair (thesis eqs. 2.2.5,
// 2.2.9-2.2.11 and 2.3.2 through models::contact_force), written without branches the
// vectoriser cannot turn into selects.
template <bool kAdhesion>
[[gnu::always_inline]] inline void lanes(const models::ContactParams& cp, const models::HamakerParams& hp, double dt,
                                         int n, PairBatch& b) {
  const bool mass_prop = cp.mass_proportional;
#pragma omp simd
  for (int k = 0; k < n; ++k) {
    const double dx = b.dx[k], dy = b.dy[k], ri = b.ri[k], rj = b.rj[k];
    const double d2 = dx * dx + dy * dy;
    const double dist = std::sqrt(d2);
    const double inv = 1.0 / dist;
    const double nx = dx * inv, ny = dy * inv;  // from j to i
    const double overlap = (ri + rj) - dist;
    const bool touching = overlap > 0.0;
    // centre to contact point, and the relative velocity of the contact points (read by the
    // contact law only while the discs overlap)
    const double li = ri - 0.5 * overlap, lj = rj - 0.5 * overlap;
    const double vrx = (b.vix[k] + b.wi[k] * li * ny) - (b.vjx[k] - b.wj[k] * lj * ny);
    const double vry = (b.viy[k] - b.wi[k] * li * nx) - (b.vjy[k] + b.wj[k] * lj * nx);
    const double vn = touching ? vrx * nx + vry * ny : 0.0;
    const double vt = touching ? -vrx * ny + vry * nx : 0.0;
    const double mred = (touching && mass_prop) ? b.mi[k] * b.mj[k] / (b.mi[k] + b.mj[k]) : 0.0;
    models::TangentialState st{b.eta[k], b.slide[k]};
    const models::ContactForce c = models::contact_force<kAdhesion>(cp, hp, ri, rj, overlap, vn, vt, mred, dt, st);
    b.eta[k] = st.eta;
    b.slide[k] = st.sliding;
    double fx = touching ? c.fn * nx - c.ft * ny : 0.0;
    double fy = touching ? c.fn * ny + c.ft * nx : 0.0;
    b.ti[k] = touching ? -li * c.ft : 0.0;
    b.tj[k] = touching ? -lj * c.ft : 0.0;
    if constexpr (kAdhesion) {
      fx -= c.fa * nx;
      fy -= c.fa * ny;
      b.fax[k] = c.fa * nx;
      b.fay[k] = c.fa * ny;
    }
    b.fx[k] = fx;
    b.fy[k] = fy;
    b.touching[k] = touching ? 1.0 : 0.0;
  }
}

}  // namespace

__attribute__((target_clones("avx512f", "avx2", "default")))
void compute_pair_batch(const models::ContactParams& cp, const models::HamakerParams& hp, double dt, bool adhesion,
                        int n, PairBatch& b) {
  if (adhesion) lanes<true>(cp, hp, dt, n, b);
  else lanes<false>(cp, hp, dt, n, b);
}

}  // namespace nipdem::engine::detail
