// Speed features of the LDC solver must not change its answers: reuse of finite-difference
// factorisations between solves (FdLocalProblem::update_conductors and the cache in LdcSolver),
// and the Aitken extrapolation of the LDC iteration.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "nipdem/solvers/ldc/ldc_solver.hpp"
#include "nipdem/solvers/ldc/local_fd.hpp"

using namespace nipdem;
using namespace nipdem::ldc;

namespace {
// Fig. 3.6-like cluster: unit square, h = 1/80, two discs R = 0.05 (gap 0.1), non-zero
// boundary data so that every part of the right-hand side is exercised.
std::vector<FdConductor> two_discs(Vec2 shift) {
  std::vector<FdConductor> c(2);
  // Centres off the grid lines by (0.5 h, 0.5 h): no fine node lies within 0.19 h of a circle.
  c[0].center = Vec2{0.4 + 0.5 / 80, 0.5 + 0.5 / 80} + shift;
  c[1].center = {0.6 + 0.5 / 80, 0.5 + 0.5 / 80};
  c[0].radius = c[1].radius = 0.05;
  c[0].charge = 1.0;
  c[1].charge = -0.5;
  return c;
}
double boundary(Vec2 x) { return 0.3 * x.x + 0.7 * x.y * x.y; }
FdLocalProblem make(Vec2 shift) {
  return FdLocalProblem({0.0, 0.0}, 1.0 / 80, 1.0 / 80, 80, 80, {false, false, false, false}, two_discs(shift), 1.0);
}
// Max relative difference of the node values and potentials of two solved problems.
double max_rel_diff(const FdLocalProblem& a, const FdLocalProblem& b) {
  double scale = 0.0, diff = 0.0;
  for (int j = 0; j < a.ny(); ++j)
    for (int i = 0; i < a.nx(); ++i) {
      scale = std::max(scale, std::abs(b.node_value(i, j)));
      diff = std::max(diff, std::abs(a.node_value(i, j) - b.node_value(i, j)));
    }
  for (int k = 0; k < 2; ++k) diff = std::max(diff, std::abs(a.potential(k) - b.potential(k)));
  return diff / scale;
}
}  // namespace

TEST(LdcFdCache, KeptFactorisationGivesFreshSolution) {
  // Disc 0 moves by 0.02 h (a DEM step): no fine node changes its kind, so the factorisation of
  // the old matrix is kept and the refinement iterates with the new matrix. Both answers solve
  // the same linear system to round-off; tolerance 1e-12 relative (backward errors ~1e-16 times
  // the conditioning of the Shortley-Weller matrix; measured difference ~1e-14).
  FdLocalProblem cached = make({0.0, 0.0});
  cached.solve(boundary);
  const Vec2 step{0.02 / 80, -0.01 / 80};
  EXPECT_TRUE(cached.update_conductors(two_discs(step)));
  cached.solve(boundary);
  FdLocalProblem fresh = make(step);
  fresh.solve(boundary);
  EXPECT_LT(max_rel_diff(cached, fresh), 1e-12);
  EXPECT_EQ(cached.counters().factorisations, 1);  // kept: no re-factorisation
  EXPECT_EQ(cached.counters().stale_solves, 1);
  // The answer did change with the geometry (the test is not comparing two identical solves).
  FdLocalProblem before = make({0.0, 0.0});
  before.solve(boundary);
  EXPECT_GT(max_rel_diff(cached, before), 1e-6);
}

TEST(LdcFdCache, NodeChangingKindForcesRefactorisation) {
  // A move of 0.6 h brings fine nodes into / out of disc 0: the unknowns are renumbered and the
  // matrix must be factorised again; the answer is again the fresh one (tolerance as above).
  FdLocalProblem cached = make({0.0, 0.0});
  cached.solve(boundary);
  const Vec2 step{0.6 / 80, 0.3 / 80};
  EXPECT_FALSE(cached.update_conductors(two_discs(step)));
  cached.solve(boundary);
  FdLocalProblem fresh = make(step);
  fresh.solve(boundary);
  EXPECT_LT(max_rel_diff(cached, fresh), 1e-12);
  EXPECT_EQ(cached.counters().factorisations, 2);
}

TEST(LdcFdCache, UnchangedGeometryIsExact) {
  // Same conductors, new charges: the matrix is identical, so the factorisation is not stale.
  FdLocalProblem cached = make({0.0, 0.0});
  cached.solve(boundary);
  auto c = two_discs({0.0, 0.0});
  c[1].charge = 2.0;
  EXPECT_TRUE(cached.update_conductors(c));
  cached.solve(boundary);
  EXPECT_EQ(cached.counters().stale_solves, 0);
  EXPECT_EQ(cached.counters().factorisations, 1);
  FdLocalProblem fresh({0.0, 0.0}, 1.0 / 80, 1.0 / 80, 80, 80, {false, false, false, false}, c, 1.0);
  fresh.solve(boundary);
  EXPECT_LT(max_rel_diff(cached, fresh), 1e-12);
}

