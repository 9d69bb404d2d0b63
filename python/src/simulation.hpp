// The C++ side of nipdem.Simulation: a NipRun driven in chunks of one insert interval, so that
// the caller can poll for Ctrl-C between chunks (python/src/bindings.cpp), and a restore that
// leaves the simulation untouched when the checkpoint is refused.
//
// The stepping loop is NipRun::advance_to's (steps up to the next multiple of the insert
// interval, then the inflow/outflow pass), written out here for two reasons: the poll between
// chunks, and the body ids of the last force evaluation, taken just before each pass: the
// electric provider's per-body voltages are in that order until the next evaluation, so
// voltages() can give them in the order of the current body arrays. tests/python checks that a
// run driven from here is bit for bit the run `nipdem run` makes (same checkpoint bytes).
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "nipdem/nip/nip.hpp"

namespace nipdem::python {

class Simulation {
 public:
  // The configuration as the CLI reads it: `text` laid over its preset, then the overrides
  // (KEY=VALUE, as `--set`). Forces are evaluated once at the start, as `nipdem run` does.
  Simulation(const std::string& text, const std::string& file, const std::vector<std::string>& overrides);

  // Advances to simulated time t_end [s] (no-op if already there). `poll` runs after every
  // insert interval and may throw to stop; the run is then at a consistent state between steps.
  void advance_to(double t_end, const std::function<void()>& poll);
  // Exactly n time steps (with the inflow/outflow passes that fall among them).
  void step(std::int64_t n, const std::function<void()>& poll);

  std::string checkpoint() const { return run_->checkpoint(); }
  // Restores into a fresh run and swaps it in only if the checkpoint is accepted: a refused
  // checkpoint (InputError naming `where`) leaves this simulation as it was.
  void restore(const std::string& blob, const std::string& where);

  // Capacitor voltage [V] of each body in the current body order (0 for a body inserted since
  // the last force evaluation, as the model starts it); empty without [electric]; NaN after a
  // restore until the next step (a checkpoint does not say which bodies they belong to).
  std::vector<double> voltages() const;

  // Set while a call runs with the GIL released (python/src/bindings.cpp).
  std::atomic<bool>& busy() const { return busy_; }

  nip::NipRun& run() { return *run_; }
  const nip::NipRun& run() const { return *run_; }

 private:
  // `n` steps that do not cross a multiple of the insert interval, then the pass if one is due.
  void chunk(std::int64_t n);

  nip::NipConfig cfg_;
  std::unique_ptr<nip::NipRun> run_;
  // Body ids at the last force evaluation, if an inflow/outflow pass came after it.
  std::vector<std::int64_t> eval_ids_;
  bool eval_ids_valid_ = false;
  bool voltages_unknown_ = false;
  mutable std::atomic<bool> busy_{false};
};

}  // namespace nipdem::python
