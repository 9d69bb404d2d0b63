#include "simulation.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace nipdem::python {

using nip::NipRun;

Simulation::Simulation(const std::string& text, const std::string& file, const std::vector<std::string>& overrides)
    : cfg_(nip::parse_nip_config(text, file, overrides)), run_(std::make_unique<NipRun>(cfg_)) {
  run_->sim().compute_forces();  // as run_nip before its first snapshot
}

void Simulation::chunk(std::int64_t n) {
  auto& sim = run_->sim();
  for (std::int64_t i = 0; i < n; ++i) sim.step();
  eval_ids_valid_ = false;
  voltages_unknown_ = false;
  if (sim.step_count() % cfg_.insert_interval == 0) {
    if (run_->electric()) {
      eval_ids_ = sim.bodies().id;
      eval_ids_valid_ = true;
    }
    run_->exchange();
  }
}

void Simulation::advance_to(double t_end, const std::function<void()>& poll) {
  auto& sim = run_->sim();
  const double dt = run_->time_step().dt;
  const std::int64_t interval = cfg_.insert_interval;
  while (sim.time() < t_end - 0.5 * dt) {
    const std::int64_t n = std::min<std::int64_t>(interval - sim.step_count() % interval,
                                                  static_cast<std::int64_t>(std::ceil((t_end - sim.time()) / dt - 0.5)));
    chunk(n);
    if (poll) poll();
  }
}

void Simulation::step(std::int64_t n, const std::function<void()>& poll) {
  auto& sim = run_->sim();
  const std::int64_t interval = cfg_.insert_interval;
  while (n > 0) {
    const std::int64_t k = std::min<std::int64_t>(n, interval - sim.step_count() % interval);
    chunk(k);
    n -= k;
    if (poll) poll();
  }
}

void Simulation::restore(const std::string& blob, const std::string& where) {
  auto fresh = std::make_unique<NipRun>(cfg_);
  fresh->restore(blob, where);
  run_ = std::move(fresh);
  eval_ids_valid_ = false;
  voltages_unknown_ = true;  // the checkpoint does not say which bodies its voltages belong to
}

std::vector<double> Simulation::voltages() const {
  const auto* e = run_->electric();
  if (!e) return {};
  const auto& ids = run_->sim().bodies().id;
  const auto& u = e->voltage();
  if (voltages_unknown_) return std::vector<double>(ids.size(), std::nan(""));
  if (!eval_ids_valid_ && u.size() == ids.size()) return u;
  // The last evaluation saw the bodies of eval_ids_ (or, before any pass, the current ones).
  const std::vector<std::int64_t>& seen = eval_ids_valid_ ? eval_ids_ : ids;
  std::unordered_map<std::int64_t, double> by_id;
  for (std::size_t i = 0; i < seen.size() && i < u.size(); ++i) by_id[seen[i]] = u[i];
  std::vector<double> out(ids.size(), 0.0);
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (auto it = by_id.find(ids[i]); it != by_id.end()) out[i] = it->second;
  return out;
}

}  // namespace nipdem::python
