// Edge sharpness (thesis §1.4, §5.3): many realizations of one printed line; the average
// coverage along the drum and the 10-90 % widths of its two edges, bootstrapped over the
// realizations. Writes OUT/lines.csv, OUT/coverage_average.csv and .png; returns the JSON
// object of CLI.md.
#pragma once
#include <nlohmann/json.hpp>

#include "nipdem/experiments/experiment.hpp"
#include "nipdem/experiments/print_line.hpp"

namespace nipdem::experiments {

struct EdgeOptions {
  int realizations = 50;
  PrintOptions print;
  int bootstrap = 400;
  // Analysis range beyond each end of the line. Each run lasts until the drum up to line end +
  // margin has left the window (plus --extra-time): drum that is still in the window at the end
  // is unobserved, and counting it as "not covered" would cut the back edge (docs/analysis.md).
  double margin_m = 200e-6;
};
nlohmann::json edge_sharpness(const ExperimentOptions& o, const EdgeOptions& e);

}  // namespace nipdem::experiments
