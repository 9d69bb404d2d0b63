// Automatic choice of the local solution method per configuration (thesis §3.4, §3.9, §3.10):
//   * analytic  — the local annulus of a disc overlaps no other local domain (eqs. 3.4.6-3.4.7);
//   * schwarz   — annuli overlap, but no Γ_k enters another disc (condition 3.9.16);
//   * finite_difference — otherwise (a local domain overlaps another disc, or the annulus would
//     not fit in the box): one fine-grid rectangle for the whole cluster (§3.10).
// Groups are connected components of "local domains overlap"; a finite-difference rectangle that
// reaches another disc absorbs that disc's group.
#pragma once
#include <span>
#include <vector>

#include "nipdem/solvers/ldc/coarse_grid.hpp"
#include "nipdem/solvers/ldc/problem.hpp"

namespace nipdem::ldc {

struct LocalGroup {
  LocalMethod method = LocalMethod::analytic;
  std::vector<int> members;  // disc indices
  std::vector<double> r2;    // local radius R2 per member (analytic / schwarz)
  int i0 = 0, i1 = 0, j0 = 0, j1 = 0;  // coarse node range of the rectangle (finite_difference)
  int refinement = 1;                  // h = H / refinement (finite_difference)
};

// Local radius R2 of a disc: max(factor R1, R1 + min_cells H), reduced to fit inside the box.
double local_radius(const Params& p, const Disc& d);

std::vector<LocalGroup> build_local_groups(const CoarseGrid& grid, std::span<const Disc> discs, const Params& p);

}  // namespace nipdem::ldc
