#include "nipdem/solvers/ldc/coarse_grid.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace nipdem::ldc {

CoarseGrid::CoarseGrid(const Params& p)
    : p_(p), nx_(p.cells_x + 1), ny_(p.cells_y + 1), x0_(p.x_min_m), y0_(p.y_min_m), hx_(p.hx()), hy_(p.hy()) {
  box_dirichlet_.assign(size(), 0);
  box_value_.assign(size(), 0.0);
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      double sum = 0.0;
      int count = 0;
      auto add = [&](const SideCondition& s, bool on) {
        if (on && s.kind == SideKind::dirichlet) { sum += s.value_V; ++count; }
      };
      add(p.left, i == 0);
      add(p.right, i == nx_ - 1);
      add(p.bottom, j == 0);
      add(p.top, j == ny_ - 1);
      if (count > 0) {  // a corner between two Dirichlet sides takes their mean
        box_dirichlet_[index(i, j)] = 1;
        box_value_[index(i, j)] = sum / count;
      }
    }
  }
}

double CoarseGrid::laplacian(std::span<const double> w, int i, int j) const {
  const double c = w[index(i, j)];
  const double e = i + 1 < nx_ ? w[index(i + 1, j)] : w[index(i - 1, j)];
  const double ww = i > 0 ? w[index(i - 1, j)] : w[index(i + 1, j)];
  const double n = j + 1 < ny_ ? w[index(i, j + 1)] : w[index(i, j - 1)];
  const double s = j > 0 ? w[index(i, j - 1)] : w[index(i, j + 1)];
  return (e + ww - 2.0 * c) / (hx_ * hx_) + (n + s - 2.0 * c) / (hy_ * hy_);
}

double CoarseGrid::interpolate(std::span<const double> u, Vec2 x) const {
  const double fx = std::clamp((x.x - x0_) / hx_, 0.0, double(nx_ - 1));
  const double fy = std::clamp((x.y - y0_) / hy_, 0.0, double(ny_ - 1));
  const int i = std::min(int(fx), nx_ - 2), j = std::min(int(fy), ny_ - 2);
  const double tx = fx - i, ty = fy - j;
  return (1 - tx) * (1 - ty) * u[index(i, j)] + tx * (1 - ty) * u[index(i + 1, j)] +
         (1 - tx) * ty * u[index(i, j + 1)] + tx * ty * u[index(i + 1, j + 1)];
}

Vec2 CoarseGrid::field(std::span<const double> u, Vec2 x) const {
  auto grad_at = [&](int i, int j) {
    const int ie = std::min(i + 1, nx_ - 1), iw = std::max(i - 1, 0);
    const int jn = std::min(j + 1, ny_ - 1), js = std::max(j - 1, 0);
    return Vec2{(u[index(ie, j)] - u[index(iw, j)]) / ((ie - iw) * hx_),
                (u[index(i, jn)] - u[index(i, js)]) / ((jn - js) * hy_)};
  };
  const double fx = std::clamp((x.x - x0_) / hx_, 0.0, double(nx_ - 1));
  const double fy = std::clamp((x.y - y0_) / hy_, 0.0, double(ny_ - 1));
  const int i = std::min(int(fx), nx_ - 2), j = std::min(int(fy), ny_ - 2);
  const double tx = fx - i, ty = fy - j;
  const Vec2 g = (1 - tx) * (1 - ty) * grad_at(i, j) + tx * (1 - ty) * grad_at(i + 1, j) +
                 (1 - tx) * ty * grad_at(i, j + 1) + tx * ty * grad_at(i + 1, j + 1);
  return -g;
}

// ---------------------------------------------------------------------------------------------

struct CoarseSolver::Impl {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  Eigen::VectorXd rhs, x;
};

CoarseSolver::CoarseSolver(const CoarseGrid& grid) : grid_(&grid), impl_(std::make_unique<Impl>()) {
  extra_.assign(grid.size(), 0);
  factorise();
}
CoarseSolver::~CoarseSolver() = default;
CoarseSolver::CoarseSolver(CoarseSolver&&) noexcept = default;
CoarseSolver& CoarseSolver::operator=(CoarseSolver&&) noexcept = default;

