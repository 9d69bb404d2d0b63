// Schwarz alternating process for overlapping local annuli (thesis §3.9, eqs. 3.9.2-3.9.5).
// Each disc k has an annulus R1_k < r < R2_k. On the part of Γ_k that lies inside another local
// domain j, the boundary data are the current analytic solution of j (Γ*_k); elsewhere they come
// from `outer` (the coarse solution in LDC). The annuli are solved in turn until the largest
// change ν (max over all discs of the change of g and of the boundary data, which by the maximum
// principle bounds the change in the whole annulus) falls below the tolerance.
//
// Valid when no Γ_k enters another disc (eq. 3.9.16); LdcSolver checks that before choosing it.
#pragma once
#include <functional>
#include <span>
#include <vector>

#include "nipdem/solvers/ldc/annulus.hpp"
#include "nipdem/solvers/ldc/problem.hpp"

namespace nipdem::ldc {

class SchwarzSolver {
 public:
  // discs and local radii R2 of one overlapping cluster; samples[k] = 2N+1 points on Γ_k.
  SchwarzSolver(std::span<const Disc> discs, std::span<const double> r2, std::span<const int> samples);
  // True if condition 3.9.16 holds: every Γ_k stays outside every other disc.
  static bool applicable(std::span<const Disc> discs, std::span<const double> r2);

  struct Result {
    int sweeps = 0;
    bool converged = false;
    std::vector<double> nu;  // ν_i for i = 1, 2, ... (change between sweep i and sweep i-1)
  };
  // `solutions` holds the initial guess if `warm` (from the previous LDC iteration), else the
  // first sweep takes `outer` on all of Γ_k. The result is written back into `solutions`.
  Result solve(const std::function<double(Vec2)>& outer, double eps, double tol_abs, int max_sweeps, bool warm,
               std::vector<AnnulusSolution>& solutions);
  // Local solution at x (deepest annulus containing x); x must lie in the union of the domains.
  static double value(std::span<const AnnulusSolution> sols, Vec2 x);
  static Vec2 field(std::span<const AnnulusSolution> sols, Vec2 x);

 private:
  std::vector<Disc> discs_;
  std::vector<double> r2_;
  std::vector<std::vector<Vec2>> points_;  // Γ_k sample points
  std::vector<std::vector<int>> owner_;    // other local domain containing the point, or -1
  std::vector<std::vector<double>> data_, outer_;
};

}  // namespace nipdem::ldc
