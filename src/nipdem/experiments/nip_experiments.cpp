#include "nipdem/experiments/nip_experiments.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <sstream>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/analysis.hpp"
#include "nipdem/experiments/ensemble.hpp"
#include "nipdem/experiments/nip.hpp"
#include "nipdem/experiments/presets.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/plot.hpp"
#include "nipdem/io/toml_reader.hpp"
#include "nipdem/version.hpp"

namespace nipdem::experiments {

namespace fs = std::filesystem;
using nlohmann::json;

NipConfig experiment_config(const ExperimentOptions& o, const std::vector<std::string>& point_sets) {
  std::vector<std::string> sets = o.sets;
  sets.insert(sets.end(), point_sets.begin(), point_sets.end());
  if (!o.config.empty()) return load_nip_config(o.config, sets);
  return parse_nip_config(preset_text(o.preset), "preset:" + o.preset, sets);
}

void reject_fixed_sets(const ExperimentOptions& o, const std::string& experiment, const std::vector<std::string>& fixed,
                       const std::map<std::string, std::string>& use_instead, bool note_config) {
  auto key_of = [](const std::string& a) { return a.substr(0, a.find('=')); };
  for (const auto& f : fixed) {
    const std::string key = key_of(f);
    for (const auto& u : o.sets) {
      if (key_of(u) != key) continue;
      const auto hint = use_instead.find(key);
      throw_input("experiment " + experiment, "--set " + key, u.substr(std::min(u.size(), key.size() + 1)),
                  "this experiment sets the key itself (" + (f.substr(key.size()) == "=*" ? key + ", a new value for every run" : f) +
                      ") and would replace the value",
                  hint != use_instead.end() ? "use " + hint->second + " instead" : "leave it out");
    }
  }
  // A key the user could set with an option is replaced in the configuration file too: say so
  // (once per experiment), not silently. Keys that define the experiment (the reduction's
  // 4 mm gap, no inflow, no VTK) are replaced without a note.
  if (!note_config) return;
  try {
    const std::string text = o.config.empty() ? preset_text(o.preset) : io::read_file(o.config);
    const toml::table root = io::parse_toml(text, o.config.empty() ? "preset:" + o.preset : o.config);
    for (const auto& f : fixed) {
      const std::string key = key_of(f);
      if (f.substr(key.size()) == "=*" || !use_instead.count(key)) continue;  // varies per run, or defines the experiment
      const toml::node_view<const toml::node> have = root.at_path(key);
      if (!have) continue;
      const toml::table want = io::parse_toml("v = " + f.substr(key.size() + 1), "--set");
      const auto a = have.value<double>(), b = want["v"].value<double>();
      std::ostringstream sa, sb;
      sa << have;
      sb << want["v"];
      if ((a && b) ? *a == *b : sa.str() == sb.str()) continue;
      std::fprintf(stderr, "nipdem: note: experiment %s sets %s (%s); the configuration's %s = %s is not used\n", experiment.c_str(), f.c_str(),
                   use_instead.at(key).c_str(), key.c_str(), a ? fmt::format("{:g}", *a).c_str() : sa.str().c_str());
    }
  } catch (const InputError&) {
    // an unreadable configuration is reported by experiment_config with its own message
  }
}

namespace {
std::string num(double v) { return fmt::format("{:.10g}", v); }

ensemble::Options ens(const ExperimentOptions& o, std::size_t count, const std::string& sub) {
  ensemble::Options e;
  e.count = count;
  e.seed = o.seed;
  e.jobs = o.jobs;
  e.mpi = o.mpi;
  e.resume = o.resume;
  e.dir = o.out / sub;
  if (o.progress)
    e.progress = [sub](std::size_t done, std::size_t total) { std::fprintf(stderr, "%s: %zu/%zu done\n", sub.c_str(), done, total); };
  return e;
}

// Progress inside one long run of an ensemble (a 100 ms reduction run takes hours): a line on
// stderr at most every `every_s` of wall time, "label: t = 12.0 / 100.0 ms (12 %), 140 s".
class Heartbeat {
 public:
  Heartbeat(bool on, std::string label, double t_end, double every_s = 60.0)
      : on_(on), label_(std::move(label)), t_end_(t_end), every_(every_s), start_(std::chrono::steady_clock::now()), last_(start_) {}
  void operator()(double t) {
    if (!on_) return;
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - last_).count() < every_) return;
    last_ = now;
    std::fprintf(stderr, "%s: t = %.4g / %.4g ms (%.0f %%), %.0f s\n", label_.c_str(), t * 1e3, t_end_ * 1e3, 100.0 * t / t_end_,
                 std::chrono::duration<double>(now - start_).count());
  }

