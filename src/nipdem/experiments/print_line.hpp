// Printing one line (§5.2, §5.3): what the Vo-level and the edge-sharpness experiments share.
// A print run turns the drum track on for the line and runs until the drum up to the line's end
// (plus a tail) has left the window; the part before the track first switches on is the same
// for every voltage of one seed, so it can be simulated once and restored (print_prefix).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "nipdem/experiments/experiment.hpp"
#include "nipdem/nip/nip.hpp"

namespace nipdem::experiments {

struct PrintOptions {
  double line_length_m = 0.2e-3;       // printed line on the drum (track on while it passes)
  double line_start_m = 0.0;
  double extra_time_s = 0.0;           // beyond the time the line needs to leave the window
};

// The printed line's options, checked before any run (a NaN would print nothing and "succeed").
void check_print_options(const std::string& where, const PrintOptions& p);

// The keys a print run sets itself ([electric] on, the line, no VTK, the seed); the voltage is
// one of them if `voltage_fixed` (the Vo-level scans it; edge sharpness uses the config's).
std::vector<FixedKey> print_fixed_keys(const PrintOptions& p, bool voltage_fixed);

// The configuration of a print run, validated: base with the line on (at `voltage_V` if given,
// else the configuration's print voltage); with a seed, the run's (engine seed, no VTK).
nip::NipConfig print_config(const nip::NipConfig& base, const PrintOptions& p, std::optional<double> voltage_V,
                       std::optional<std::uint64_t> seed);

struct PrintRun { long printed; std::vector<nip::NipRun::CoverageBin> coverage; double time; double s_observed_m; };

// Prints one line; runs until the drum up to `tail_m` beyond the line's end has left the window
// (+ extra_time_s). s_observed_m: the drum coordinate up to which the drum has left the window.
// `prefix`: a checkpoint from print_prefix() for the same seed, taken before the track switches
// on; the run starts from it instead of from t = 0 (identical result, less work).
PrintRun print_line(const ExperimentOptions& o, const nip::NipConfig& base, const PrintOptions& p, double voltage, std::uint64_t seed,
                    double tail_m = 0.0, const std::string* prefix = nullptr);

// The part of a print run before the drum track first switches on: the same for every voltage
// of one seed (the track is at its off voltage until then), so a Vo-level scan simulates it once.
// Stops two time steps before the switch; returns the checkpoint there (nothing if the track
// switches on within the first insert interval: then there is nothing worth sharing).
std::optional<std::string> print_prefix(const ExperimentOptions& o, const nip::NipConfig& base, const PrintOptions& p, std::uint64_t seed);

}  // namespace nipdem::experiments