bool CoarseSolver::set_extra_dirichlet(std::span<const std::uint8_t> mask) {
  if (std::equal(mask.begin(), mask.end(), extra_.begin(), extra_.end())) return false;
  extra_.assign(mask.begin(), mask.end());
  factorise();
  return true;
}

// The matrix is -L with every row on a Neumann side scaled by 1/2 (1/4 in a Neumann corner):
// that makes the mirrored stencil symmetric, so a Cholesky (LDL^T) factorisation applies.
void CoarseSolver::factorise() {
  const auto t0 = std::chrono::steady_clock::now();
  const CoarseGrid& g = *grid_;
  const int nx = g.nx(), ny = g.ny();
  free_index_.assign(g.size(), -1);
  free_nodes_.clear();
  for (int n = 0; n < g.size(); ++n)
    if (!g.box_dirichlet(n) && !extra_[n]) {
      free_index_[n] = int(free_nodes_.size());
      free_nodes_.push_back(n);
    }
  const int m = int(free_nodes_.size());
  row_scale_.assign(m, 1.0);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(5 * std::size_t(m));
  const double cx = 1.0 / (g.hx() * g.hx()), cy = 1.0 / (g.hy() * g.hy());
  for (int k = 0; k < m; ++k) {
    const int n = free_nodes_[k], i = n % nx, j = n / nx;
    double scale = 1.0;
    if (i == 0 || i == nx - 1) scale *= 0.5;
    if (j == 0 || j == ny - 1) scale *= 0.5;
    row_scale_[k] = scale;
    trip.emplace_back(k, k, scale * 2.0 * (cx + cy));
    auto nb = [&](int ii, int jj, double c) {
      const int f = free_index_[g.index(ii, jj)];
      if (f >= 0) trip.emplace_back(k, f, -scale * c);
    };
    if (i + 1 < nx) nb(i + 1, j, i == 0 ? 2 * cx : cx);
    if (i > 0) nb(i - 1, j, i == nx - 1 ? 2 * cx : cx);
    if (j + 1 < ny) nb(i, j + 1, j == 0 ? 2 * cy : cy);
    if (j > 0) nb(i, j - 1, j == ny - 1 ? 2 * cy : cy);
  }
  Eigen::SparseMatrix<double> a(m, m);
  a.setFromTriplets(trip.begin(), trip.end());
  impl_->ldlt.compute(a);
  if (impl_->ldlt.info() != Eigen::Success)
    throw std::runtime_error("ldc: coarse matrix factorisation failed (no Dirichlet boundary?)");
  impl_->rhs.resize(m);
  impl_->x.resize(m);
  ++factorisations_;
  last_factor_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void CoarseSolver::solve(std::span<const double> source, std::span<double> u) {
  const CoarseGrid& g = *grid_;
  const int nx = g.nx(), ny = g.ny();
  for (int n = 0; n < g.size(); ++n)
    if (g.box_dirichlet(n)) u[n] = g.box_value(n);
  const double cx = 1.0 / (g.hx() * g.hx()), cy = 1.0 / (g.hy() * g.hy());
  Eigen::VectorXd& rhs = impl_->rhs;
  for (int k = 0; k < int(free_nodes_.size()); ++k) {
    const int n = free_nodes_[k], i = n % nx, j = n / nx;
    double b = -source[n];
    auto nb = [&](int ii, int jj, double c) {
      const int nn = g.index(ii, jj);
      if (free_index_[nn] < 0) b += c * u[nn];
    };
    if (i + 1 < nx) nb(i + 1, j, i == 0 ? 2 * cx : cx);
    if (i > 0) nb(i - 1, j, i == nx - 1 ? 2 * cx : cx);
    if (j + 1 < ny) nb(i, j + 1, j == 0 ? 2 * cy : cy);
    if (j > 0) nb(i, j - 1, j == ny - 1 ? 2 * cy : cy);
    rhs[k] = row_scale_[k] * b;
  }
  impl_->x = impl_->ldlt.solve(rhs);
  for (int k = 0; k < int(free_nodes_.size()); ++k) u[free_nodes_[k]] = impl_->x[k];
}

}  // namespace nipdem::ldc
