#include "nipdem/models/rc_charge.hpp"

#include <cmath>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"

namespace nipdem::charge {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr const char* kWhere = "charge model";
}  // namespace

void RcChargeParams::validate() const {
  require_positive(kWhere, "R_tt_ohm", R_tt_ohm);
  require_positive(kWhere, "R_ti_ohm", R_ti_ohm);
  require_positive(kWhere, "C_td_F", C_td_F);
  if (!(R_td_ohm > 0.0)) require_positive(kWhere, "R_td_ohm", R_td_ohm);  // inf allowed (no leak)
  require_positive(kWhere, "range_m", range_m);
}

RcChargeParams RcChargeParams::black() {
  RcChargeParams p;
  p.C_td_F = 3.9e-16;
  p.R_td_ohm = 1.8e24;
  p.range_m = 10.5e-6;
  calibrate_contacts(p, 5.9e11, 15.0, 1.0);
  return p;
}

RcChargeParams RcChargeParams::colour() {
  RcChargeParams p;
  p.C_td_F = 2.8e-16;
  p.R_td_ohm = 1.8e24;
  p.range_m = 12e-6;
  calibrate_contacts(p, 6.3e11, 15.0, 1.0);
  return p;
}

double rc_time_constant(double R_path, DrumCoupling coupling, const RcChargeParams& p) {
  if (coupling == DrumCoupling::none) return kInf;
  const double Rtd = coupling == DrumCoupling::contact ? p.R_td_ohm : kInf;
  // tau = C / (1/R_path + 1/R_td)
  const double G = 1.0 / R_path + 1.0 / Rtd;
  return G > 0.0 ? p.C_td_F / G : kInf;
}

double rc_steady_voltage(double V_drum, double R_path, DrumCoupling coupling, const RcChargeParams& p) {
  if (coupling == DrumCoupling::none) return 0.0;
  const double Rtd = coupling == DrumCoupling::contact ? p.R_td_ohm : kInf;
  const double g_path = 1.0 / R_path, G = g_path + 1.0 / Rtd;
  return G > 0.0 ? V_drum * g_path / G : 0.0;
}

double rc_update(double u, double V_drum, double R_path, DrumCoupling coupling, const RcChargeParams& p, double dt) {
  if (!(dt >= 0.0)) require_range(kWhere, "dt", dt, 0.0, kInf);
  if (!(R_path > 0.0)) require_positive(kWhere, "R_path", R_path);  // inf allowed (no path)
  const double tau = rc_time_constant(R_path, coupling, p);
  if (std::isinf(tau)) return u;  // no path and no leak: the charge is kept
  const double u_inf = rc_steady_voltage(V_drum, R_path, coupling, p);
  return u_inf + (u - u_inf) * std::exp(-dt / tau);
}

void rc_update_all(std::span<double> u, std::span<const double> R_path, std::span<const DrumCoupling> coupling,
                   double V_drum, const RcChargeParams& p, double dt) {
  if (R_path.size() != u.size() || coupling.size() != u.size())
    throw_input(kWhere, "array sizes", fmt::format("u {}, R_path {}, coupling {}", u.size(), R_path.size(), coupling.size()),
                "must be equal");
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = rc_update(u[i], V_drum, R_path[i], coupling[i], p, dt);
}

double chain_resistance(int k, const RcChargeParams& p) {
  if (k < 0) throw_input(kWhere, "contacts on path", std::to_string(k), "must be >= 0");
  return k * p.R_tt_ohm + p.R_ti_ohm;
}

void calibrate_contacts(RcChargeParams& p, double R_cal, double mean_hops, double rho) {
  require_positive(kWhere, "R_cal_ohm", R_cal);
  require_range(kWhere, "mean_hops", mean_hops, 0.0, kInf);
  require_positive(kWhere, "rho", rho);
  p.R_tt_ohm = R_cal / (mean_hops + rho);
  p.R_ti_ohm = rho * p.R_tt_ohm;
}

}  // namespace nipdem::charge
