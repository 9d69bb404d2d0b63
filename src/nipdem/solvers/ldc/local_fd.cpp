#include "nipdem/solvers/ldc/local_fd.hpp"

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "nipdem/core/constants.hpp"

namespace nipdem::ldc {

struct FdLocalProblem::Impl {
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
  Eigen::SparseMatrix<double> a;
  // Row-major copy for the residuals of the refinement: a gather per row is about twice as
  // fast as the column-major scatter, and the residuals cost as much as the LU solves.
  Eigen::SparseMatrix<double, Eigen::RowMajor> a_rows;
  Eigen::VectorXd rhs, x, r;
  int free_count = 0;
  bool analyzed = false;
  std::vector<int> pattern_outer, pattern_inner;  // sparsity pattern seen by analyzePattern
};

namespace {
// Componentwise backward error at which a solve counts as exact (a few units of round-off).
constexpr double kRoundOff = 8.0 * std::numeric_limits<double>::epsilon();
int flux_points(double radius, double h) { return std::max(32, 4 * int(std::ceil(2 * constants::pi * radius / h))); }
}  // namespace

FdLocalProblem::FdLocalProblem(Vec2 lo, double hx, double hy, int cells_x, int cells_y, std::array<bool, 4> neumann,
                               std::vector<FdConductor> conductors, double eps, FdOptions opt)
    : lo_(lo), hx_(hx), hy_(hy), eps_(eps), nx_(cells_x + 1), ny_(cells_y + 1), neumann_(neumann), opt_(opt),
      cond_(std::move(conductors)), impl_(std::make_unique<Impl>()) {
  assemble();
  factorize();
  impl_->rhs.resize(impl_->a.rows());
  impl_->x.setZero(impl_->a.rows());
  u_.assign(std::size_t(nx_) * ny_, 0.0);
  g_.assign(cond_.size(), 0.0);
}

void FdLocalProblem::assemble() {
  const int nn = nx_ * ny_;
  const double hmin = std::min(hx_, hy_);
  kind_.assign(nn, -1);
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const int n = j * nx_ + i;
      const bool dir = (i == 0 && !neumann_[0]) || (i == nx_ - 1 && !neumann_[1]) || (j == 0 && !neumann_[2]) ||
                       (j == ny_ - 1 && !neumann_[3]);
      if (dir) { kind_[n] = -2; continue; }
      const Vec2 x = node(i, j);
      for (int k = 0; k < int(cond_.size()); ++k) {
        const FdConductor& c = cond_[k];
        const bool in = c.rectangle ? (x.x >= c.lo.x - 1e-9 * hx_ && x.x <= c.hi.x + 1e-9 * hx_ &&
                                       x.y >= c.lo.y - 1e-9 * hy_ && x.y <= c.hi.y + 1e-9 * hy_)
                                    : norm(x - c.center) <= c.radius + 1e-3 * hmin;
        if (in) { kind_[n] = k; break; }
      }
    }
  unknown_.assign(nn, -1);
  int nf = 0;
  for (int n = 0; n < nn; ++n)
    if (kind_[n] == -1) unknown_[n] = nf++;
  impl_->free_count = nf;
  const int ng = int(cond_.size());
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(std::size_t(nf) * 5 + 64 * ng);
  couplings_.clear();
  // Adds coef * u(node) to row; node may be free, a conductor (-> g) or a Dirichlet node (-> rhs).
  auto add = [&](int row, int n, double coef) {
    if (kind_[n] == -1) trip.emplace_back(row, unknown_[n], coef);
    else if (kind_[n] >= 0) trip.emplace_back(row, nf + kind_[n], coef);
    else couplings_.push_back({row, n, coef});
  };
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const int n = j * nx_ + i;
      if (kind_[n] != -1) continue;
      const int row = unknown_[n];
      const Vec2 p = node(i, j);
      double diag = 0.0;
      for (int axis = 0; axis < 2; ++axis) {
        const double h = axis == 0 ? hx_ : hy_;
        double arm[2];
        int target[2];
        for (int s = 0; s < 2; ++s) {
          const int dir = s == 0 ? 1 : -1;
          int qi = i + (axis == 0 ? dir : 0), qj = j + (axis == 1 ? dir : 0);
          int sgn = dir;
          if (qi < 0 || qi >= nx_ || qj < 0 || qj >= ny_) {  // Neumann side: mirror node
            qi = i - (axis == 0 ? dir : 0);
            qj = j - (axis == 1 ? dir : 0);
            sgn = -dir;
          }
          const int q = qj * nx_ + qi;
          target[s] = q;
          arm[s] = h;
          if (opt_.shortley_weller && kind_[q] >= 0 && !cond_[kind_[q]].rectangle) {  // Shortley-Weller arm to the circle
            const FdConductor& c = cond_[kind_[q]];
            const Vec2 d = axis == 0 ? Vec2{double(sgn), 0.0} : Vec2{0.0, double(sgn)};
            const Vec2 w = p - c.center;
            const double b = dot(w, d), disc = b * b - (norm2(w) - c.radius * c.radius);
            const double t = -b - std::sqrt(std::max(disc, 0.0));
            arm[s] = std::clamp(t, 1e-3 * h, h);
          }
        }
        const double sum = arm[0] + arm[1];
        for (int s = 0; s < 2; ++s) {
          const double c = 2.0 / (arm[s] * sum);
          add(row, target[s], c);
          diag -= c;
        }
      }
      trip.emplace_back(row, row, diag);
    }
  // Charge conditions (rows nf + k), divided by ε.
  flux_radius_.assign(ng, 0.0);
  for (int k = 0; k < ng; ++k) {
    const int row = nf + k;
    const FdConductor& c = cond_[k];
    if (c.rectangle) {
      for (int n = 0; n < nn; ++n) {
        if (kind_[n] != k) continue;
        const int i = n % nx_, j = n / nx_;
        const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
        for (int s = 0; s < 4; ++s) {
          const int qi = i + di[s], qj = j + dj[s];
          if (qi < 0 || qi >= nx_ || qj < 0 || qj >= ny_) continue;
          const int q = qj * nx_ + qi;
          if (kind_[q] == k) continue;
          const double ratio = s < 2 ? hy_ / hx_ : hx_ / hy_;
          add(row, q, -ratio);  // -(u_q - g) * ratio
          trip.emplace_back(row, nf + k, ratio);
        }
      }
    } else {
      // Flux circle offset, reduced where another conductor or the rectangle side is closer than
      // the offset plus one cell (its bilinear cells must lie in the field region of disc k).
      double room = std::min({c.center.x - c.radius - lo_.x, lo_.x + (nx_ - 1) * hx_ - c.center.x - c.radius,
                              c.center.y - c.radius - lo_.y, lo_.y + (ny_ - 1) * hy_ - c.center.y - c.radius});
      for (int j = 0; j < ng; ++j) {
        if (j == k) continue;
        const FdConductor& o = cond_[j];
        const double gap = o.rectangle ? norm(c.center - Vec2{std::clamp(c.center.x, o.lo.x, o.hi.x),
                                                                 std::clamp(c.center.y, o.lo.y, o.hi.y)}) - c.radius
                                       : norm(c.center - o.center) - c.radius - o.radius;
        room = std::min(room, gap);
      }
      const double offset = std::clamp(room / hmin - 1.5, 0.0, opt_.flux_offset_cells);
      const double rf = c.radius + offset * hmin;
      flux_radius_[k] = rf;
      const int m = flux_points(rf, hmin);
      const double wq = -2.0 * constants::pi * rf / m;
      for (int s = 0; s < m; ++s) {
        const double t = 2.0 * constants::pi * s / m;
        const double ct = std::cos(t), st = std::sin(t);
        const Vec2 x = c.center + rf * Vec2{ct, st};
        const int ci = std::clamp(int(std::floor((x.x - lo_.x) / hx_)), 0, nx_ - 2);
        const int cj = std::clamp(int(std::floor((x.y - lo_.y) / hy_)), 0, ny_ - 2);
        const double X = (x.x - lo_.x) / hx_ - ci, Y = (x.y - lo_.y) / hy_ - cj;
        // eq. 3.10.6: d/dr of the bilinear interpolant
        const double w00 = ct * (-(1 - Y)) / hx_ + st * (-(1 - X)) / hy_;
        const double w10 = ct * (1 - Y) / hx_ + st * (-X) / hy_;
        const double w01 = ct * (-Y) / hx_ + st * (1 - X) / hy_;
        const double w11 = ct * Y / hx_ + st * X / hy_;
        add(row, cj * nx_ + ci, wq * w00);
        add(row, cj * nx_ + ci + 1, wq * w10);
        add(row, (cj + 1) * nx_ + ci, wq * w01);
        add(row, (cj + 1) * nx_ + ci + 1, wq * w11);
      }
    }
  }
  Eigen::SparseMatrix<double> a(nf + ng, nf + ng);
  a.setFromTriplets(trip.begin(), trip.end());
  a.makeCompressed();
  impl_->a = std::move(a);
  impl_->a_rows = impl_->a;
}

