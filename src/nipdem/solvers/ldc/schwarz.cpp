#include "nipdem/solvers/ldc/schwarz.hpp"

#include <algorithm>
#include <cmath>

namespace nipdem::ldc {

namespace {
// Index of the annulus whose Γ is farthest from x among those containing x (excluding `skip`).
int deepest(std::span<const Vec2> centers, std::span<const double> r2, Vec2 x, int skip) {
  int best = -1;
  double depth = 0.0;
  for (int j = 0; j < int(centers.size()); ++j) {
    if (j == skip) continue;
    const double d = r2[j] - norm(x - centers[j]);
    if (d > depth) { depth = d; best = j; }
  }
  return best;
}
}  // namespace

SchwarzSolver::SchwarzSolver(std::span<const Disc> discs, std::span<const double> r2, std::span<const int> samples)
    : discs_(discs.begin(), discs.end()), r2_(r2.begin(), r2.end()) {
  const int n = int(discs.size());
  std::vector<Vec2> centers(n);
  for (int k = 0; k < n; ++k) centers[k] = discs[k].center_m;
  points_.resize(n);
  owner_.resize(n);
  data_.resize(n);
  outer_.resize(n);
  for (int k = 0; k < n; ++k) {
    const int m = samples[k];
    points_[k].resize(m);
    owner_[k].resize(m);
    data_[k].assign(m, 0.0);
    outer_[k].assign(m, 0.0);
    for (int j = 0; j < m; ++j) {
      points_[k][j] = AnnulusSolution::sample_point(centers[k], r2[k], j, m);
      owner_[k][j] = deepest(centers, r2, points_[k][j], k);
    }
  }
}

bool SchwarzSolver::applicable(std::span<const Disc> discs, std::span<const double> r2) {
  for (std::size_t k = 0; k < discs.size(); ++k)
    for (std::size_t j = 0; j < discs.size(); ++j) {
      if (j == k) continue;
      const double d = norm(discs[k].center_m - discs[j].center_m);
      if (d < r2[k] + r2[j] && d <= r2[k] + discs[j].radius_m) return false;
    }
  return true;
}

SchwarzSolver::Result SchwarzSolver::solve(const std::function<double(Vec2)>& outer, double eps, double tol_abs,
                                           int max_sweeps, bool warm, std::vector<AnnulusSolution>& sol) {
  const int n = int(discs_.size());
  sol.resize(n);
  for (int k = 0; k < n; ++k)
    for (std::size_t j = 0; j < points_[k].size(); ++j) outer_[k][j] = outer(points_[k][j]);
  Result res;
  std::vector<double> g_old(n, 0.0);
  bool have_previous = warm;
  for (int k = 0; k < n && warm; ++k) g_old[k] = sol[k].potential();
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    double nu = 0.0;
    for (int k = 0; k < n; ++k) {
      std::vector<double>& d = data_[k];
      for (std::size_t j = 0; j < d.size(); ++j) {
        const int o = owner_[k][j];
        const bool use_other = o >= 0 && (have_previous || o < k);
        const double v = use_other ? sol[o].value(points_[k][j]) : outer_[k][j];
        if (have_previous) nu = std::max(nu, std::abs(v - d[j]));
        d[j] = v;
      }
      sol[k].fit(discs_[k].center_m, discs_[k].radius_m, r2_[k], discs_[k].charge_C_per_m, eps, d);
      if (have_previous) nu = std::max(nu, std::abs(sol[k].potential() - g_old[k]));
      g_old[k] = sol[k].potential();
    }
    res.sweeps = sweep + 1;
    if (have_previous) {
      res.nu.push_back(nu);
      if (nu <= tol_abs) {
        res.converged = true;
        break;
      }
    }
    have_previous = true;
  }
  return res;
}

double SchwarzSolver::value(std::span<const AnnulusSolution> sols, Vec2 x) {
  int best = 0;
  double depth = -1e300;
  for (int j = 0; j < int(sols.size()); ++j) {
    const double d = sols[j].r2() - norm(x - sols[j].center());
    if (d > depth) { depth = d; best = j; }
  }
  return sols[best].value(x);
}

Vec2 SchwarzSolver::field(std::span<const AnnulusSolution> sols, Vec2 x) {
  int best = 0;
  double depth = -1e300;
  for (int j = 0; j < int(sols.size()); ++j) {
    const double d = sols[j].r2() - norm(x - sols[j].center());
    if (d > depth) { depth = d; best = j; }
  }
  return sols[best].field(x);
}

}  // namespace nipdem::ldc