 private:
  bool on_;
  std::string label_;
  double t_end_, every_;
  std::chrono::steady_clock::time_point start_, last_;
};

json failures(const ensemble::Summary& s) {
  json f = json::array();
  for (const auto& r : s.records) if (!r.ok) f.push_back({{"index", r.index}, {"seed", r.seed}, {"error", r.error}});
  return f;
}

// A steady front whose window takes in more than twice what it lets out is flagged "filling":
// the assembly is still growing and the front may drift later (docs/analysis.md, "Filling").
constexpr double kFillingBelow = 0.5;

json meta(const ExperimentOptions& o) {
  return {{"git_hash", kGitHash}, {"preset", o.config.empty() ? o.preset : ""}, {"config", o.config}, {"set", o.sets},
          {"seed", o.seed}, {"jobs", o.jobs}, {"mpi", o.mpi}};
}
}  // namespace

// ---------------------------------------------------------------- front position (§5.1)
json front_position(const ExperimentOptions& o, const FrontPositionOptions& f) {
  if (f.gaps_m.empty()) throw_input("experiment front-position", "--gap", "", "need at least one gap");
  for (double g : f.gaps_m) require_range("experiment front-position", "--gap", g, 20e-6, 5e-3);
  for (double v : f.sleeve_speeds_m_per_min) require_range("experiment front-position", "--sleeve-speed", v, 0.0, 1000.0);
  require_range("experiment front-position", "--min-time", f.min_time_s, 0.0, 10.0);
  require_range("experiment front-position", "--max-time", f.max_time_s, 1e-6, 10.0);
  if (!(f.max_time_s >= f.min_time_s)) throw_input("experiment front-position", "--max-time", num(f.max_time_s), "must not be below --min-time", fmt::format("[{:g}, inf)", f.min_time_s));
  std::vector<std::pair<double, double>> points;  // (gap, speed m/s; <0 = preset)
  const std::vector<double> speeds = f.sleeve_speeds_m_per_min.empty() ? std::vector<double>{-1.0} : f.sleeve_speeds_m_per_min;
  for (double v : speeds) for (double g : f.gaps_m) points.emplace_back(g, v < 0 ? -1.0 : v / 60.0);
  // Validate every point's configuration before running anything.
  auto point_sets = [&](std::size_t i) {
    std::vector<std::string> s = {"geometry.gap_m=" + num(points[i].first), "output.vtk=false"};
    if (points[i].second >= 0) s.push_back("geometry.roller_surface_speed_m_per_s=" + num(points[i].second));
    return s;
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    auto fixed = point_sets(i);
    fixed.push_back("run.seed=*");
    reject_fixed_sets(o, "front-position", fixed,
                      {{"geometry.gap_m", "--gap"}, {"geometry.roller_surface_speed_m_per_s", "--sleeve-speed"}, {"run.seed", "--seed"}}, i == 0);
    experiment_config(o, point_sets(i));
  }
  auto task = [&](std::size_t i, std::uint64_t seed) {
    auto sets = point_sets(i);
    sets.push_back("run.seed=" + std::to_string(seed % (1ULL << 62)));
    NipRun run(experiment_config(o, sets));
    std::vector<double> t, front, back;
    std::vector<std::int64_t> cum_in, cum_out;  // particles in / out of the window so far
    analysis::SteadyState st;
    analysis::ExtentOptions eo{analysis::FrontAt::min_x, 3, 0.02};  // ignore a few stray particles
    const double h = 0.5 * run.config().gap;
    Heartbeat beat(o.progress, fmt::format("front_position[{}] gap {:g} um", i, points[i].first * 1e6), f.max_time_s);
    while (run.sim().time() < f.max_time_s) {
      run.advance_to(run.sim().time() + f.sample_interval_s);
      beat(run.sim().time());
      const auto xs = run.assembly_x(h, run.config().roller_pits_filled ? 0.5 * run.config().size.d50 : -1.0);
      if (xs.size() < 8) continue;  // no assembly (yet)
      const auto e = analysis::assembly_extent(run.sim().time(), xs, eo);
      t.push_back(e.t); front.push_back(e.front); back.push_back(e.back);
      cum_in.push_back(run.inserted());
      cum_out.push_back(run.removed(Exit::developed) + run.removed(Exit::returned) + run.removed(Exit::lost));
      if (run.sim().time() >= f.min_time_s && t.size() >= 40 && t.size() % 10 == 0) {
        st = analysis::detect_steady_state(t, front);
        if (st.steady) break;
      }
    }
    if (t.size() >= 40) st = analysis::detect_steady_state(t, front);
    json series = json::array();
    for (std::size_t k = 0; k < t.size(); ++k) series.push_back({t[k], front[k], back[k], cum_in[k], cum_out[k]});
    json res{{"gap_m", points[i].first}, {"sleeve_speed_m_per_s", run.config().roller_speed},
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
  };
  const auto sum = ensemble::run(task, ens(o, points.size(), "front_position"));
  if (!sum.is_root) return {};
  json rows = json::array();
  std::string csv = "gap_m,sleeve_speed_m_per_s,front_m,front_std_m,steady,outflow_over_inflow_steady\n";
  std::map<double, io::Series> by_speed;
  int n_filling = 0;
  for (const auto& r : sum.records) {
    if (!r.ok) continue;
    json row = r.result;
    const auto ratio = row.value("outflow_over_inflow_steady", json(nullptr));
    csv += fmt::format("{:.6g},{:.6g},{:.6g},{:.6g},{},{}\n", row["gap_m"].get<double>(), row["sleeve_speed_m_per_s"].get<double>(),
                       row["front_m"].get<double>(), row["front_std_m"].get<double>(), row["steady"].get<bool>() ? 1 : 0,
                       ratio.is_number() ? fmt::format("{:.3g}", ratio.get<double>()) : std::string("nan"));
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
  io::write_file_atomic(o.out / "front_position.csv", csv);
  io::PlotSpec plot;
  plot.title = "Clean-state front position (thesis §5.1)";
  plot.x_label = "gap w_h [µm]";
  plot.y_label = "front position x [µm] (magnet edge = 0)";
  for (auto& [v, s] : by_speed) plot.series.push_back(s);
  if (!plot.series.empty() && !plot.series[0].x.empty()) io::write_plot_png(o.out / "front_position.png", plot);
  return {{"experiment", "front-position"}, {"points", rows}, {"failed", failures(sum)}, {"n_failed", sum.n_failed},
          {"n_filling", n_filling},
          {"csv", (o.out / "front_position.csv").string()}, {"plot", (o.out / "front_position.png").string()}, {"meta", meta(o)}};
}

// ---------------------------------------------------------------- reduction (§4.6)
json reduction(const ExperimentOptions& o, const ReductionOptions& r) {
  if (r.cohesion_ratios.empty()) throw_input("experiment reduction", "--r", "", "need at least one cohesion ratio");
  for (double v : r.cohesion_ratios) require_range("experiment reduction", "--r", v, 0.0, 1e6);
  require_range("experiment reduction", "--time", r.time_s, 1e-6, 10.0);
  require_range("experiment reduction", "--pile-width", r.pile_width_m, 10e-6, 2.0 * r.window_half_width_m);
  require_range("experiment reduction", "--pile-height", r.pile_height_m, 10e-6, 4e-3);
  if (r.pits != "empty" && r.pits != "filled" && r.pits != "preset")
    throw_input("experiment reduction", "--pits", r.pits, "allowed: empty, filled, preset");
  auto point_sets = [&](std::size_t i) {
    const double w = r.window_half_width_m;
    std::vector<std::string> s{"adhesion.cohesion_ratio=" + num(r.cohesion_ratios[i]),
                                    "geometry.gap_m=4e-3",  // no DI-drum: it is far away
                                    "inflow.layer_thickness_m=0", "inflow.prefill=false", "output.vtk=false",
                                    "electric.enabled=false",
                                    "geometry.window_x_min_m=" + num(-w), "geometry.window_x_max_m=" + num(w)};
    if (r.pits != "preset") s.push_back("inflow.roller_pits=\"" + r.pits + "\"");
    return s;
  };
  for (std::size_t i = 0; i < r.cohesion_ratios.size(); ++i) {
    auto fixed = point_sets(i);
    fixed.push_back("run.seed=*");
    reject_fixed_sets(o, "reduction", fixed, {{"adhesion.cohesion_ratio", "--r"}, {"inflow.roller_pits", "--pits"}, {"run.seed", "--seed"}}, i == 0);
    experiment_config(o, point_sets(i));
  }
  auto task = [&](std::size_t i, std::uint64_t seed) {
    auto sets = point_sets(i);
    sets.push_back("run.seed=" + std::to_string(seed % (1ULL << 62)));
    NipRun run(experiment_config(o, sets));
    const int n0 = run.fill_on_roller(-0.5 * r.pile_width_m, 0.5 * r.pile_width_m, 0.0, r.pile_height_m, r.pile_area_fraction);
    std::vector<analysis::Extent> ext;
    // front: the supply-roller side; the 5 % outermost particles on each side are the stream
    // carried away in the roughness, not the assembly the thesis films (§4.6)
    analysis::ExtentOptions eo{analysis::FrontAt::max_x, 3, 0.05};
    const double half_dt = 0.5 * run.time_step().dt;  // time lands within dt/2 of a target
    Heartbeat beat(o.progress, fmt::format("reduction[{}] r = {:g}", i, r.cohesion_ratios[i]), r.time_s);
    while (run.sim().time() < r.time_s - half_dt) {
      run.advance_to(std::min(r.time_s, run.sim().time() + r.sample_interval_s));
      beat(run.sim().time());
      // the assembly above the land level: toner in filled pits is the sleeve's, not the pile's
      const auto xs = run.assembly_x(r.pile_height_m * 2.0, run.config().roller_pits_filled ? 0.5 * run.config().size.d50 : -1.0);
      if (xs.size() >= 8) ext.push_back(analysis::assembly_extent(run.sim().time(), xs, eo));
    }
    // removed from the assembly = what left the window minus what the sleeve brought in its
    // filled pits (those pass through; they are not the assembly's loss)
    const auto out = run.removed(Exit::returned) + run.removed(Exit::developed);
    json res{{"r", r.cohesion_ratios[i]}, {"initial_particles", n0}, {"removed", out - run.inserted_on_roller()},
             {"left_window", out}, {"brought_in_pits", run.inserted_on_roller()},
             {"lost", run.removed(Exit::lost)}, {"time_s", run.sim().time()}};
    if (ext.size() >= 3) {
      const auto rs = analysis::reduction_speed(ext);
      res["reduction_speed_m_per_s"] = rs.speed;
      res["reduction_speed_stderr_m_per_s"] = rs.speed_stderr;
    }
    json series = json::array();
    for (const auto& e : ext) series.push_back({e.t, e.front, e.back, e.size, e.n});
    res["series_t_front_back_size_n"] = series;
    return res;
  };
  const auto sum = ensemble::run(task, ens(o, r.cohesion_ratios.size(), "reduction"));
  if (!sum.is_root) return {};
  json rows = json::array();
  std::string csv = "r,removed,time_s,removed_per_100ms,reduction_speed_m_per_s,reduction_speed_stderr_m_per_s\n";
  io::Series s;
  s.label = "particles removed in the observation time";
  s.markers = true;
  s.line = false;  // one stochastic run per r: points, not a curve through them
  for (const auto& rec : sum.records) {
    if (!rec.ok) continue;
    json row = rec.result;
    const double T = row["time_s"].get<double>();
    row["removed_per_100ms"] = row["removed"].get<double>() * 0.1 / T;
    csv += fmt::format("{:.6g},{},{:.6g},{:.6g},{:.6g},{:.6g}\n", row["r"].get<double>(), row["removed"].get<long>(), T,
                       row["removed_per_100ms"].get<double>(), row.value("reduction_speed_m_per_s", NAN),
                       row.value("reduction_speed_stderr_m_per_s", NAN));
    s.x.push_back(row["r"].get<double>());
    s.y.push_back(std::max(row["removed"].get<double>(), 0.5));
    // time series of each point as its own CSV; an r given more than once (seeds) adds the index
    const double rv = row["r"].get<double>();
    const bool repeated = std::count(r.cohesion_ratios.begin(), r.cohesion_ratios.end(), rv) > 1;
    const std::string series_file = repeated ? fmt::format("reduction_r{:g}_i{}.csv", rv, rec.index) : fmt::format("reduction_r{:g}.csv", rv);
    row["index"] = rec.index;
    row["seed"] = rec.seed;
    row["series_csv"] = (o.out / series_file).string();
    std::string ts = "time_s,front_m,back_m,size_m,particles\n";
    for (auto& e : row["series_t_front_back_size_n"]) ts += fmt::format("{:.6g},{:.6g},{:.6g},{:.6g},{}\n", e[0].get<double>(), e[1].get<double>(), e[2].get<double>(), e[3].get<double>(), e[4].get<long>());
    io::write_file_atomic(o.out / series_file, ts);
    row.erase("series_t_front_back_size_n");
    rows.push_back(row);
  }
  io::write_file_atomic(o.out / "reduction.csv", csv);
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
  return {{"experiment", "reduction"}, {"pits", r.pits}, {"points", rows},
          {"pile_width_m", r.pile_width_m}, {"pile_height_m", r.pile_height_m}, {"pile_area_fraction", r.pile_area_fraction}, {"failed", failures(sum)}, {"n_failed", sum.n_failed},
          {"table_4_3_reduction_speed_m_per_s", {{"black", 7.6e-4}, {"color", 2.5e-4}}},
          {"csv", (o.out / "reduction.csv").string()}, {"meta", meta(o)}};
}

// ---------------------------------------------------------------- printing (§5.2, §5.3)
namespace {
struct PrintRun { long printed; std::vector<NipRun::CoverageBin> coverage; double time; double s_observed_m; };

const std::map<std::string, std::string> kPrintHints = {
    {"print.voltage_V", "--v0 and --step"}, {"print.start_m", "--line-start"}, {"print.length_m", "--line-length"}, {"run.seed", "--seed"}};

std::vector<std::string> print_sets(const PrintOptions& p, double voltage, std::uint64_t seed) {
  return {"electric.enabled=true", "print.pattern=\"line\"", "print.voltage_V=" + num(voltage),
          "print.start_m=" + num(p.line_start_m), "print.length_m=" + num(p.line_length_m),
          "output.vtk=false", "run.seed=" + std::to_string(seed % (1ULL << 62))};
}

// Prints one line; runs until the drum up to `tail_m` beyond the line's end has left the window
// (+ extra_time_s). s_observed_m: the drum coordinate up to which the drum has left the window.
// `prefix`: a checkpoint from print_prefix() for the same seed, taken before the track switches
// on; the run starts from it instead of from t = 0 (identical result, less work).
PrintRun print_line(const ExperimentOptions& o, const PrintOptions& p, double voltage, std::uint64_t seed, double tail_m = 0.0,
                    const std::string* prefix = nullptr) {
  NipConfig cfg = experiment_config(o, print_sets(p, voltage, seed));
  // run until the drum up to line end + tail_m has passed the window's downstream edge
  const double v = std::fabs(cfg.drum_speed);
  const double ride = cfg.nip_x - cfg.x_min;  // nip to the window's downstream edge along the drum
  const double t_end = (p.line_start_m + p.line_length_m + tail_m + ride) / v + p.extra_time_s;
  NipRun run(cfg);
  if (prefix) run.restore_before_print_switch(*prefix);
  Heartbeat beat(o.progress, fmt::format("line at {:g} V (seed {})", voltage, seed % 100000), t_end);
  run.advance_to(t_end, [&] { beat(run.sim().time()); });
  const double t = run.sim().time();
  return {run.removed(Exit::developed), run.coverage(0.25 * cfg.size.d50), t, v * t - ride};
}

// The part of a print run before the drum track first switches on: the same for every voltage
// of one seed (the track is at its off voltage until then), so a Vo-level scan simulates it once.
// Stops two time steps before the switch; returns the checkpoint there (nothing if the track
// switches on within the first insert interval: then there is nothing worth sharing).
std::optional<std::string> print_prefix(const ExperimentOptions& o, const PrintOptions& p, std::uint64_t seed) {
  NipRun run(experiment_config(o, print_sets(p, 1.0, seed)));
  const double dt = run.time_step().dt;
  const double t_stop = run.first_print_switch_time() - 2.0 * dt;
  if (!(t_stop > run.config().insert_interval * dt) || !std::isfinite(t_stop)) return std::nullopt;
  Heartbeat beat(o.progress, fmt::format("common start before the line (seed {})", seed % 100000), t_stop);
  run.advance_to(t_stop, [&] { beat(run.sim().time()); });
  return run.checkpoint();
}
}  // namespace

namespace {
// The printed line's options, checked before any run (a NaN would print nothing and "succeed").
void check_print_options(const std::string& where, const PrintOptions& p) {
  require_range(where, "--line-length (print.length_m)", p.line_length_m, 1e-6, 1.0);
  require_range(where, "--line-start (print.start_m)", p.line_start_m, -1.0, 1.0);
  require_range(where, "--extra-time", p.extra_time_s, 0.0, 1.0);
}
}  // namespace

json vo_level(const ExperimentOptions& o, const VoOptions& v) {
  require_range("experiment vo-level", "--step", v.step_V, 1e-3, 100.0);
  if (v.seeds < 1 || v.seeds > 100000) throw_input("experiment vo-level", "--seeds", std::to_string(v.seeds), "out of range", "[1, 100000]");
  check_print_options("experiment vo-level", v.print);
  // the search options are checked once here (exit 2), not in every seed's task
  analysis::find_vo_level([](double) { return 1L; }, {.v0_V = v.v0_V, .step_V = v.step_V, .v_max_V = v.v_max_V, .coarse_step_V = v.coarse_step_V});
  // reject a bad configuration or line before any run starts (exit 2, not failed points)
  auto fixed = print_sets(v.print, 0.0, 0);
  for (auto& f : fixed)
    if (f.rfind("print.voltage_V=", 0) == 0 || f.rfind("run.seed=", 0) == 0) f = f.substr(0, f.find('=')) + "=*";
  reject_fixed_sets(o, "vo-level", fixed, kPrintHints);
  experiment_config(o, {"electric.enabled=true", "print.pattern=\"line\"", "print.voltage_V=1", "print.start_m=" + num(v.print.line_start_m),
                        "print.length_m=" + num(v.print.line_length_m)});
  auto task = [&](std::size_t, std::uint64_t seed) {
    const auto prefix = print_prefix(o, v.print, seed);
    const auto res = analysis::find_vo_level([&](double V) { return print_line(o, v.print, V, seed, 0.0, prefix ? &*prefix : nullptr).printed; },
                                             {.v0_V = v.v0_V, .step_V = v.step_V, .v_max_V = v.v_max_V, .coarse_step_V = v.coarse_step_V});
    json trace = json::array();
    for (auto& [V, n] : res.trace) trace.push_back({V, n});
    return json{{"found", res.found}, {"vo_V", res.vo_V}, {"trace_V_printed", trace}};
  };
  const auto sum = ensemble::run(task, ens(o, static_cast<std::size_t>(v.seeds), "vo_level"));
  if (!sum.is_root) return {};
  std::vector<double> vo;
  json per = json::array();
  for (const auto& r : sum.records) {
    if (!r.ok) continue;
    per.push_back(r.result);
    if (r.result["found"].get<bool>()) vo.push_back(r.result["vo_V"].get<double>());
  }
  double mean = 0, sd = 0;
  for (double x : vo) mean += x;
  if (!vo.empty()) mean /= vo.size();
  for (double x : vo) sd += (x - mean) * (x - mean);
  if (vo.size() > 1) sd = std::sqrt(sd / (vo.size() - 1));
  return {{"experiment", "vo-level"}, {"step_V", v.step_V}, {"coarse_step_V", v.coarse_step_V}, {"vo_mean_V", vo.empty() ? json(nullptr) : json(mean)}, {"vo_std_V", sd},
          {"seeds_found", vo.size()}, {"seeds_total", v.seeds}, {"per_seed", per}, {"failed", failures(sum)},
          {"n_failed", sum.n_failed}, {"meta", meta(o)}};
}

json edge_sharpness(const ExperimentOptions& o, const EdgeOptions& e) {
  if (e.realizations < 2 || e.realizations > 100000)
    throw_input("experiment edge-sharpness", "--realizations", std::to_string(e.realizations), "out of range", "[2, 100000]");
  if (e.bootstrap < 0 || e.bootstrap > 1000000)
    throw_input("experiment edge-sharpness", "--bootstrap", std::to_string(e.bootstrap), "out of range", "[0, 1000000]");
  check_print_options("experiment edge-sharpness", e.print);
  // The line is printed at the configuration's print.voltage_V (default 40 V, §5.3).
  std::vector<std::string> fixed;
  for (const auto& f : print_sets(e.print, 0.0, 0))
    if (f.rfind("print.voltage_V=", 0) != 0) fixed.push_back(f.rfind("run.seed=", 0) == 0 ? "run.seed=*" : f);
  reject_fixed_sets(o, "edge-sharpness", fixed, kPrintHints);
  const NipConfig base = experiment_config(o, {"electric.enabled=true", "print.pattern=\"line\"",
                                                "print.start_m=" + num(e.print.line_start_m), "print.length_m=" + num(e.print.line_length_m)});
  require_range("experiment edge-sharpness", "--margin", e.margin_m, 20e-6, 5e-3);
  const double volts = base.electric.pattern.segments().empty() ? 40.0 : base.electric.pattern.segments()[0].voltage_V;
  auto task = [&](std::size_t, std::uint64_t seed) {
    const auto pr = print_line(o, e.print, volts, seed, e.margin_m);
    json bins = json::array();
    for (const auto& b : pr.coverage) bins.push_back({b.s0, b.covered ? 1 : 0});
    return json{{"printed", pr.printed}, {"bins_s_covered", bins}, {"s_observed_m", pr.s_observed_m}};
  };
  const auto sum = ensemble::run(task, ens(o, static_cast<std::size_t>(e.realizations), "edge_sharpness"));
  if (!sum.is_root) return {};
  // Common grid over all realizations: bin width d50/4 from the line start - margin to end + margin.
  const double bin = 0.25 * base.size.d50;
  const double lo = e.print.line_start_m - e.margin_m, hi = e.print.line_start_m + e.print.line_length_m + e.margin_m;
  const int n = static_cast<int>(std::lround((hi - lo) / bin));
  std::vector<double> x(n);
  for (int k = 0; k < n; ++k) x[k] = lo + (k + 0.5) * bin;
  std::vector<std::vector<double>> curves;
  long printed_total = 0;
  for (const auto& r : sum.records) {
    if (!r.ok) continue;
    // Drum still inside the window at the run's end is unobserved, not uncovered: a realization
    // (e.g. resumed from a folder made with a shorter run) must have observed the whole grid.
    const double seen = r.result.contains("s_observed_m") ? r.result["s_observed_m"].get<double>() : -1.0;
    if (seen < hi - 0.5 * bin)
      throw_input((o.out / "edge_sharpness" / "realizations").string(), "realization " + std::to_string(r.index) + " s_observed_m",
                  r.result.contains("s_observed_m") ? num(seen) : "missing (made by an older nipdem)",
                  fmt::format("every line must have observed the drum up to the analysis range's end, line end + margin = {:.4g} m; use a new --out", hi));
    std::vector<double> c(n, 0.0);
    for (auto& b : r.result["bins_s_covered"]) {
      const int k = static_cast<int>(std::floor((b[0].get<double>() + 0.5 * bin - lo) / bin));
      if (k >= 0 && k < n && b[1].get<int>()) c[k] = 1.0;
    }
    printed_total += r.result["printed"].get<long>();
    curves.push_back(c);
  }
  // One row per line (failed ones too): enough to redo the analysis on another grid.
  std::string lines = "index,seed,ok,wall_s,printed,s_observed_um,covered_bin_starts_um\n";
  for (const auto& r : sum.records) {
    lines += fmt::format("{},{},{},{:.1f},", r.index, r.seed, r.ok ? 1 : 0, r.wall_s);
    if (!r.ok) { lines += ",,\n"; continue; }
    lines += fmt::format("{},{:.1f},", r.result["printed"].get<long>(), 1e6 * r.result["s_observed_m"].get<double>());
    std::string starts;
    for (auto& b : r.result["bins_s_covered"])
      if (b[1].get<int>()) starts += (starts.empty() ? "" : ";") + fmt::format("{:.3f}", 1e6 * b[0].get<double>());
    lines += starts + "\n";
  }
  io::write_file_atomic(o.out / "lines.csv", lines);
  json out = {{"experiment", "edge-sharpness"}, {"voltage_V", volts}, {"realizations", curves.size()}, {"printed_particles", printed_total},
              {"failed", failures(sum)}, {"n_failed", sum.n_failed}, {"lines_file", (o.out / "lines.csv").string()}, {"meta", meta(o)}};
  const auto avg = curves.empty() ? std::vector<double>(n, 0.0) : analysis::average_curve(curves);
  double peak = 0;
  for (double c : avg) peak = std::max(peak, c);
  if (peak <= 0.0) {
    out["error"] = "nothing was printed in any realization: no edge to fit (see docs/results)";
    out["edge_front_m"] = nullptr;
    out["edge_back_m"] = nullptr;
    return out;
  }
  // An edge that has not decayed at an end of the analysis range is cut by it (first / last d50).
  const auto ends = analysis::range_end_coverage(avg);
  out["coverage_at_range_start"] = ends.at_start;
  out["coverage_at_range_end"] = ends.at_end;
  for (const auto& w : ends.warnings) std::fprintf(stderr, "nipdem: warning: edge-sharpness: %s\n", w.c_str());
  out["warnings"] = ends.warnings;
  analysis::SigmoidOptions so;
  so.binomial_realizations = static_cast<int>(curves.size());
  // The drum carries the line towards -x; its front (printed first) is at low s.
  const auto boot = analysis::bootstrap_line_edges(x, curves, e.bootstrap, o.seed, 0.95, so, analysis::FrontSide::low_x);
  const auto fit = analysis::fit_line_edges(x, avg, so, analysis::FrontSide::low_x);
  json js = analysis::edge_sharpness_json(boot, curves.size());
  for (auto& [k, v] : js.items()) out[k] = v;
  analysis::write_coverage_csv(o.out / "coverage_average.csv", x, avg, fit);
  io::write_plot_png(o.out / "coverage_average.png", analysis::coverage_plot(x, avg, fit, "Average coverage of printed lines (fig. 1.8 analogue)",
                                                                              e.print.line_start_m, e.print.line_start_m + e.print.line_length_m));
  out["coverage_file"] = (o.out / "coverage_average.csv").string();
  return out;
}

}  // namespace nipdem::experiments