void FdLocalProblem::factorize() {
  const auto& a = impl_->a;
  const int nnz = int(a.nonZeros());
  const bool same_pattern =
      impl_->analyzed && impl_->pattern_outer.size() == std::size_t(a.outerSize() + 1) &&
      impl_->pattern_inner.size() == std::size_t(nnz) &&
      std::equal(impl_->pattern_outer.begin(), impl_->pattern_outer.end(), a.outerIndexPtr()) &&
      std::equal(impl_->pattern_inner.begin(), impl_->pattern_inner.end(), a.innerIndexPtr());
  if (!same_pattern) {
    impl_->lu.analyzePattern(a);
    impl_->pattern_outer.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1);
    impl_->pattern_inner.assign(a.innerIndexPtr(), a.innerIndexPtr() + nnz);
    impl_->analyzed = true;
  }
  impl_->lu.factorize(a);
  if (impl_->lu.info() != Eigen::Success)
    throw std::runtime_error("ldc: finite-difference local matrix is singular (conductor without free neighbours?)");
  ++counters_.factorisations;
  stale_ = false;
  fresh_backward_error_ = -1.0;  // measured by the next solve
}

FdLocalProblem::~FdLocalProblem() = default;

int FdLocalProblem::refine(int max_steps, double min_reduction) {
  // Short arms next to a circle make the matrix badly scaled; iterative refinement steps bring
  // the solution back to round-off (without them the LDC iteration stalls at ~1e-4). Refine until
  // the componentwise backward error is at round-off level, or while the residual falls by
  // min_reduction per step. With the factorisation of an earlier matrix the same loop is a
  // preconditioned stationary iteration for the current matrix.
  const auto& a = impl_->a_rows;
  Eigen::VectorXd& x = impl_->x;
  Eigen::VectorXd& r = impl_->r;
  const Eigen::VectorXd& b = impl_->rhs;
  r.resize(b.size());
  double last = std::numeric_limits<double>::infinity();
  int steps = 0;
  for (;;) {
    // r = b - A x and the componentwise backward error max_i |r_i| / (|A||x| + |b|)_i, one pass.
    double res = 0.0, berr = 0.0;
    for (int i = 0; i < int(a.outerSize()); ++i) {
      double ri = b[i], den = std::abs(b[i]);
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(a, i); it; ++it) {
        const double t = it.value() * x[it.col()];
        ri -= t;
        den += std::abs(t);
      }
      r[i] = ri;
      res = std::max(res, std::abs(ri));
      if (den > 0) berr = std::max(berr, std::abs(ri) / den);
    }
    backward_error_ = berr;
    if (steps >= max_steps || berr <= kRoundOff || !(res < min_reduction * last)) break;
    last = res;
    x += impl_->lu.solve(r);
    ++steps;
  }
  counters_.refinement_steps += steps;
  return steps;
}

