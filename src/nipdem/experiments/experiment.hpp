// What the experiments of chapters 4-5 share (front position, reduction, Vo-level, edge
// sharpness, front force; one file each): the user's choice of base configuration, the keys an
// experiment sets itself (a user --set of one is refused, not silently replaced), the ensemble
// every experiment runs on, and the "meta" block of its JSON.
//
// An experiment reads its base configuration once (preset or file with the user's --set) and
// makes each point by editing the typed fields of a copy and calling validate(): no key=value
// strings, no second reading of the file.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/experiments/ensemble.hpp"
#include "nipdem/nip/nip_config.hpp"
#include "nipdem/io/progress.hpp"

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

// The base configuration: the preset or the file, with the user's --set; read, not yet
// validated (a point edits a copy, then validates it).
nip::NipConfig base_config(const ExperimentOptions& o);

// A key the experiment sets itself.
struct FixedKey {
  std::string key;  // dotted config key
  // The experiment's value; monostate: a new value for every run (the seed, the voltage).
  std::variant<std::monostate, double, bool, std::string> value;
  // The option that sets it; empty: the key defines the experiment (no --set, no note).
  std::string use_instead;
  // The value as messages show it; empty: %.10g for a number, a string in quotes.
  std::string shown = {};
};

// Exit 2 (InputError) if a user --set names a key in `fixed`: the experiment's own value would
// replace it silently. If `note_config`, a key with a use_instead option and a fixed value that
// the configuration file (or the preset, without a file) gives another value is noted on stderr
// (the experiment's value is used).
void reject_fixed_sets(const ExperimentOptions& o, const std::string& experiment, const std::vector<FixedKey>& fixed,
                       bool note_config = true);

// The engine seed of one run (config key run.seed) from its ensemble seed.
inline std::uint64_t run_seed(std::uint64_t ensemble_seed) { return ensemble_seed % (1ULL << 62); }

// Ensemble options of an experiment writing its realizations to OUT/sub.
ensemble::Options ensemble_options(const ExperimentOptions& o, std::size_t count, const std::string& sub);
// Progress of one long run inside the ensemble: a plain line every minute with ETA (io::Progress).
io::Progress run_progress(const ExperimentOptions& o, const std::string& label, double t_start, double t_end);
// [{index, seed, error}] of the failed realizations.
nlohmann::json failures(const ensemble::Summary& s);
// The "meta" block of an experiment's JSON (CLI.md).
// What ran: build, preset/config, overrides, seed, jobs; with the ensemble, also how many of its
// realizations each build computed ("realization_builds": [{git_hash, realizations}]; git_hash
// "unrecorded" for records older than that key).
nlohmann::json meta(const ExperimentOptions& o, const ensemble::Summary* sum = nullptr);

}  // namespace nipdem::experiments
