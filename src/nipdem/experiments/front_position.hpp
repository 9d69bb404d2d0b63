// Front position of the clean-state toner assembly vs gap and sleeve speed (thesis §5.1): one
// run per (gap, speed) point until the front is steady (analysis::detect_steady_state), run as
// an ensemble (threads or MPI, resumable). Writes OUT/front_position.csv and .png; returns the
// JSON object of CLI.md.
#pragma once
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/experiments/experiment.hpp"

namespace nipdem::experiments {

struct FrontPositionOptions {
  std::vector<double> gaps_m = {150e-6};
  std::vector<double> sleeve_speeds_m_per_min;  // empty: the preset's
  double sample_interval_s = 2e-5;
  double min_time_s = 1e-3;            // never call a run steady before this
  double max_time_s = 5e-3;            // give up (reported as not steady)
};
nlohmann::json front_position(const ExperimentOptions& o, const FrontPositionOptions& f);

}  // namespace nipdem::experiments
