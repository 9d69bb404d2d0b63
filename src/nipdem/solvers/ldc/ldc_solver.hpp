// Local Defect Correction solver for floating charged discs (thesis ch. 3, eqs. 3.2.2-3.2.8).
//
// One iteration:
//   1. coarse solve  L u^H = χ d  with u^H = f on Dirichlet sides, u^H = g_k at coarse nodes
//      inside disc k (eqs. 3.2.3, 3.2.6-3.2.7; d = 0 on a cold first iteration);
//   2. local solves from u^H on every Γ: analytic / Schwarz / finite-difference (local_domains.hpp)
//      giving new disc potentials g_k and local solutions u_l;
//   3. defect d = L(w) at coarse nodes of the defect region (eq. 3.2.5), where w = u_l in the local
//      domains and u^H outside. A defect node needs its whole five-point stencil inside the local
//      domain and a distance > safety_m from Γ (eq. 3.2.8);
//   4. stop when max|Δg_k| and the change of u^H on every Γ are below tolerance × potential scale.
//
// The solver sees particles only through Disc (position, radius, charge per unit length). It is
// not coupled to the DEM: the nip's electric force uses the sphere-plate model (docs/electric.md);
// coupling LDC into the time loop would be its own piece of work (docs/ldc.md). Consecutive solve() calls with the same number of
// discs warm-start from the previous potentials, coarse solution and defect.
#pragma once
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "nipdem/core/vec2.hpp"
#include "nipdem/solvers/ldc/coarse_grid.hpp"
#include "nipdem/solvers/ldc/problem.hpp"

namespace nipdem::ldc {

struct SolveStats {
  int iterations = 0;
  bool converged = false;
  int coarse_factorisations = 0;     // during this solve
  std::vector<double> kappa;         // κ_i = max |u^H - u_l| at coarse nodes of the local domains
  std::vector<double> delta;         // δ_i = max change of u^H on Γ between coarse solves i and i+1
  std::vector<double> potential_change;  // max_k |g_k,i - g_k,i-1|
  int schwarz_sweeps = 0;            // total over the solve
  int fd_groups = 0;                 // finite-difference local problems in this solve
  int fd_kept = 0;                   // ... that kept their matrix factorisation from the previous solve
  int fd_factorisations = 0;         // LU factorisations of finite-difference matrices during this solve
  int extrapolations = 0;            // Aitken steps (Params::aitken)
};

class LdcSolver {
 public:
  explicit LdcSolver(const Params& p);  // validates p (InputError)
  ~LdcSolver();
  LdcSolver(LdcSolver&&) noexcept;
  LdcSolver& operator=(LdcSolver&&) noexcept;

  // Solves for the given discs (validated: InputError on bad input). Warm start if the number of
  // discs equals that of the previous call.
  const SolveStats& solve(std::span<const Disc> discs);
  void reset_warm_start();
  // Called after every LDC iteration of solve() with the statistics so far (iterations,
  // potential_change, delta), e.g. for a progress line; empty (the default) calls nothing.
  void set_progress(std::function<void(const SolveStats&)> progress);

  int disc_count() const;
  double potential(int k) const;         // g_k [V]
  Vec2 force(int k) const;               // electric force per unit length on disc k [N/m]
  LocalMethod method(int k) const;
  double potential_at(Vec2 x) const;     // u [V]
  Vec2 field(Vec2 x) const;              // E = -grad u [V/m]
  const SolveStats& stats() const;
  const CoarseGrid& grid() const;
  std::span<const double> coarse_solution() const;
  const Params& params() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nipdem::ldc