void FdLocalProblem::solve(const std::function<double(Vec2)>& boundary) {
  const int nf = impl_->free_count, ng = int(cond_.size());
  for (int n = 0; n < nx_ * ny_; ++n)
    if (kind_[n] == -2) u_[n] = boundary(node(n % nx_, n / nx_));
  Eigen::VectorXd& rhs = impl_->rhs;
  rhs.setZero();
  for (int k = 0; k < ng; ++k) rhs[nf + k] = cond_[k].charge / eps_;
  for (const Coupling& c : couplings_) rhs[c.row] -= c.coef * u_[c.node];
  // With a kept (stale) factorisation, start from the previous solution (same unknowns, close in
  // an LDC iteration): the error of the preconditioned iteration is then relative to the change.
  // With a fresh factorisation a plain solve is as accurate and saves one residual.
  if (stale_ && have_solution_) {
    impl_->r.noalias() = rhs;
    impl_->r.noalias() -= impl_->a_rows * impl_->x;
    impl_->x += impl_->lu.solve(impl_->r);
  } else {
    impl_->x = impl_->lu.solve(rhs);
  }
  constexpr int kFreshSteps = 6;
  // A kept factorisation must reach the round-off level of a fresh one within a few steps;
  // otherwise it is too stale to be cheaper and the current matrix is factorised.
  constexpr int kStaleSteps = 12;
  if (stale_) {
    ++counters_.stale_solves;
    // A step that reduces the residual by less than 10x means the old factorisation is too far
    // from the current matrix to reach round-off in kStaleSteps: give up early.
    refine(kStaleSteps, 0.1);
    const double target = std::max(4.0 * fresh_backward_error_, 64.0 * std::numeric_limits<double>::epsilon());
    if (!(backward_error_ <= target)) {
      factorize();
      refine(kFreshSteps, 0.5);
      fresh_backward_error_ = backward_error_;
    }
  } else {
    refine(kFreshSteps, 0.5);
    if (fresh_backward_error_ < 0) fresh_backward_error_ = backward_error_;  // reference for stale solves
  }
  have_solution_ = true;
  for (int k = 0; k < ng; ++k) g_[k] = impl_->x[nf + k];
  for (int n = 0; n < nx_ * ny_; ++n) {
    if (kind_[n] == -1) u_[n] = impl_->x[unknown_[n]];
    else if (kind_[n] >= 0) u_[n] = g_[kind_[n]];
  }
}

