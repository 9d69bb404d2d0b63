// LDC electrostatic solver benchmark (one figure: time per warm-started solve vs. discs and grid).
//
//   build/bench/bench_ldc [--quick]
//   build/bench/bench_ldc --case DISCS CELLS RESOLVES [BOX_SIDE_M]   (one row)
//
// Setup: square box L = 1 mm, u = 0 at the bottom, 500 V at the top, Neumann sides; discs of
// radius 5 µm and charge 1e-10 C/m at random non-overlapping positions (centre distance
// >= 2.5 R). One cold LDC solve to 1e-8 relative change, then 100 re-solves, each after moving
// every disc by a Gaussian step of 0.01 R (a DEM time step), warm-started from the previous one.
// Also: the coarse-solver choice (sparse LDL^T vs conjugate gradients) on the same grids.
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "nipdem/core/wait_policy.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/solvers/ldc/ldc_solver.hpp"
#include "nipdem/version.hpp"

using namespace nipdem;
using namespace nipdem::ldc;

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
// Process CPU time [s]: the solver is single-threaded, and on the shared machine the wall time of
// the same run varies by 2-3x with the load of other jobs; CPU time varies much less.
double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

constexpr double kR = 5e-6, kQ = 1e-10;
double kL = 1e-3;  // box side [m]; the constant-density scan enlarges it

Params box_params(int cells) {
  Params p;
  p.x_max_m = p.y_max_m = kL;
  p.cells_x = p.cells_y = cells;
  p.top = {SideKind::dirichlet, 500.0};
  p.left.kind = p.right.kind = SideKind::neumann;
  p.tolerance = 1e-8;
  p.max_iterations = 60;  // known issue (docs/ldc.md): large finite-difference clusters may stall
  return p;
}

std::vector<Disc> random_discs(int n, Rng& rng) {
  std::vector<Disc> d;
  while (int(d.size()) < n) {
    const Vec2 c{rng.uniform(3 * kR, kL - 3 * kR), rng.uniform(3 * kR, kL - 3 * kR)};
    bool ok = true;
    for (const Disc& o : d) ok = ok && norm(o.center_m - c) >= 2.5 * kR;
    if (ok) d.push_back({c, kR, kQ});
  }
  return d;
}

struct Result {
  double cold_s, warm_s, warm_iterations, cold_iterations;
  double warm_cpu_s;  // CPU time per warm re-solve
  int analytic, schwarz, fd;
  int factorisations;
  int unconverged;  // solves that hit max_iterations
  double fd_groups = 0, fd_kept = 0, fd_factorisations = 0;  // per warm re-solve (mean)
};

Result run(int n, int cells, int resolves, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Disc> discs = random_discs(n, rng);
  LdcSolver solver(box_params(cells));
  auto t0 = Clock::now();
  solver.solve(discs);
  Result r{};
  r.cold_s = seconds_since(t0);
  r.cold_iterations = solver.stats().iterations;
  r.unconverged += !solver.stats().converged;
  for (int k = 0; k < n; ++k) {
    const LocalMethod m = solver.method(k);
    r.analytic += m == LocalMethod::analytic;
    r.schwarz += m == LocalMethod::schwarz;
    r.fd += m == LocalMethod::finite_difference;
  }
  double iters = 0;
  t0 = Clock::now();
  const double c0 = cpu_seconds();
  for (int s = 0; s < resolves; ++s) {
    for (Disc& d : discs) {
      const Vec2 step{0.01 * kR * rng.normal(), 0.01 * kR * rng.normal()};
      Vec2 c = d.center_m + step;
      bool ok = c.x > 2 * kR && c.x < kL - 2 * kR && c.y > 2 * kR && c.y < kL - 2 * kR;
      for (const Disc& o : discs) ok = ok && (&o == &d || norm(o.center_m - c) > 2.05 * kR);
      if (ok) d.center_m = c;
    }
    solver.solve(discs);
    iters += solver.stats().iterations;
    r.unconverged += !solver.stats().converged;
    r.factorisations += solver.stats().coarse_factorisations;
    r.fd_groups += double(solver.stats().fd_groups) / resolves;
    r.fd_kept += double(solver.stats().fd_kept) / resolves;
    r.fd_factorisations += double(solver.stats().fd_factorisations) / resolves;
  }
  r.warm_s = seconds_since(t0) / resolves;
  r.warm_cpu_s = (cpu_seconds() - c0) / resolves;
  r.warm_iterations = iters / resolves;
  return r;
}

