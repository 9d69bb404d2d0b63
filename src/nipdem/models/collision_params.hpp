// From material data to linear spring-dashpot parameters, thesis §4.2.2 and §2.2.2:
// Hertz stiffness (eqs. 4.2.7-4.2.13), damping from restitution and contact time
// (eqs. 2.2.7-2.2.8), tangential spring ks = 2k/7 (eq. 4.3.11) and the stability bound of
// Newmark purely explicit (eq. 4.2.25); contact_params, the one derivation of a contact's
// parameters from (k, e, m_red, mu_s, mu_d). See docs/contact.md for the eq. 2.2.7 erratum.
#pragma once

#include "nipdem/models/contact.hpp"

namespace nipdem::models {

struct Material {
  double youngs_modulus_Pa = 0.0;  // E
  double poisson_ratio = 0.0;      // sigma
};

// theta_i = (1 - sigma_i^2) / (pi E_i), eq. 4.2.9 [1/Pa].
double hertz_theta(const Material& m);
// k_H = 4/(3 pi) sqrt(Ri Rj/(Ri+Rj)) / (theta_i + theta_j), eq. 4.2.8 [N/m^1.5]; Rj may be +inf.
double hertz_kH(double ri, double rj, const Material& mi, const Material& mj);
// Maximum overlap for impact speed v and reduced mass m, eq. 4.2.12 [m].
double hertz_max_overlap(double kH, double m_red, double v);
// Linear stiffness with the same energy at maximum overlap, eq. 4.2.10: k = 4/5 kH xi_max^1/2.
double linear_k_from_hertz(double kH, double xi_max);
// Eq. 4.2.13 written with p = xi_max/Ri: k = 16 sqrt(p)/(15 pi) sqrt(Rj/(Ri+Rj)) Ri/(theta_i+theta_j).
double linear_k_from_p(double p, double ri, double rj, const Material& mi, const Material& mj);

// Which relation between (k, gamma, m) and (e_n, t_n) to use.
//  physical: e_n = exp(-pi/(2 w)) — the exact solution of m xi'' + gamma xi' + k xi = 0;
//  thesis:   e_n = exp(-pi/w) as printed in eq. 2.2.7 (reproduces Table 4.2, but a simulated
//            collision with that gamma rebounds with exp(-pi/(2w)); docs/contact.md).
// In both, w = 1/2 sqrt(4 m k / gamma^2 - 1) and t_n = m pi / (gamma w) (eq. 2.2.8).
enum class DampingConvention { physical, thesis };

// gamma [N s/m] giving restitution e for stiffness k and reduced mass m (0 < e <= 1).
double gamma_from_restitution(double k, double m_red, double e, DampingConvention c = DampingConvention::physical);
// The linear contact of one collision type (eq. 2.2.5 with eqs. 2.2.9-2.2.11): stiffness k [N/m]
// as given, gamma [N s/m] from the restitution e at reduced mass m_red [kg] (eqs. 2.2.7-2.2.8),
// ks = 2k/7 (eq. 4.3.11 with c = 1), static and dynamic friction mu_s, mu_d [-]; no tangential
// damping, damping not mass-proportional (the thesis model).
ContactParams contact_params(double k, double restitution, double m_red, double mu_s, double mu_d,
                             DampingConvention c = DampingConvention::physical);
// Restitution and contact time of a linear spring-dashpot collision (underdamped only).
double restitution(double k, double gamma, double m_red, DampingConvention c = DampingConvention::physical);
double contact_time(double k, double gamma, double m_red);
// Stability bound of Newmark purely explicit, eq. 4.2.25: dt <= min(2m/gamma, 2 gamma/k).
// Returns 0 for gamma = 0 (the scheme is unconditionally unstable without damping).
double newmark_dt_max(double k, double gamma, double m_red);
// Stability bound of velocity Verlet (central difference) for a damped linear oscillator with
// the damping force explicit: dt <= 2 (sqrt(1 + zeta^2) - zeta)/w0, w0 = sqrt(k/m),
// zeta = gamma/(2 sqrt(k m)).
double verlet_dt_max(double k, double gamma, double m_red);

}  // namespace nipdem::models