bool FdLocalProblem::update_conductors(std::vector<FdConductor> conductors) {
  if (conductors.size() != cond_.size())
    throw std::invalid_argument("ldc: update_conductors needs the same number of conductors");
  for (std::size_t k = 0; k < cond_.size(); ++k)
    if (conductors[k].rectangle != cond_[k].rectangle)
      throw std::invalid_argument("ldc: update_conductors cannot change a conductor's kind");
  const std::vector<int> old_kind = kind_;
  const Eigen::SparseMatrix<double> old_a = impl_->a;
  cond_ = std::move(conductors);
  assemble();
  if (kind_ != old_kind) {  // unknowns renumbered: the old factorisation and solution do not apply
    have_solution_ = false;
    impl_->x.setZero(impl_->a.rows());
    impl_->rhs.resize(impl_->a.rows());
    factorize();
    return false;
  }
  const auto& a = impl_->a;
  const bool identical = a.nonZeros() == old_a.nonZeros() &&
                         std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1, old_a.outerIndexPtr()) &&
                         std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), old_a.innerIndexPtr()) &&
                         std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), old_a.valuePtr());
  if (!identical) stale_ = true;
  return true;
}

bool FdLocalProblem::contains(Vec2 x) const {
  const double tx = 1e-9 * hx_, ty = 1e-9 * hy_;
  return x.x >= lo_.x - tx && x.x <= lo_.x + (nx_ - 1) * hx_ + tx && x.y >= lo_.y - ty &&
         x.y <= lo_.y + (ny_ - 1) * hy_ + ty;
}