TEST(LdcFdCache, SolverReusesClusterFactorisationsOnWarmResolve) {
  // Three discs close enough for one finite-difference cluster. (1) Re-solve with new charges at
  // the same positions: the cluster keeps its factorisation (no LU during the re-solve). (2)
  // Re-solve after steps of 0.01 R: whether the factorisation is kept or redone (a fine node
  // crossing a circle forces a new one), the answer must equal a cold solve. Tolerance 1e-8
  // relative on g and 1e-6 on the force: both iterations stop at a relative change of 1e-11.
  Params p;
  p.x_max_m = p.y_max_m = 1e-3;
  p.cells_x = p.cells_y = 100;
  p.top = {SideKind::dirichlet, 500.0};
  p.left.kind = p.right.kind = SideKind::neumann;
  p.tolerance = 1e-11;
  const double R = 5e-6;
  const Vec2 c{5.0313e-4, 4.9729e-4};
  std::vector<Disc> d = {{c, R, 1e-10}, {c + Vec2{2.6 * R, 0.0}, R, -1e-10}, {c + Vec2{0.0, 2.6 * R}, R, 2e-10}};
  LdcSolver warm(p);
  warm.solve(d);
  ASSERT_EQ(warm.method(0), LocalMethod::finite_difference);
  EXPECT_EQ(warm.stats().fd_groups, 1);
  EXPECT_EQ(warm.stats().fd_factorisations, 1);
  auto same_as_cold = [&](const char* what) {
    LdcSolver cold(p);
    cold.solve(d);
    EXPECT_TRUE(warm.stats().converged) << what;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(warm.potential(k), cold.potential(k), 1e-8 * std::abs(cold.potential(k))) << what;
      EXPECT_NEAR(warm.force(k).x, cold.force(k).x, 1e-6 * norm(cold.force(k))) << what;
      EXPECT_NEAR(warm.force(k).y, cold.force(k).y, 1e-6 * norm(cold.force(k))) << what;
    }
  };
  d[1].charge_C_per_m = -3e-10;
  warm.solve(d);
  EXPECT_EQ(warm.stats().fd_kept, 1);
  EXPECT_EQ(warm.stats().fd_factorisations, 0);
  same_as_cold("new charges");
  for (Disc& x : d) x.center_m += Vec2{0.01 * R, -0.007 * R};
  warm.solve(d);
  EXPECT_LE(warm.stats().fd_factorisations, 1);
  same_as_cold("moved");
}

TEST(LdcAitken, SameAnswerInFewerIterations) {
  // Problem 3.8.1 with the disc (thesis formulation, H = 1/40): the plain LDC iteration converges
  // with the steady factor 0.39 (Table 3.2), the case the Aitken step is made for. Both runs stop
  // at a relative change of 1e-12; the potentials must agree to 1e-9 relative (the stopping
  // test bounds the remaining error by ~ tol ρ/(1-ρ)), with fewer iterations when extrapolating.
  Params p;
  p.cells_x = p.cells_y = 40;
  p.bottom = {SideKind::dirichlet, 0.0};
  p.top = {SideKind::dirichlet, 1.0};
  p.left.kind = p.right.kind = SideKind::neumann;
  p.permittivity_F_per_m = 1.0;
  p.initial_potential_V = 0.1;
  p.dirichlet_conductor_nodes = true;
  p.local_radius_factor = 5.0;
  p.local_min_cells = 1.0;
  p.tolerance = 1e-12;
  const Disc d{{0.5, 0.5}, 0.05, 1.13};
  p.aitken = false;
  LdcSolver plain(p);
  plain.solve(std::span<const Disc>(&d, 1));
  p.aitken = true;
  LdcSolver fast(p);
  fast.solve(std::span<const Disc>(&d, 1));
  ASSERT_TRUE(plain.stats().converged);
  ASSERT_TRUE(fast.stats().converged);
  EXPECT_EQ(plain.stats().extrapolations, 0);
  EXPECT_GE(fast.stats().extrapolations, 1);
  EXPECT_LT(fast.stats().iterations, plain.stats().iterations);
  EXPECT_NEAR(fast.potential(0), plain.potential(0), 1e-9 * std::abs(plain.potential(0)));
}
