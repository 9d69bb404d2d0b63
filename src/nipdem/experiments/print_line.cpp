#include "nipdem/experiments/print_line.hpp"

#include <cmath>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"

namespace nipdem::experiments {

void check_print_options(const std::string& where, const PrintOptions& p) {
  require_range(where, "--line-length (print.length_m)", p.line_length_m, 1e-6, 1.0);
  require_range(where, "--line-start (print.start_m)", p.line_start_m, -1.0, 1.0);
  require_range(where, "--extra-time", p.extra_time_s, 0.0, 1.0);
}

std::vector<FixedKey> print_fixed_keys(const PrintOptions& p, bool voltage_fixed) {
  std::vector<FixedKey> k = {{"electric.enabled", true, ""}, {"print.pattern", std::string("line"), ""}};
  if (voltage_fixed) k.push_back({"print.voltage_V", std::monostate{}, "--v0 and --step"});
  k.push_back({"print.start_m", p.line_start_m, "--line-start"});
  k.push_back({"print.length_m", p.line_length_m, "--line-length"});
  k.push_back({"output.vtk", false, ""});
  k.push_back({"run.seed", std::monostate{}, "--seed"});
  return k;
}

nip::NipConfig print_config(const nip::NipConfig& base, const PrintOptions& p, std::optional<double> voltage_V,
                       std::optional<std::uint64_t> seed) {
  nip::NipConfig c = base;
  nip::set_print_line(c, p.line_start_m, p.line_length_m, voltage_V);
  if (seed) {
    c.vtk = false;
    c.seed = run_seed(*seed);
  }
  validate(c);
  return c;
}

PrintRun print_line(const ExperimentOptions& o, const nip::NipConfig& base, const PrintOptions& p, double voltage, std::uint64_t seed,
                    double tail_m, const std::string* prefix) {
  const nip::NipConfig cfg = print_config(base, p, voltage, seed);
  // run until the drum up to line end + tail_m has passed the window's downstream edge
  const double v = std::fabs(cfg.drum_speed);
  const double ride = cfg.nip_x - cfg.x_min;  // nip to the window's downstream edge along the drum
  const double t_end = (p.line_start_m + p.line_length_m + tail_m + ride) / v + p.extra_time_s;
  nip::NipRun run(cfg);
  if (prefix) run.restore_before_print_switch(*prefix);
  auto progress = run_progress(o, fmt::format("line at {:g} V (seed {}):", voltage, seed % 100000), run.sim().time(), t_end);
  run.advance_to(t_end, [&] { progress.update(run.sim().time(), run.sim().step_count()); });
  const double t = run.sim().time();
  return {run.removed(nip::Exit::developed), run.coverage(0.25 * cfg.size.d50), t, v * t - ride};
}

std::optional<std::string> print_prefix(const ExperimentOptions& o, const nip::NipConfig& base, const PrintOptions& p, std::uint64_t seed) {
  nip::NipRun run(print_config(base, p, 1.0, seed));
  const double dt = run.time_step().dt;
  const double t_stop = run.first_print_switch_time() - 2.0 * dt;
  if (!(t_stop > run.config().insert_interval * dt) || !std::isfinite(t_stop)) return std::nullopt;
  auto progress = run_progress(o, fmt::format("common start before the line (seed {}):", seed % 100000), 0.0, t_stop);
  run.advance_to(t_stop, [&] { progress.update(run.sim().time(), run.sim().step_count()); });
  return run.checkpoint();
}

}  // namespace nipdem::experiments
