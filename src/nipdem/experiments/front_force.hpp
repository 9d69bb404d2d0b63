// Net force on a front particle (thesis §2.5.4, figs. 2.23-2.25): a toner of radius d95/2 at
// surface distance l from the DI-drum, at process position x, feels
//   - the electric force towards the drum, that of a grounded conducting sphere at gap
//     d = l + d_l / eps_r (eq. 2.5.43) from a plate at the print voltage V: the exact
//     sphere-plane force (models/electric_force.hpp) and, for comparison, eq. 2.5.31 as printed
//     (2x the physical force, docs/electric.md). It acts along the drum normal; its y-component
//     counts. No screening: as in the thesis this is an upper estimate (§2.5.4);
//   - the magnet's force on its induced moment, F = (m . grad) B with m of eq. 4.5.1 (eq. 2.4.34),
//     from the configuration's magnet field (nip/nip_forces.hpp make_magnet_field).
// The net y-force is positive towards the drum. Everything comes from a NipConfig (preset or
// file, with --set overrides), with the gap set to the one asked for (the thesis takes the
// maximal gap: the weakest magnet pull, hence the largest net force to the drum of any setting).
//
// The crossing distance l*(x) is where the net force changes sign (bisection in l; the electric
// force falls and the magnet's pull grows with l, so there is one crossing). Beyond
// max over the front region of l*(x) the net force points to the roller everywhere there.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/experiments/experiment.hpp"

namespace nipdem::experiments {

struct FrontForceOptions {
  double gap_m = 240e-6;                 // w_h: the largest gap of the §5.1 measurements (fig. 5.3)
  double voltage_V = 0.0;                // 0: the configuration's print voltage ([print], else 40 V, §2.5.1)
  std::vector<double> l_m = {2e-6, 4e-6, 6e-6, 8e-6, 10e-6, 12e-6};  // figs. 2.24-2.25
  double x_min_m = -0.5e-3, x_max_m = 0.1e-3, dx_m = 5e-6;           // figs. 2.24-2.25
  double front_x_min_m = -300e-6, front_x_max_m = 0.0;               // front region (§2.5.4, §5.1)
  void validate() const;
};

struct FrontForcePoint {
  double x_m = 0, l_m = 0, y_m = 0;      // particle centre (x, y) in the nip frame
  double electric_exact_N = 0;           // y-components [N], + towards the drum
  double electric_printed_N = 0;
  double magnetic_N = 0;
  double net_exact_N() const { return electric_exact_N + magnetic_N; }
  double net_printed_N() const { return electric_printed_N + magnetic_N; }
};

// One evaluation (exposed for tests). `printed` selects eq. 2.5.31 as printed.
struct FrontForceModel {
  nip::NipConfig cfg;
  std::shared_ptr<const magnet::MagnetField> field;
  double radius_m = 0, voltage_V = 0;
  FrontForcePoint at(double x_m, double l_m) const;
  // Smallest l in [l_lo, l_hi] with net force <= 0 (NaN if the net force is still > 0 at l_hi,
  // l_lo if it is already <= 0 there).
  double crossing(double x_m, bool printed, double l_lo = 0.1e-6, double l_hi = 100e-6) const;
};
FrontForceModel make_front_force_model(const ExperimentOptions& e, const FrontForceOptions& f);

// Runs the map for one configuration; writes OUT/front_force.csv, OUT/front_force_crossing.csv,
// OUT/front_force.png (net force vs x, one curve per l, exact and as printed) and
// OUT/front_force_crossing.png; returns the JSON object.
nlohmann::json front_force(const ExperimentOptions& e, const FrontForceOptions& f);

}  // namespace nipdem::experiments
