// Contact force laws of thesis §2.2: linear spring-dashpot normal force and a tangential
// spring capped by static/dynamic Coulomb friction, composed with Hamaker adhesion (§2.3) into
// one contact between two surfaces (contact_force), and the elastic energy such a contact
// stores (contact_energy). Pure functions, no state but what the caller stores per contact
// (tangential stretch eta and the sliding flag).
//
// Why one composition: the engine evaluates this law in its disc-disc pair kernel and in its
// disc-wall loop, and energy() reads the springs back; all three call the functions below, so
// the law is written once. The geometry (overlap, normal, lever arms, the relative velocity of
// the contact points) and where the history is stored stay with the callers, which differ.
#pragma once
#include <cmath>

#include "nipdem/models/hamaker.hpp"

namespace nipdem::models {

// Parameters of one collision type (toner-toner, toner-roller, toner-drum, ...).
struct ContactParams {
  double k = 0.0;         // normal spring constant [N/m]                 (eq. 2.2.5, alpha = 1)
  double gamma = 0.0;     // normal damping [N s/m], or [1/s] if mass_proportional (eq. 2.2.5, beta = 1)
  double ks = 0.0;        // tangential spring constant [N/m]             (eq. 2.2.10; 2k/7 by eq. 4.3.11)
  double mu_s = 0.0;      // static friction coefficient [-]              (eq. 2.2.9)
  double mu_d = 0.0;      // dynamic friction coefficient [-], mu_d <= mu_s
  double gamma_t = 0.0;   // tangential damping [N s/m] or [1/s]; 0 in the thesis model
  // If true, gamma and gamma_t are rates [1/s] multiplied by the reduced mass of the pair
  // (the LAMMPS gran/hooke convention, used by the peer benchmark). The thesis uses false.
  bool mass_proportional = false;
};

// Per-contact history carried from step to step (eq. 2.2.11).
struct TangentialState {
  double eta = 0.0;      // tangential spring stretch along the current tangent [m]
  // 1 while the contact slides with dynamic friction, else 0 (a double, selected on like eta:
  // see tangential_force).
  double sliding = 0.0;
};

// The forces of one contact on the body whose outward normal is n (the other body gets their
// negatives): the vector force is fn n + ft t - fa n with t = perp(n) = (-n_y, n_x), and the
// torque about that body's centre is -l ft for a lever l from its centre to the contact point.
struct ContactForce {
  double fn = 0.0;  // spring-dashpot normal force [N] (> 0 repulsive); 0 unless the surfaces overlap
  double ft = 0.0;  // tangential force along t [N]; 0 unless the surfaces overlap
  double fa = 0.0;  // Hamaker attraction, a magnitude acting along -n [N]; 0 without adhesion
};

// Linear spring-dashpot normal force, eq. 2.2.5 with alpha = beta = 1:
//   F_n = k xi - gamma_eff * v_n, xi = overlap [m], v_n = separating normal velocity [m/s].
// Not clipped at zero: the contact lasts until the overlap vanishes, which is what the
// closed-form restitution and contact time of eq. 2.2.7 assume (docs/contact.md).
inline double normal_force(const ContactParams& p, double overlap, double v_n, double m_red) {
  const double g = p.mass_proportional ? p.gamma * m_red : p.gamma;
  return p.k * overlap - g * v_n;
}

// Tangential spring with static/dynamic Coulomb cap, eqs. 2.2.9-2.2.11.
// v_t: tangential velocity of this body's contact point relative to the other [m/s];
// fn_load: normal load used for the Coulomb cap [N] (>= 0); dt: time step [s].
// Updates st and returns the tangential force along t on this body.
//  - sticking: eta += v_t dt, F_t = -ks eta (- gamma_t v_t), valid while |F_t| <= mu_s F_n;
//  - beyond mu_s F_n the contact slides: |F_t| = mu_d F_n and the spring is not stretched
//    further (eta is held at the value that carries the dynamic force);
//  - a sliding contact sticks again when the trial spring force falls to mu_d F_n or below,
//    i.e. when the slip stops or reverses.
inline double tangential_force(const ContactParams& p, TangentialState& st, double v_t, double fn_load,
                               double dt, double m_red) {
  // Both outcomes are computed and one is selected (no branch on the data): in the nip, where
  // the outcome varies from pair to pair, branches were slower (0.981x on bench_nip, measured
  // 2026-12-07: docs/performance.md, eleventh pass).
  const double gt = p.mass_proportional ? p.gamma_t * m_red : p.gamma_t;
  const double eta_trial = st.eta + v_t * dt;
  const double f_trial = -p.ks * eta_trial - gt * v_t;
  const double load = fn_load > 0.0 ? fn_load : 0.0;
  const double cap = (st.sliding != 0.0 ? p.mu_d : p.mu_s) * load;
  const bool stick = std::fabs(f_trial) <= cap;
  const double f_slide = std::copysign(p.mu_d * load, f_trial);
  const double eta_slide = -(f_slide + gt * v_t) / p.ks;
  const bool spring = p.ks > 0.0;  // without a tangential spring: no force, history untouched
  st.eta = spring ? (stick ? eta_trial : eta_slide) : st.eta;
  st.sliding = spring ? (stick ? 0.0 : 1.0) : st.sliding;
  return spring ? (stick ? f_trial : f_slide) : 0.0;
}

// One contact between two surfaces, the composition of the three laws above: the normal
// spring-dashpot (eq. 2.2.5), the tangential Coulomb spring with its history (eqs. 2.2.9-2.2.11)
// and, if kAdhesion, Hamaker attraction (eq. 2.3.2).
//   overlap: xi [m], > 0 while the surfaces overlap, else minus the gap;
//   r1, r2: radii of the two spheres for Hamaker [m] (r2 = +inf for a wall);
//   v_n, v_t: relative velocity of the contact points, separating normal and tangential
//             components [m/s] (read only while overlapping: callers may pass 0 otherwise);
//   m_red: reduced mass of the pair [kg] (used only if cp.mass_proportional); dt: step [s];
//   st: the contact's tangential history, advanced while overlapping and reset to empty when
//       the contact is open (the history of a contact ends the moment it opens).
// kAdhesion = false is the plain contact law (hp is not read, fa = 0); a template parameter so
// that the engine's kernels compile without the adhesion branch.
template <bool kAdhesion>
inline ContactForce contact_force(const ContactParams& cp, const HamakerParams& hp, double r1, double r2, double overlap,
                                  double v_n, double v_t, double m_red, double dt, TangentialState& st) {
  // Evaluated whether or not the surfaces overlap, then selected (no branch on the data, as in
  // tangential_force, and for the same reason).
  const bool touching = overlap > 0.0;
  TangentialState s = st;
  const double fn = normal_force(cp, overlap, v_n, m_red);
  const double ft = tangential_force(cp, s, v_t, fn, dt, m_red);
  ContactForce f;
  f.fn = touching ? fn : 0.0;
  f.ft = touching ? ft : 0.0;
  st.eta = touching ? s.eta : 0.0;
  st.sliding = touching ? s.sliding : 0.0;
  if constexpr (kAdhesion) f.fa = hamaker_force(hp, r1, r2, -overlap);
  return f;
}

// Elastic energy stored in one contact [J]: the normal spring 1/2 k xi^2 (eq. 2.2.5, alpha = 1)
// plus the tangential spring 1/2 ks eta^2 (eq. 2.2.10); 0 for an open contact (overlap <= 0).
// Its derivative with respect to the overlap is the spring part of normal_force.
inline double contact_energy(const ContactParams& p, double overlap, double eta) {
  if (!(overlap > 0.0)) return 0.0;
  return 0.5 * p.k * overlap * overlap + 0.5 * p.ks * eta * eta;
}

}  // namespace nipdem::models