double FdLocalProblem::value(Vec2 x) const {
  for (int k = 0; k < int(cond_.size()); ++k)
    if (!cond_[k].rectangle && norm(x - cond_[k].center) <= cond_[k].radius) return g_[k];
  const double fx = std::clamp((x.x - lo_.x) / hx_, 0.0, double(nx_ - 1));
  const double fy = std::clamp((x.y - lo_.y) / hy_, 0.0, double(ny_ - 1));
  const int i = std::min(int(fx), nx_ - 2), j = std::min(int(fy), ny_ - 2);
  const double X = fx - i, Y = fy - j;
  return (1 - X) * (1 - Y) * u_[j * nx_ + i] + X * (1 - Y) * u_[j * nx_ + i + 1] + (1 - X) * Y * u_[(j + 1) * nx_ + i] +
         X * Y * u_[(j + 1) * nx_ + i + 1];
}

Vec2 FdLocalProblem::field(Vec2 x) const {
  for (int k = 0; k < int(cond_.size()); ++k)
    if (!cond_[k].rectangle && norm(x - cond_[k].center) < cond_[k].radius) return {};
  const double fx = std::clamp((x.x - lo_.x) / hx_, 0.0, double(nx_ - 1));
  const double fy = std::clamp((x.y - lo_.y) / hy_, 0.0, double(ny_ - 1));
  const int i = std::min(int(fx), nx_ - 2), j = std::min(int(fy), ny_ - 2);
  const double X = fx - i, Y = fy - j;
  const double u00 = u_[j * nx_ + i], u10 = u_[j * nx_ + i + 1], u01 = u_[(j + 1) * nx_ + i],
               u11 = u_[(j + 1) * nx_ + i + 1];
  const double gx = ((1 - Y) * (u10 - u00) + Y * (u11 - u01)) / hx_;
  const double gy = ((1 - X) * (u01 - u00) + X * (u11 - u10)) / hy_;
  return {-gx, -gy};
}

Vec2 FdLocalProblem::force(int k) const {
  // Maxwell stress ∮ ε[(E·n)E - E²n/2] ds on the flux circle: equal to ∮ σ²/(2ε) n ds on the disc
  // surface (divergence-free stress in the charge-free region between them).
  const FdConductor& c = cond_[k];
  if (c.rectangle) return {};
  const double rf = flux_radius_[k];
  const int m = flux_points(rf, std::min(hx_, hy_));
  Vec2 f{};
  for (int s = 0; s < m; ++s) {
    const double t = 2.0 * constants::pi * s / m;
    const Vec2 n{std::cos(t), std::sin(t)};
    const Vec2 e = field(c.center + rf * n);
    f += dot(e, n) * e - 0.5 * norm2(e) * n;
  }
  return f * (eps_ * 2.0 * constants::pi * rf / m);
}

double FdLocalProblem::box_flux_charge(int k, int margin) const {
  const FdConductor& c = cond_[k];
  const Vec2 lo = c.rectangle ? c.lo : c.center - Vec2{c.radius, c.radius};
  const Vec2 hi = c.rectangle ? c.hi : c.center + Vec2{c.radius, c.radius};
  const int i0 = int(std::floor((lo.x - lo_.x) / hx_ + 1e-9)) - margin;
  const int i1 = int(std::ceil((hi.x - lo_.x) / hx_ - 1e-9)) + margin;
  const int j0 = int(std::floor((lo.y - lo_.y) / hy_ + 1e-9)) - margin;
  const int j1 = int(std::ceil((hi.y - lo_.y) / hy_ - 1e-9)) + margin;
  if (i0 < 1 || j0 < 1 || i1 > nx_ - 2 || j1 > ny_ - 2)
    throw std::runtime_error("ldc: flux box does not fit in the finite-difference grid");
  auto u = [&](int i, int j) { return u_[j * nx_ + i]; };
  double flux = 0.0;  // Σ (u_out - u_in) * face/dist  =  ∮ du/dn ds with n pointing outward
  for (int j = j0; j <= j1; ++j)
    flux += (u(i0 - 1, j) - u(i0, j) + u(i1 + 1, j) - u(i1, j)) * hy_ / hx_;
  for (int i = i0; i <= i1; ++i)
    flux += (u(i, j0 - 1) - u(i, j0) + u(i, j1 + 1) - u(i, j1)) * hx_ / hy_;
  return -eps_ * flux;
}

}  // namespace nipdem::ldc
