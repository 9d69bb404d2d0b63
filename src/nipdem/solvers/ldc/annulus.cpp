#include "nipdem/solvers/ldc/annulus.hpp"

#include <algorithm>
#include <cmath>

#include "nipdem/core/constants.hpp"

namespace nipdem::ldc {

int AnnulusSolution::samples_for(double R2, double h) {
  const int n = std::max(4, int(std::ceil(constants::pi * R2 / h)));
  return 2 * n + 1;
}

Vec2 AnnulusSolution::sample_point(Vec2 c, double R2, int j, int M) {
  const double t = 2.0 * constants::pi * j / M;
  return {c.x + R2 * std::cos(t), c.y + R2 * std::sin(t)};
}

void AnnulusSolution::fit(Vec2 center, double R1, double R2, double q, double eps,
                          std::span<const double> samples) {
  c_ = center;
  r1_ = R1;
  r2_ = R2;
  const int M = int(samples.size());
  const int N = (M - 1) / 2;
  a_.assign(N, 0.0);
  b_.assign(N, 0.0);
  s2n_.resize(N);
  double mean = 0.0;
  for (double s : samples) mean += s;
  mean /= M;
  // c_k of eq. 3.4.5, combined into real coefficients a_k = c_k + c_-k, b_k = i(c_k - c_-k).
  for (int j = 0; j < M; ++j) {
    const double t = 2.0 * constants::pi * j / M;
    const double ct = std::cos(t), st = std::sin(t);
    double cn = 1.0, sn = 0.0;  // cos(nt), sin(nt) by rotation
    for (int n = 0; n < N; ++n) {
      const double c2 = cn * ct - sn * st;
      sn = sn * ct + cn * st;
      cn = c2;
      a_[n] += samples[j] * cn;
      b_[n] += samples[j] * sn;
    }
  }
  const double ratio2 = (R1 / R2) * (R1 / R2);
  double p = 1.0;
  for (int n = 0; n < N; ++n) {
    a_[n] *= 2.0 / M;
    b_[n] *= 2.0 / M;
    p *= ratio2;
    s2n_[n] = p;
  }
  b0_ = -q / (2.0 * constants::pi * eps);
  a0_ = mean - b0_ * std::log(R2 / R1);
}

double AnnulusSolution::value(Vec2 x) const {
  const Vec2 d = x - c_;
  const double r = norm(d);
  if (r <= r1_) return a0_;
  const double ct = d.x / r, st = d.y / r;
  const double rho = r / r2_;                    // (r/R2)^n grows as rho^n
  const double inner = (r1_ / r) * (r1_ / r);    // (R1/r)^(2n)
  double u = a0_ + b0_ * std::log(r / r1_);
  double cn = 1.0, sn = 0.0, pr = 1.0, pi = 1.0;
  for (std::size_t n = 0; n < a_.size(); ++n) {
    const double c2 = cn * ct - sn * st;
    sn = sn * ct + cn * st;
    cn = c2;
    pr *= rho;
    pi *= inner;
    u += (a_[n] * cn + b_[n] * sn) * pr * (1.0 - pi) / (1.0 - s2n_[n]);
  }
  return u;
}

Vec2 AnnulusSolution::field(Vec2 x) const {
  const Vec2 d = x - c_;
  const double r = norm(d);
  if (r < r1_) return {};
  const double ct = d.x / r, st = d.y / r;
  const double rho = r / r2_, inner = (r1_ / r) * (r1_ / r);
  double ur = b0_ / r, ut = 0.0;  // du/dr and (1/r) du/dθ
  double cn = 1.0, sn = 0.0, pr = 1.0, pi = 1.0;
  for (std::size_t n = 0; n < a_.size(); ++n) {
    const double c2 = cn * ct - sn * st;
    sn = sn * ct + cn * st;
    cn = c2;
    pr *= rho;
    pi *= inner;
    const double k = double(n + 1) / r / (1.0 - s2n_[n]);
    ur += (a_[n] * cn + b_[n] * sn) * k * pr * (1.0 + pi);
    ut += (-a_[n] * sn + b_[n] * cn) * k * pr * (1.0 - pi);
  }
  // grad u = ur e_r + ut e_θ; E = -grad u.
  return {-(ur * ct - ut * st), -(ur * st + ut * ct)};
}

double AnnulusSolution::surface_field(double theta) const {
  const double ct = std::cos(theta), st = std::sin(theta);
  const double rho = r1_ / r2_;
  double ur = b0_ / r1_;
  double cn = 1.0, sn = 0.0, pr = 1.0;
  for (std::size_t n = 0; n < a_.size(); ++n) {
    const double c2 = cn * ct - sn * st;
    sn = sn * ct + cn * st;
    cn = c2;
    pr *= rho;
    ur += (a_[n] * cn + b_[n] * sn) * 2.0 * double(n + 1) / r1_ * pr / (1.0 - s2n_[n]);
  }
  return -ur;
}

Vec2 AnnulusSolution::force(double eps) const {
  // E_r has degree N, so E_r² cos θ has degree 2N+1: 2N+2 or more points integrate it exactly.
  const int m = 2 * int(a_.size()) + 8;
  Vec2 f{};
  for (int j = 0; j < m; ++j) {
    const double t = 2.0 * constants::pi * j / m;
    const double e = surface_field(t);
    f += Vec2{std::cos(t), std::sin(t)} * (e * e);
  }
  return f * (0.5 * eps * r1_ * 2.0 * constants::pi / m);
}

}  // namespace nipdem::ldc
