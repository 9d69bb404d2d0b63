// The Vo-level (thesis §5.2): the lowest drum voltage that prints, per seed, by stepping the
// voltage of one printed line (analysis::find_vo_level); statistics over the seeds. Returns the
// JSON object of CLI.md.
#pragma once
#include <nlohmann/json.hpp>

#include "nipdem/experiments/experiment.hpp"
#include "nipdem/experiments/print_line.hpp"

namespace nipdem::experiments {

struct VoOptions {
  double v0_V = 0.0, step_V = 0.5, v_max_V = 60.0;
  double coarse_step_V = 0.0;          // 0: plain stepping (analysis::VoSearchOptions)
  int seeds = 3;
  PrintOptions print;
};
nlohmann::json vo_level(const ExperimentOptions& o, const VoOptions& v);

}  // namespace nipdem::experiments
