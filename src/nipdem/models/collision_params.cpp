#include "nipdem/models/collision_params.hpp"

#include <cmath>
#include <limits>

#include "nipdem/core/constants.hpp"

namespace nipdem::models {

using constants::pi;

double hertz_theta(const Material& m) {  // eq. 4.2.9
  return (1.0 - m.poisson_ratio * m.poisson_ratio) / (pi * m.youngs_modulus_Pa);
}

double hertz_kH(double ri, double rj, const Material& mi, const Material& mj) {  // eq. 4.2.8
  const double reff = std::isinf(rj) ? ri : ri * rj / (ri + rj);
  return 4.0 / (3.0 * pi) * std::sqrt(reff) / (hertz_theta(mi) + hertz_theta(mj));
}

double hertz_max_overlap(double kH, double m_red, double v) {  // eq. 4.2.12
  return std::pow(5.0 * m_red * v * v / (4.0 * kH), 0.4);
}

double linear_k_from_hertz(double kH, double xi_max) {  // eq. 4.2.10
  return 0.8 * kH * std::sqrt(xi_max);
}

double linear_k_from_p(double p, double ri, double rj, const Material& mi, const Material& mj) {  // eq. 4.2.13
  const double ratio = std::isinf(rj) ? 1.0 : rj / (ri + rj);
  return 16.0 * std::sqrt(p) / (15.0 * pi) * std::sqrt(ratio) * ri / (hertz_theta(mi) + hertz_theta(mj));
}

// With w = 1/2 sqrt(4mk/gamma^2 - 1): physical e = exp(-pi/(2w)), thesis e = exp(-pi/w).
double gamma_from_restitution(double k, double m_red, double e, DampingConvention c) {
  if (e >= 1.0) return 0.0;
  const double lne = -std::log(e);
  const double w = (c == DampingConvention::physical ? pi / (2.0 * lne) : pi / lne);
  // 4 m k / gamma^2 = 4 w^2 + 1
  return std::sqrt(4.0 * m_red * k / (4.0 * w * w + 1.0));
}

ContactParams contact_params(double k, double restitution, double m_red, double mu_s, double mu_d, DampingConvention c) {
  ContactParams p;
  p.k = k;
  p.gamma = gamma_from_restitution(k, m_red, restitution, c);
  p.ks = 2.0 * k / 7.0;  // eq. 4.3.11 with c = 1
  p.mu_s = mu_s;
  p.mu_d = mu_d;
  return p;
}

double restitution(double k, double gamma, double m_red, DampingConvention c) {
  if (gamma == 0.0) return 1.0;
  const double w = 0.5 * std::sqrt(4.0 * m_red * k / (gamma * gamma) - 1.0);
  return std::exp(-(c == DampingConvention::physical ? pi / (2.0 * w) : pi / w));
}

double contact_time(double k, double gamma, double m_red) {  // eq. 2.2.7, t_n = pi/omega_d
  const double wd2 = k / m_red - gamma * gamma / (4.0 * m_red * m_red);
  return pi / std::sqrt(wd2);
}

double newmark_dt_max(double k, double gamma, double m_red) {  // eq. 4.2.25
  if (gamma <= 0.0) return 0.0;
  return std::fmin(2.0 * m_red / gamma, 2.0 * gamma / k);
}

double verlet_dt_max(double k, double gamma, double m_red) {
  const double w0 = std::sqrt(k / m_red);
  const double zeta = gamma / (2.0 * std::sqrt(k * m_red));
  return 2.0 * (std::sqrt(1.0 + zeta * zeta) - zeta) / w0;
}

}  // namespace nipdem::models
