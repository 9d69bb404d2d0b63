// Charge model of the DI toner assembly (thesis §2.5.5, fig. 2.26; circuit laws as in
// eqs. 4.7.1–4.7.3 without the measurement resistor).
//
// Each toner particle within d50 of the drum is a capacitor C_td [F] to the drum; a particle
// touching the drum also leaks through R_td [ohm]. It charges from the grounded imaging
// roller through the resistance R_path [ohm] of its shortest conducting path
// (solvers/conduction_path.hpp; R_path = k R_tt + R_ti for k toner–toner contacts).
//
// State per particle: u [V] = drum potential minus particle potential, i.e. the voltage over
// C_td; the particle charge is q = -C_td u and the electric force uses |u| as the voltage of
// models/electric_force.hpp. The 1-D circuit roller -R_path- particle -(C_td || R_td)- drum
// (drum at V_d) gives
//   C_td du/dt = (V_d - u)/R_path - u/R_td,
// so with V_d constant over a step the exact update is
//   u(t+dt) = u_inf + (u(t) - u_inf) exp(-dt/tau),
//   u_inf = V_d R_td/(R_path + R_td),  tau = C_td R_path R_td/(R_path + R_td).
// No path (R_path = inf): u_inf = 0, tau = C_td R_td (leak only, if touching the drum); not
// touching the drum either: tau = inf, the particle keeps its charge. The update is exact
// for any dt (no stability limit), and for R_td = inf reduces to the plain RC charge
// u_inf = V_d, tau = R_path C_td.
#pragma once
#include <limits>
#include <span>

namespace nipdem::charge {

inline constexpr double kNoPath = std::numeric_limits<double>::infinity();

// Thesis §4.7 calibrated values (per particle): black R = 5.9e11 ohm, C = 3.9e-16 F;
// colour R = 6.3e11 ohm, C = 2.8e-16 F; R_d = 1.8e24 ohm for both.
struct RcChargeParams {
  double R_tt_ohm = 3.7e10;   // toner–toner contact resistance [ohm] (see docs/charge-model.md)
  double R_ti_ohm = 3.7e10;   // toner–imaging-roller contact resistance [ohm]
  double C_td_F = 3.9e-16;    // toner–drum capacity [F]
  double R_td_ohm = 1.8e24;   // toner–drum leak when touching [ohm]; inf = no leak
  double range_m = 10.5e-6;   // a particle within this distance of the drum is a capacitor (d50) [m]
  // Throws InputError naming "charge model" and the key (R > 0, C > 0, range > 0).
  void validate() const;
  static RcChargeParams black();   // per-contact values from the calibrated R with k = 15 hops
  static RcChargeParams colour();
};

enum class DrumCoupling {
  none,       // farther than range_m from the drum: not a capacitor, state unchanged
  capacitor,  // within range: C_td to the drum
  contact     // touching the drum: C_td parallel to R_td
};

// Exact one-step update of the capacitor voltage u [V] over dt [s] >= 0 with drum voltage
// V_drum [V] and path resistance R_path [ohm] (kNoPath if the particle has no path).
double rc_update(double u, double V_drum, double R_path, DrumCoupling coupling, const RcChargeParams& p, double dt);

// Batch form for the engine: u[i] = rc_update(u[i], V_drum, R_path[i], coupling[i], p, dt)
// for all i (arrays of equal length; InputError otherwise).
void rc_update_all(std::span<double> u, std::span<const double> R_path, std::span<const DrumCoupling> coupling,
                   double V_drum, const RcChargeParams& p, double dt);

// Time constant [s] and asymptotic voltage [V] of the step above (tau = inf: frozen).
double rc_time_constant(double R_path, DrumCoupling coupling, const RcChargeParams& p);
double rc_steady_voltage(double V_drum, double R_path, DrumCoupling coupling, const RcChargeParams& p);

// Path resistance of a chain of k toner–toner contacts and one roller contact [ohm].
double chain_resistance(int k, const RcChargeParams& p);

// Per-contact calibration (docs/charge-model.md): given the calibrated assembly resistance
// R_cal [ohm], the mean number of toner–toner contacts <k> on the shortest paths of the
// particles at the drum, and rho = R_ti/R_tt, returns R_tt = R_cal/(<k> + rho) and sets
// R_ti = rho R_tt so that a path with <k> contacts has resistance R_cal.
void calibrate_contacts(RcChargeParams& p, double R_cal, double mean_hops, double rho = 1.0);

}  // namespace nipdem::charge
