#include "nipdem/experiments/reduction.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/analysis/analysis.hpp"
#include "nipdem/nip/nip.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"

namespace nipdem::experiments {

using nlohmann::json;

namespace {
void check(const ReductionOptions& r) {
  if (r.cohesion_ratios.empty()) throw_input("experiment reduction", "--r", "", "need at least one cohesion ratio");
  for (double v : r.cohesion_ratios) require_range("experiment reduction", "--r", v, 0.0, 1e6);
  require_range("experiment reduction", "--time", r.time_s, 1e-6, 10.0);
  require_range("experiment reduction", "--pile-width", r.pile_width_m, 10e-6, 2.0 * r.window_half_width_m);
  require_range("experiment reduction", "--pile-height", r.pile_height_m, 10e-6, 4e-3);
  if (r.pits != "empty" && r.pits != "filled" && r.pits != "preset")
    throw_input("experiment reduction", "--pits", r.pits, "allowed: empty, filled, preset");
}

constexpr double kNoDrumGap_m = 4e-3;  // no DI-drum: it is far away

std::vector<FixedKey> fixed_keys(const ReductionOptions& r, double ratio) {
  const double w = r.window_half_width_m;
  std::vector<FixedKey> k = {{"adhesion.cohesion_ratio", ratio, "--r"}, {"geometry.gap_m", kNoDrumGap_m, "", "4e-3"},
                             {"inflow.layer_thickness_m", 0.0, ""},     {"inflow.prefill", false, ""},
                             {"output.vtk", false, ""},                 {"electric.enabled", false, ""},
                             {"geometry.window_x_min_m", -w, ""},       {"geometry.window_x_max_m", w, ""}};
  if (r.pits != "preset") k.push_back({"inflow.roller_pits", r.pits, "--pits"});
  k.push_back({"run.seed", std::monostate{}, "--seed"});
  return k;
}

nip::NipConfig point_config(const nip::NipConfig& base, const ReductionOptions& r, double ratio) {
  nip::NipConfig c = base;
  c.cohesion_ratio = ratio;
  c.gap = kNoDrumGap_m;
  c.layer_thickness = 0.0;
  c.prefill = false;
  c.vtk = false;
  c.electric.enabled = false;
  c.x_min = -r.window_half_width_m;
  c.x_max = r.window_half_width_m;
  if (r.pits != "preset") c.roller_pits_filled = r.pits == "filled";
  return c;
}

// One point: the pile on the roller, observed for time_s.
json run_point(const ExperimentOptions& o, const ReductionOptions& r, const nip::NipConfig& base, std::size_t i, std::uint64_t seed) {
  nip::NipConfig cfg = point_config(base, r, r.cohesion_ratios[i]);
  cfg.seed = run_seed(seed);
  validate(cfg);
  nip::NipRun run(cfg);
  const int n0 = run.fill_on_roller(-0.5 * r.pile_width_m, 0.5 * r.pile_width_m, 0.0, r.pile_height_m, r.pile_area_fraction);
  std::vector<analysis::Extent> ext;
  // front: the supply-roller side; the 5 % outermost particles on each side are the stream
  // carried away in the roughness, not the assembly the thesis films (§4.6)
  analysis::ExtentOptions eo{analysis::FrontAt::max_x, 3, 0.05};
  const double half_dt = 0.5 * run.time_step().dt;  // time lands within dt/2 of a target
  auto progress = run_progress(o, fmt::format("reduction[{}] r = {:g}:", i, r.cohesion_ratios[i]), 0.0, r.time_s);
  while (run.sim().time() < r.time_s - half_dt) {
    run.advance_to(std::min(r.time_s, run.sim().time() + r.sample_interval_s));
    progress.update(run.sim().time(), run.sim().step_count());
    // the assembly above the land level: toner in filled pits is the sleeve's, not the pile's
    const auto xs = run.assembly_x(r.pile_height_m * 2.0, run.config().roller_pits_filled ? 0.5 * run.config().size.d50 : -1.0);
    if (xs.size() >= 8) ext.push_back(analysis::assembly_extent(run.sim().time(), xs, eo));
  }
  // removed from the assembly = what left the window minus what the sleeve brought in its
  // filled pits (those pass through; they are not the assembly's loss)
  const auto out = run.removed(nip::Exit::returned) + run.removed(nip::Exit::developed);
  json res{{"r", r.cohesion_ratios[i]}, {"initial_particles", n0}, {"removed", out - run.inserted_on_roller()},
           {"left_window", out}, {"brought_in_pits", run.inserted_on_roller()},
           {"lost", run.removed(nip::Exit::lost)}, {"time_s", run.sim().time()}};
  if (ext.size() >= 3) {
    const auto rs = analysis::reduction_speed(ext);
    res["reduction_speed_m_per_s"] = rs.speed;
    res["reduction_speed_stderr_m_per_s"] = rs.speed_stderr;
  }
  json series = json::array();
  for (const auto& e : ext) series.push_back({e.t, e.front, e.back, e.size, e.n});
  res["series_t_front_back_size_n"] = series;
  return res;
}

// reduction.csv, a time-series CSV per point and the plot; returns the JSON rows.
json report(const ExperimentOptions& o, const ReductionOptions& r, const ensemble::Summary& sum) {
  json rows = json::array();
  std::vector<std::vector<double>> csv;
  io::Series s;
  s.label = "particles removed in the observation time";
  s.markers = true;
  s.line = false;  // one stochastic run per r: points, not a curve through them
  for (const auto& rec : sum.records) {
    if (!rec.ok) continue;
    json row = rec.result;
    const double T = row["time_s"].get<double>();
    row["removed_per_100ms"] = row["removed"].get<double>() * 0.1 / T;
    csv.push_back({row["r"].get<double>(), row["removed"].get<double>(), T, row["removed_per_100ms"].get<double>(),
                   row.value("reduction_speed_m_per_s", NAN), row.value("reduction_speed_stderr_m_per_s", NAN)});
    s.x.push_back(row["r"].get<double>());
    s.y.push_back(std::max(row["removed"].get<double>(), 0.5));
    // time series of each point as its own CSV; an r given more than once (seeds) adds the index
    const double rv = row["r"].get<double>();
    const bool repeated = std::count(r.cohesion_ratios.begin(), r.cohesion_ratios.end(), rv) > 1;
    const std::string series_file = repeated ? fmt::format("reduction_r{:g}_i{}.csv", rv, rec.index) : fmt::format("reduction_r{:g}.csv", rv);
    row["index"] = rec.index;
    row["seed"] = rec.seed;
    row["series_csv"] = (o.out / series_file).string();
    std::vector<std::vector<double>> ts;
    for (auto& e : row["series_t_front_back_size_n"])
      ts.push_back({e[0].get<double>(), e[1].get<double>(), e[2].get<double>(), e[3].get<double>(), e[4].get<double>()});
    io::write_csv(o.out / series_file, {"time_s", "front_m", "back_m", "size_m", "particles"}, ts,
                  {"{:.6g}", "{:.6g}", "{:.6g}", "{:.6g}", "{:.0f}"});
    row.erase("series_t_front_back_size_n");
    rows.push_back(row);
  }
  io::write_csv(o.out / "reduction.csv",
                {"r", "removed", "time_s", "removed_per_100ms", "reduction_speed_m_per_s", "reduction_speed_stderr_m_per_s"}, csv,
                {"{:.6g}", "{:.0f}", "{:.6g}", "{:.6g}", "{:.6g}", "{:.6g}"});
  if (!s.x.empty()) {
    io::PlotSpec p;
    p.title = "Reduction experiment (thesis §4.6, fig. 4.25 analogue)";
    p.x_label = "r = F_coh / F_adh";
    p.y_label = "particles removed";
    p.log_x = s.x.size() > 1 && s.x.front() > 0;
    p.log_y = true;
    p.series.push_back(s);
    io::write_plot_png(o.out / "reduction.png", p);
  }
  return rows;
}
}  // namespace

json reduction(const ExperimentOptions& o, const ReductionOptions& r) {
  check(r);
  reject_fixed_sets(o, "reduction", fixed_keys(r, r.cohesion_ratios[0]));
  const nip::NipConfig base = base_config(o);
  for (double ratio : r.cohesion_ratios) {  // every point's configuration is checked before anything runs
    nip::NipConfig c = point_config(base, r, ratio);
    validate(c);
  }
  const auto sum = ensemble::run([&](std::size_t i, std::uint64_t seed) { return run_point(o, r, base, i, seed); },
                                 ensemble_options(o, r.cohesion_ratios.size(), "reduction"));
  if (!sum.is_root) return {};
  json rows = report(o, r, sum);
  return {{"experiment", "reduction"}, {"pits", r.pits}, {"points", rows},
          {"pile_width_m", r.pile_width_m}, {"pile_height_m", r.pile_height_m}, {"pile_area_fraction", r.pile_area_fraction}, {"failed", failures(sum)}, {"n_failed", sum.n_failed},
          {"table_4_3_reduction_speed_m_per_s", {{"black", 7.6e-4}, {"color", 2.5e-4}}},
          {"csv", (o.out / "reduction.csv").string()}, {"meta", meta(o, &sum)}};
}

}  // namespace nipdem::experiments
