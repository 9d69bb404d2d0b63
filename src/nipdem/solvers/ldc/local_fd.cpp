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
  Eigen::VectorXd rhs, x, r;
  int free_count = 0;
};

namespace {
int flux_points(double radius, double h) { return std::max(32, 4 * int(std::ceil(2 * constants::pi * radius / h))); }
}  // namespace

FdLocalProblem::FdLocalProblem(Vec2 lo, double hx, double hy, int cells_x, int cells_y, std::array<bool, 4> neumann,
                               std::vector<FdConductor> conductors, double eps, FdOptions opt)
    : lo_(lo), hx_(hx), hy_(hy), eps_(eps), nx_(cells_x + 1), ny_(cells_y + 1), neumann_(neumann), opt_(opt),
      cond_(std::move(conductors)), impl_(std::make_unique<Impl>()) {
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
  impl_->lu.analyzePattern(a);
  impl_->lu.factorize(a);
  impl_->a = std::move(a);
  if (impl_->lu.info() != Eigen::Success)
    throw std::runtime_error("ldc: finite-difference local matrix is singular (conductor without free neighbours?)");
  impl_->rhs.resize(nf + ng);
  impl_->x.resize(nf + ng);
  u_.assign(nn, 0.0);
  g_.assign(ng, 0.0);
}

FdLocalProblem::~FdLocalProblem() = default;

void FdLocalProblem::solve(const std::function<double(Vec2)>& boundary) {
  const int nf = impl_->free_count, ng = int(cond_.size());
  for (int n = 0; n < nx_ * ny_; ++n)
    if (kind_[n] == -2) u_[n] = boundary(node(n % nx_, n / nx_));
  Eigen::VectorXd& rhs = impl_->rhs;
  rhs.setZero();
  for (int k = 0; k < ng; ++k) rhs[nf + k] = cond_[k].charge / eps_;
  for (const Coupling& c : couplings_) rhs[c.row] -= c.coef * u_[c.node];
  impl_->x = impl_->lu.solve(rhs);
  // Short arms next to a circle make the matrix badly scaled; iterative refinement steps
  // bring the solution back to round-off (without them the LDC iteration stalls at ~1e-4).
  // Refine while the residual keeps halving (at most 6 steps).
  double last = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 6; ++it) {
    impl_->r = rhs - impl_->a * impl_->x;
    const double res = impl_->r.lpNorm<Eigen::Infinity>();
    if (!(res < 0.5 * last)) break;  // no further progress
    last = res;
    impl_->x += impl_->lu.solve(impl_->r);
  }
  for (int k = 0; k < ng; ++k) g_[k] = impl_->x[nf + k];
  for (int n = 0; n < nx_ * ny_; ++n) {
    if (kind_[n] == -1) u_[n] = impl_->x[unknown_[n]];
    else if (kind_[n] >= 0) u_[n] = g_[kind_[n]];
  }
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
