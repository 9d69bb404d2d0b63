// The experiments of thesis chapters 4 and 5 run on the nip model, each as an ensemble of
// independent sweep points / realizations (threads or MPI, resumable; experiments/ensemble):
//  - front position of the clean-state assembly vs gap and sleeve speed (§5.1),
//  - the reduction experiment: no drum, the sleeve strips an assembly resting on the magnet
//    (§4.6, fig. 4.25, Table 4.3),
//  - the Vo-level: the lowest drum voltage that prints (§5.2),
//  - edge sharpness from many printed lines (§1.4, §5.3).
// Each returns one JSON object (CLI.md keys) and writes CSV data and PNG plots to `out`.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/experiments/nip_config.hpp"

namespace nipdem::experiments {

struct ExperimentOptions {
  std::string preset = "black";       // base configuration (unless config is given)
  std::string config;                 // a config file instead of a preset
  std::vector<std::string> sets;      // KEY=VALUE overrides applied to every point
  std::uint64_t seed = 1;
  int jobs = 1;
  bool mpi = false;
  bool resume = true;
  std::filesystem::path out = "runs/experiment";
  bool progress = true;
};

struct FrontPositionOptions {
  std::vector<double> gaps_m = {150e-6};
  std::vector<double> sleeve_speeds_m_per_min;  // empty: the preset's
  double sample_interval_s = 2e-5;
  double min_time_s = 1e-3;            // never call a run steady before this
  double max_time_s = 5e-3;            // give up (reported as not steady)
};
nlohmann::json front_position(const ExperimentOptions& o, const FrontPositionOptions& f);

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

struct PrintOptions {
  double line_length_m = 0.2e-3;       // printed line on the drum (track on while it passes)
  double line_start_m = 0.0;
  double extra_time_s = 0.0;           // beyond the time the line needs to leave the window
};
struct VoOptions {
  double v0_V = 0.0, step_V = 0.5, v_max_V = 60.0;
  double coarse_step_V = 0.0;          // 0: plain stepping (analysis::VoSearchOptions)
  int seeds = 3;
  PrintOptions print;
};
nlohmann::json vo_level(const ExperimentOptions& o, const VoOptions& v);

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

// Base configuration of an experiment point: preset or file, then the user's --set, then
// the point's own overrides.
NipConfig experiment_config(const ExperimentOptions& o, const std::vector<std::string>& point_sets);

// Exit 2 (InputError) if a user --set names a key in `fixed` ("key=value"; value "*" = varies
// per run): the experiment's own value would replace it silently. `use_instead` maps a key to
// the option that sets it. If `note_config`, a key of `use_instead` present in the configuration
// file with another value is noted on stderr (the experiment's value is used).
void reject_fixed_sets(const ExperimentOptions& o, const std::string& experiment, const std::vector<std::string>& fixed,
                       const std::map<std::string, std::string>& use_instead = {}, bool note_config = true);

}  // namespace nipdem::experiments
