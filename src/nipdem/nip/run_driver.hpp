// Runs a nip simulation to its end time with snapshots, checkpoints, a progress line and a
// summary.json; resumes from the last checkpoint. Everything is written atomically.
//
// Output folder layout:
//   config.toml          effective configuration (after --set overrides)
//   summary.json         counts, timing, parameters, geometry, git hash (written at the end)
//   timeseries.csv       one row per snapshot
//   removals.csv         every particle that left the window (time, exit, position, size)
//   particles.pvd        ParaView collection of particles/frame_*.vtp
//   checkpoint.bin       last checkpoint (engine + runner state)
#pragma once
#include <filesystem>

#include <nlohmann/json.hpp>

#include "nipdem/nip/nip.hpp"

namespace nipdem::nip {

struct RunOptions {
  bool resume = false;
  bool force = false;      // allow writing into a folder that already holds results
  bool progress = true;
};

nlohmann::json run_nip(const NipConfig& cfg, const std::filesystem::path& out, const RunOptions& opt);

}  // namespace nipdem::nip
