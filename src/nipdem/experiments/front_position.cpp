#include "nipdem/experiments/front_position.hpp"

#include <cmath>
#include <cstdio>
#include <map>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/analysis/analysis.hpp"
#include "nipdem/nip/nip.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"

namespace nipdem::experiments {

using nlohmann::json;

namespace {
// A steady front whose window takes in more than twice what it lets out is flagged "filling":
// the assembly is still growing and the front may drift later (docs/analysis.md, "Filling").
constexpr double kFillingBelow = 0.5;

struct Point { double gap_m; double speed_m_per_s; };  // speed < 0: the configuration's

void check(const FrontPositionOptions& f) {
  if (f.gaps_m.empty()) throw_input("experiment front-position", "--gap", "", "need at least one gap");
  for (double g : f.gaps_m) require_range("experiment front-position", "--gap", g, 20e-6, 5e-3);
  for (double v : f.sleeve_speeds_m_per_min) require_range("experiment front-position", "--sleeve-speed", v, 0.0, 1000.0);
  require_range("experiment front-position", "--min-time", f.min_time_s, 0.0, 10.0);
  require_range("experiment front-position", "--max-time", f.max_time_s, 1e-6, 10.0);
  if (!(f.max_time_s >= f.min_time_s))
    throw_input("experiment front-position", "--max-time", fmt::format("{:.10g}", f.max_time_s), "must not be below --min-time",
                fmt::format("[{:g}, inf)", f.min_time_s));
}

std::vector<Point> points_of(const FrontPositionOptions& f) {
  std::vector<Point> points;
  const std::vector<double> speeds = f.sleeve_speeds_m_per_min.empty() ? std::vector<double>{-1.0} : f.sleeve_speeds_m_per_min;
  for (double v : speeds) for (double g : f.gaps_m) points.push_back({g, v < 0 ? -1.0 : v / 60.0});
  return points;
}

std::vector<FixedKey> fixed_keys(const Point& p) {
  std::vector<FixedKey> k = {{"geometry.gap_m", p.gap_m, "--gap"}, {"output.vtk", false, ""}};
  if (p.speed_m_per_s >= 0) k.push_back({"geometry.roller_surface_speed_m_per_s", p.speed_m_per_s, "--sleeve-speed"});
  k.push_back({"run.seed", std::monostate{}, "--seed"});
  return k;
}

nip::NipConfig point_config(const nip::NipConfig& base, const Point& p) {
  nip::NipConfig c = base;
  c.gap = p.gap_m;
  c.vtk = false;
  if (p.speed_m_per_s >= 0) c.roller_speed = p.speed_m_per_s;
  return c;
}

// One point: sample the assembly's extent until the front is steady or max_time.
json run_point(const ExperimentOptions& o, const FrontPositionOptions& f, const nip::NipConfig& base, std::size_t i, const Point& p,
               std::uint64_t seed) {
  nip::NipConfig cfg = point_config(base, p);
  cfg.seed = run_seed(seed);
  validate(cfg);
  nip::NipRun run(cfg);
  std::vector<double> t, front, back;
  std::vector<std::int64_t> cum_in, cum_out;  // particles in / out of the window so far
  analysis::SteadyState st;
  analysis::ExtentOptions eo{analysis::FrontAt::min_x, 3, 0.02};  // ignore a few stray particles
  const double h = 0.5 * run.config().gap;
  auto progress = run_progress(o, fmt::format("front_position[{}] gap {:g} um:", i, p.gap_m * 1e6), 0.0, f.max_time_s);
  while (run.sim().time() < f.max_time_s) {
    run.advance_to(run.sim().time() + f.sample_interval_s);
    progress.update(run.sim().time(), run.sim().step_count());
    const auto xs = run.assembly_x(h, run.config().roller_pits_filled ? 0.5 * run.config().size.d50 : -1.0);
    if (xs.size() < 8) continue;  // no assembly (yet)
    const auto e = analysis::assembly_extent(run.sim().time(), xs, eo);
    t.push_back(e.t); front.push_back(e.front); back.push_back(e.back);
    cum_in.push_back(run.inserted());
    cum_out.push_back(run.removed(nip::Exit::developed) + run.removed(nip::Exit::returned) + run.removed(nip::Exit::lost));
    if (run.sim().time() >= f.min_time_s && t.size() >= 40 && t.size() % 10 == 0) {
      st = analysis::detect_steady_state(t, front);
      if (st.steady) break;
    }
  }
  if (t.size() >= 40) st = analysis::detect_steady_state(t, front);
  json series = json::array();
  for (std::size_t k = 0; k < t.size(); ++k) series.push_back({t[k], front[k], back[k], cum_in[k], cum_out[k]});
  json res{{"gap_m", p.gap_m}, {"sleeve_speed_m_per_s", run.config().roller_speed},
           {"front_m", st.value}, {"front_std_m", st.std}, {"front_stderr_m", st.stderr_mean},
           {"steady", st.steady}, {"not_steady_reason", st.reason}, {"t_onset_s", st.t_onset},
           {"simulated_s", run.sim().time()}, {"particles_at_end", run.sim().bodies().x.size()},
           {"series_t_front_back_m_in_out", series}};
  // Is the window still filling over the steady part? (docs/analysis.md, "Filling")
  if (st.steady) {
    const auto fb = analysis::flow_balance(t, cum_in, cum_out, st.t_onset);
    res["inflow_steady"] = fb.inflow;
    res["outflow_steady"] = fb.outflow;
    res["outflow_over_inflow_steady"] = std::isfinite(fb.outflow_over_inflow) ? json(fb.outflow_over_inflow) : json(nullptr);
    res["filling"] = fb.inflow > 0 && fb.outflow_over_inflow < kFillingBelow;
  }
  return res;
}

// The points' CSV and plot, a warning per filling window; returns the JSON rows.
json report(const ExperimentOptions& o, const ensemble::Summary& sum, int& n_filling) {
  json rows = json::array();
  std::vector<std::vector<double>> csv;
  std::map<double, io::Series> by_speed;
  n_filling = 0;
  for (const auto& r : sum.records) {
    if (!r.ok) continue;
    json row = r.result;
    const auto ratio = row.value("outflow_over_inflow_steady", json(nullptr));
    csv.push_back({row["gap_m"].get<double>(), row["sleeve_speed_m_per_s"].get<double>(), row["front_m"].get<double>(),
                   row["front_std_m"].get<double>(), row["steady"].get<bool>() ? 1.0 : 0.0,
                   ratio.is_number() ? ratio.get<double>() : NAN});
    if (row.value("filling", false)) {
      ++n_filling;
      std::fprintf(stderr,
                   "nipdem: warning: front-position: gap %g um, %.3g m/min: the front is steady but the window is still filling "
                   "(outflow/inflow = %.2f over the steady part); the front may still drift: try a larger --min-time\n",
                   row["gap_m"].get<double>() * 1e6, row["sleeve_speed_m_per_s"].get<double>() * 60.0, ratio.get<double>());
    }
    const double v = row["sleeve_speed_m_per_s"].get<double>();
    auto& s = by_speed[v];
    s.label = fmt::format("sleeve speed {:.3g} m/min", v * 60);
    s.markers = true;
    s.line_only_if_resolved = true;  // a line only where consecutive fronts differ by more than their spread
    s.x.push_back(row["gap_m"].get<double>() * 1e6);
    s.y.push_back(row["front_m"].get<double>() * 1e6);
    s.y_err.push_back(row["front_std_m"].get<double>() * 1e6);
    row.erase("series_t_front_back_m_in_out");
    row.erase("series_t_front_back_m");  // realizations written before the in/out counts
    rows.push_back(row);
  }
  io::write_csv(o.out / "front_position.csv",
                {"gap_m", "sleeve_speed_m_per_s", "front_m", "front_std_m", "steady", "outflow_over_inflow_steady"}, csv,
                {"{:.6g}", "{:.6g}", "{:.6g}", "{:.6g}", "{:.0f}", "{:.3g}"});
  io::PlotSpec plot;
  plot.title = "Clean-state front position (thesis §5.1)";
  plot.x_label = "gap w_h [µm]";
  plot.y_label = "front position x [µm] (magnet edge = 0)";
  for (auto& [v, s] : by_speed) plot.series.push_back(s);
  if (!plot.series.empty() && !plot.series[0].x.empty()) io::write_plot_png(o.out / "front_position.png", plot);
  return rows;
}
}  // namespace

json front_position(const ExperimentOptions& o, const FrontPositionOptions& f) {
  check(f);
  const std::vector<Point> points = points_of(f);
  reject_fixed_sets(o, "front-position", fixed_keys(points[0]));
  const nip::NipConfig base = base_config(o);
  for (const auto& p : points) {  // every point's configuration is checked before anything runs
    nip::NipConfig c = point_config(base, p);
    validate(c);
  }
  const auto sum = ensemble::run([&](std::size_t i, std::uint64_t seed) { return run_point(o, f, base, i, points[i], seed); },
                                 ensemble_options(o, points.size(), "front_position"));
  if (!sum.is_root) return {};
  int n_filling = 0;
  json rows = report(o, sum, n_filling);
  return {{"experiment", "front-position"}, {"points", rows}, {"failed", failures(sum)}, {"n_failed", sum.n_failed},
          {"n_filling", n_filling},
          {"csv", (o.out / "front_position.csv").string()}, {"plot", (o.out / "front_position.png").string()}, {"meta", meta(o, &sum)}};
}

}  // namespace nipdem::experiments
