// The reduction experiment (thesis §4.6, fig. 4.25, Table 4.3): no drum, the sleeve strips an
// assembly resting on the magnet; one run per cohesion ratio r = F_coh/F_adh, as an ensemble
// (threads or MPI, resumable). Writes OUT/reduction.csv, one time-series CSV per point and
// OUT/reduction.png; returns the JSON object of CLI.md.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/experiments/experiment.hpp"

namespace nipdem::experiments {

struct ReductionOptions {
  std::vector<double> cohesion_ratios = {1.0};
  double time_s = 0.1;                 // observation time (thesis: 100 ms)
  double sample_interval_s = 1e-4;
  double pile_width_m = 400e-6;        // assembly initially resting on the knife
  double pile_height_m = 120e-6;
  double pile_area_fraction = 0.6;
  double window_half_width_m = 600e-6;
  // Sleeve pits entering upstream of the pile: "empty" (default: at the start only the pile
  // carries toner, and in 100 ms no point of the sleeve comes round again from the supply
  // roller: 5 cm (black) / 2 cm (colour) of travel on a 12.6 cm circumference), "filled"
  // (as in the running machine, docs/geometry.md) or "preset" (the configuration's value).
  std::string pits = "empty";
};
nlohmann::json reduction(const ExperimentOptions& o, const ReductionOptions& r);

}  // namespace nipdem::experiments
