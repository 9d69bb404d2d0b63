// Contact force laws of thesis §2.2: linear spring-dashpot normal force and a tangential
// spring capped by static/dynamic Coulomb friction. Pure functions, no state but what the
// caller stores per contact (tangential stretch eta and the sliding flag).
#pragma once
#include <cmath>

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
  bool sliding = false;  // true while the contact slides with dynamic friction
};

struct ContactForce {
  double fn = 0.0;  // normal force on the body whose outward normal is n [N] (>0 repulsive)
  double ft = 0.0;  // tangential force along t = perp(n) on the same body [N]
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
  if (p.ks <= 0.0) return 0.0;
  const double gt = p.mass_proportional ? p.gamma_t * m_red : p.gamma_t;
  const double eta_trial = st.eta + v_t * dt;
  const double f_trial = -p.ks * eta_trial - gt * v_t;
  const double load = fn_load > 0.0 ? fn_load : 0.0;
  const double cap = (st.sliding ? p.mu_d : p.mu_s) * load;
  if (std::fabs(f_trial) <= cap) {
    st.eta = eta_trial;
    st.sliding = false;
    return f_trial;
  }
  st.sliding = true;
  const double f = std::copysign(p.mu_d * load, f_trial);
  st.eta = -(f + gt * v_t) / p.ks;
  return f;
}

}  // namespace nipdem::models
