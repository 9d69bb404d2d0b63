// Analytic local solution around one floating disc (thesis §3.4, eqs. 3.4.4-3.4.7):
// Laplace's equation in the annulus R1 < r < R2, u = g on r = R1 with the charge condition, and
// u = u_Γ(θ) on r = R2, where u_Γ is the trigonometric polynomial (eqs. 3.4.4-3.4.5) through
// 2N+1 equally spaced samples of the coarse solution on Γ.
//
//   u(r,θ) = a0 + b0 ln(r/R1) + Σ_n (a_n cos nθ + b_n sin nθ) f_n(r),
//   f_n(r) = ((r/R1)^n - (r/R1)^-n) / ((R2/R1)^n - (R2/R1)^-n)   (written overflow-free),
//   b0 = -q / (2π ε)  (physical sign, see problem.hpp),  a0 = mean(u_Γ) - b0 ln(R2/R1) = g.
//
// The thesis prints (3.4.7) with the normalisation of f_n folded into a_n, b_n; here a_n, b_n are
// the plain Fourier coefficients of u_Γ, which is the same solution.
#pragma once
#include <span>
#include <vector>

#include "nipdem/core/vec2.hpp"

namespace nipdem::ldc {

class AnnulusSolution {
 public:
  // Number of samples 2N+1 on Γ used for a local radius R2 and coarse spacing h: about one per h.
  static int samples_for(double R2, double h);
  // Sample points on Γ: x_j = c + R2 (cos θ_j, sin θ_j), θ_j = 2πj/M.
  static Vec2 sample_point(Vec2 c, double R2, int j, int M);

  // Fits the solution to samples u_Γ(θ_j), j = 0..M-1 (M odd), for charge q [C/m] and
  // permittivity eps [F/m]. Reuses its coefficient storage (no allocation after the first fit).
  void fit(Vec2 center, double R1, double R2, double q, double eps, std::span<const double> samples);

  double potential() const { return a0_; }  // g [V]
  Vec2 center() const { return c_; }
  double r1() const { return r1_; }
  double r2() const { return r2_; }
  int modes() const { return int(a_.size()); }
  // u at x; for |x - c| <= R1 returns g.
  double value(Vec2 x) const;
  // E = -grad u at x (zero inside the disc).
  Vec2 field(Vec2 x) const;
  // Normal field E_r on the disc surface at angle θ; surface charge density σ = ε E_r.
  double surface_field(double theta) const;
  // Electric force per unit length [N/m]: ∮ σ²/(2ε) n ds over the disc boundary, evaluated with
  // a trapezoidal rule that is exact for the trigonometric polynomial E_r².
  Vec2 force(double eps) const;

 private:
  Vec2 c_;
  double r1_ = 0, r2_ = 0, a0_ = 0, b0_ = 0;
  std::vector<double> a_, b_;  // a_[n-1], b_[n-1]: Fourier coefficients of u_Γ
  std::vector<double> s2n_;    // (R1/R2)^(2n) for the overflow-free radial functions
};

}  // namespace nipdem::ldc