// Coarse solver choice: factorise once + back-substitute vs. conjugate gradients per solve.
void coarse_solver_comparison(int cells) {
  const int n = cells - 1, m = n * n;  // Dirichlet box, interior unknowns
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int k = j * n + i;
      t.emplace_back(k, k, 4.0);
      if (i > 0) t.emplace_back(k, k - 1, -1.0);
      if (i + 1 < n) t.emplace_back(k, k + 1, -1.0);
      if (j > 0) t.emplace_back(k, k - n, -1.0);
      if (j + 1 < n) t.emplace_back(k, k + n, -1.0);
    }
  Eigen::SparseMatrix<double> a(m, m);
  a.setFromTriplets(t.begin(), t.end());
  Eigen::VectorXd b = Eigen::VectorXd::Random(m), x(m);
  auto t0 = Clock::now();
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(a);
  const double factor = seconds_since(t0);
  t0 = Clock::now();
  for (int r = 0; r < 10; ++r) x = ldlt.solve(b);
  const double solve = seconds_since(t0) / 10;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> cg;
  cg.setTolerance(1e-10);
  t0 = Clock::now();
  cg.compute(a);
  const double cg_setup = seconds_since(t0);
  t0 = Clock::now();
  for (int r = 0; r < 3; ++r) x = cg.solve(b);
  const double cg_solve = seconds_since(t0) / 3;
  std::printf("  %4dx%-4d  LDLT factor %8.2f ms  solve %7.3f ms | CG+IC(1e-10) setup %7.2f ms  solve %8.2f ms (%d its)\n",
              cells, cells, 1e3 * factor, 1e3 * solve, 1e3 * cg_setup, 1e3 * cg_solve, int(cg.iterations()));
}
void print_row(const char* label, const Result& r) {
  std::printf("  %9s %10.2f %6.0f %12.3f %10.3f %8.2f   %d/%d/%d  %d   %.1f/%.1f/%.1f\n", label, 1e3 * r.cold_s,
              r.cold_iterations, 1e3 * r.warm_s, 1e3 * r.warm_cpu_s, r.warm_iterations, r.analytic, r.schwarz, r.fd, r.unconverged, r.fd_groups, r.fd_kept,
              r.fd_factorisations);
}
const char* kHeader = "  %9s %10s %6s %12s %10s %8s   %s\n";
const char* kColumns = "analytic/schwarz/fd  unconverged  fd clusters/kept/LU per re-solve";
}  // namespace

int main(int argc, char** argv) {
  nipdem::apply_wait_policy(argv);  // may re-execute once (core/wait_policy.hpp)
  if (argc == 6 && std::strcmp(argv[1], "--case") == 0) kL = std::atof(argv[5]);  // --case ... BOX_M
  if (argc >= 5 && std::strcmp(argv[1], "--case") == 0) {  // --case DISCS CELLS RESOLVES [BOX_M]
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
    const Result r = run(std::atoi(argv[2]), std::atoi(argv[3]), std::atoi(argv[4]), 42);
    std::printf(kHeader, "discs", "cold [ms]", "its", "warm [ms]", "cpu [ms]", "its", kColumns);
    print_row(argv[2], r);
    return 0;
  }
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const int resolves = quick ? 10 : 100;
  std::printf("bench_ldc  nipdem %s  git %s\n", kVersion, kGitHash);
  std::printf("box %.0e m, R = %.0e m, q = %.0e C/m, 500 V across, tolerance 1e-8, %d warm re-solves "
              "(steps 0.01 R)\n",
              kL, kR, kQ, resolves);
  {
    const Result r = run(100, 100, resolves, 42);
    std::printf("\nMain figure: 100 discs, grid 100x100 (H = 2R): cold solve %.2f ms (%.0f iterations), "
                "warm re-solve %.3f ms (CPU %.3f ms, %.2f iterations, mean of %d), methods analytic/schwarz/fd %d/%d/%d, "
                "unconverged %d\n",
                1e3 * r.cold_s, r.cold_iterations, 1e3 * r.warm_s, 1e3 * r.warm_cpu_s, r.warm_iterations, resolves, r.analytic, r.schwarz,
                r.fd, r.unconverged);
  }
  std::printf("\nTime per solve vs number of discs (coarse grid 100x100, H = 2R; 20 warm re-solves, 5 for 200 and 400):\n");
  std::printf(kHeader, "discs", "cold [ms]", "its", "warm [ms]", "cpu [ms]", "its", kColumns);
  for (int n : {25, 50, 100, 200, 400}) {
    const Result r = run(n, 100, quick ? 3 : (n > 100 ? 5 : 20), 42);
    print_row(std::to_string(n).c_str(), r);
  }
  // Same density (100 discs per mm², H = 2R) in a growing box: the algorithmic scaling, without
  // the denser packing (more Schwarz groups and finite-difference clusters) of the scan above.
  std::printf("\nTime per solve vs number of discs at constant density (100 per mm^2, box side sqrt(N/100) mm, "
              "H = 2R; 10 warm re-solves):\n");
  std::printf(kHeader, "discs", "cold [ms]", "its", "warm [ms]", "cpu [ms]", "its", kColumns);
  for (int n : {25, 100, 400, 1600}) {
    const int cells = int(std::lround(100.0 * std::sqrt(n / 100.0)));
    kL = 1e-3 * cells / 100.0;
    const Result r = run(n, cells, quick ? 3 : 10, 42);
    print_row(std::to_string(n).c_str(), r);
  }
  kL = 1e-3;
  std::printf("\nTime per solve vs coarse grid (100 discs, 10 warm re-solves):\n");
  std::printf(kHeader, "grid", "cold [ms]", "its", "warm [ms]", "cpu [ms]", "its", kColumns);
  for (int cells : {50, 100, 200, 400}) {
    const Result r = run(100, cells, quick ? 3 : 10, 42);
    print_row((std::to_string(cells) + "x" + std::to_string(cells)).c_str(), r);
  }
  std::printf("\nCoarse solver choice (5-point Laplacian, Dirichlet box):\n");
  for (int cells : {100, 200, 400}) coarse_solver_comparison(cells);
  return 0;
}
