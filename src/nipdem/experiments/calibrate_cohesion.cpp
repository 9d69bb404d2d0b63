#include "nipdem/experiments/calibrate_cohesion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"
#include "nipdem/version.hpp"

namespace nipdem::calibrate {

using nlohmann::json;
namespace {
const char* kWhere = "calibrate cohesion";
}

CohesionFit fit_cohesion_ratio(std::vector<SpeedPoint> pts, double target) {
  if (pts.size() < 2) throw_input(kWhere, "points", std::to_string(pts.size()), "need at least two reduction speeds");
  if (!std::isfinite(target)) throw_input(kWhere, "--target-speed", "non-finite", "must be a finite speed [m/s]");
  for (const auto& p : pts) {
    if (!(p.r > 0.0) || !std::isfinite(p.r)) throw_input(kWhere, "r", fmt::format("{:g}", p.r), "r must be > 0 (the fit is in ln r)");
    if (!std::isfinite(p.speed)) throw_input(kWhere, "reduction_speed_m_per_s", fmt::format("{:g} at r = {:g}", p.speed, p.r), "must be finite");
  }
  std::sort(pts.begin(), pts.end(), [](const SpeedPoint& a, const SpeedPoint& b) { return a.r < b.r; });
  CohesionFit f;
  const double trend = pts.back().speed - pts.front().speed;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double d = pts[i + 1].speed - pts[i].speed;
    const double se = std::hypot(pts[i].stderr_, pts[i + 1].stderr_);
    if (d * trend < 0.0 && std::abs(d) > 2.0 * se) ++f.against_trend;
  }
  std::size_t first = pts.size();
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double a = pts[i].speed - target, b = pts[i + 1].speed - target;
    if ((a <= 0.0 && b >= 0.0) || (a >= 0.0 && b <= 0.0)) {
      ++f.crossings;
      if (first == pts.size()) first = i;
    }
  }
  if (first == pts.size()) {
    const bool all_above = pts.front().speed > target;
    // decreasing v(r) expected (fig. 4.25): above target everywhere -> more cohesion needed
    const bool falls = pts.back().speed < pts.front().speed;
    f.hint = all_above ? (falls ? "every speed is above the target: raise --r-max" : "every speed is above the target and v does not fall with r")
                       : (falls ? "every speed is below the target: lower --r-min" : "every speed is below the target and v does not fall with r");
    return f;
  }
  const SpeedPoint& lo = pts[first];
  const SpeedPoint& hi = pts[first + 1];
  f.bracketed = true;
  f.r_lo = lo.r;
  f.r_hi = hi.r;
  const double u0 = std::log(lo.r), u1 = std::log(hi.r);
  const double dv = hi.speed - lo.speed;
  const double slope = dv / (u1 - u0);  // dv / d ln r
  const double u = dv == 0.0 ? 0.5 * (u0 + u1) : u0 + (target - lo.speed) / slope;
  f.r_fit = std::exp(u);
  const double sigma = std::max(lo.stderr_, hi.stderr_);
  if (slope != 0.0 && sigma > 0.0) {
    const double du = sigma / std::abs(slope);
    f.r_1sigma_lo = std::exp(u - du);
    f.r_1sigma_hi = std::exp(u + du);
  } else {
    f.r_1sigma_lo = lo.r;
    f.r_1sigma_hi = hi.r;
  }
  return f;
}

std::vector<double> interior_log_points(double lo, double hi, std::size_t n) {
  if (!(lo > 0.0) || !(hi > lo)) throw_input(kWhere, "bracket", fmt::format("[{:g}, {:g}]", lo, hi), "need 0 < lo < hi");
  std::vector<double> r;
  const double a = std::log(lo), b = std::log(hi);
  for (std::size_t k = 1; k <= n; ++k) r.push_back(std::exp(a + (b - a) * double(k) / double(n + 1)));
  return r;
}

namespace {
void check_options(const experiments::ExperimentOptions* o, const CohesionOptions& c) {
  // |v| > 10 m/s would be 20x the fastest sleeve: not a reduction speed (negative: the assembly grows)
  require_range(kWhere, "--target-speed", c.target_speed_m_per_s, -10.0, 10.0);
  require_range(kWhere, "--r-min", c.r_min, 1e-6, 1e6);
  require_range(kWhere, "--r-max", c.r_max, 1e-6, 1e6);
  if (!(c.r_max > c.r_min)) throw_input(kWhere, "--r-max", fmt::format("{:g}", c.r_max), fmt::format("must be above --r-min ({:g})", c.r_min));
  if (c.points < 2 || c.points > 64) throw_input(kWhere, "--points", std::to_string(c.points), "allowed 2 .. 64");
  if (c.rounds < 1 || c.rounds > 20) throw_input(kWhere, "--rounds", std::to_string(c.rounds), "allowed 1 .. 20");
  if (o && o->mpi) throw_input(kWhere, "--mpi", "", "not supported: each round needs the previous round's bracket; use --jobs");
}
}  // namespace

CohesionSearch search_cohesion_ratio(const SpeedEvaluator& evaluate, const CohesionOptions& c) {
  check_options(nullptr, c);
  CohesionSearch out;
  std::vector<double> rs;
  {  // round 0: log-spaced over [r_min, r_max], both ends included
    const double a = std::log(c.r_min), b = std::log(c.r_max);
    for (std::size_t k = 0; k < c.points; ++k) rs.push_back(std::exp(a + (b - a) * double(k) / double(c.points - 1)));
    rs.front() = c.r_min;  // the ends exactly as given (exp(log(x)) may differ in the last bit)
    rs.back() = c.r_max;
  }
  for (std::size_t k = 0; k < c.rounds; ++k) {
    out.rounds_r.push_back(rs);
    for (const auto& p : evaluate(k, rs)) out.points.push_back(p);
    if (out.points.size() < 2) break;
    out.fit = fit_cohesion_ratio(out.points, c.target_speed_m_per_s);
    if (!out.fit.bracketed || k + 1 == c.rounds) break;
    rs = interior_log_points(out.fit.r_lo, out.fit.r_hi, c.points);
  }
  std::sort(out.points.begin(), out.points.end(), [](const SpeedPoint& a, const SpeedPoint& b) { return a.r < b.r; });
  return out;
}

CountFit fit_cohesion_from_counts(const std::vector<CountPoint>& points, const CountTarget& t) {
  for (const auto& p : points) {
    if (!std::isfinite(p.r) || p.r < 0.0) throw_input(kWhere, "r", fmt::format("{:g}", p.r), "must be finite and >= 0");
    if (!std::isfinite(p.removed)) throw_input(kWhere, "removed", fmt::format("{:g} at r = {:g}", p.removed, p.r), "must be finite");
    if (!std::isfinite(p.initial) || p.initial <= 0.0) throw_input(kWhere, "initial_particles", fmt::format("{:g} at r = {:g}", p.initial, p.r), "must be > 0");
  }
  require_range(kWhere, "--target-speed", t.speed, 0.0, 10.0);
  require_range(kWhere, "--target-range (low)", t.speed_lo, 0.0, t.speed);
  require_range(kWhere, "--target-range (high)", t.speed_hi, t.speed, 10.0);
  require_range(kWhere, "time_s", t.time_s, 1e-6, 10.0);
  require_range(kWhere, "--pile-width", t.pile_width_m, 1e-6, 1e-1);
  std::map<double, std::vector<double>> by_r;
  double n0 = 0.0;
  for (const auto& p : points) {
    by_r[p.r].push_back(p.removed);
    n0 += p.initial;
  }
  if (by_r.size() < 2) throw_input(kWhere, "points", std::to_string(by_r.size()) + " distinct r", "need at least two distinct r");
  CountFit f;
  f.n0 = n0 / double(points.size());
  const double per_speed = t.time_s * f.n0 / t.pile_width_m;  // toner per (m/s)
  f.target = t.speed * per_speed;
  f.target_lo = t.speed_lo * per_speed;
  f.target_hi = t.speed_hi * per_speed;
  for (const auto& [r, v] : by_r) {
    CountRow row{r, v.size(), 0.0, 0.0};
    for (double x : v) row.mean += x;
    row.mean /= double(v.size());
    if (v.size() > 1) {
      double ss = 0.0;
      for (double x : v) ss += (x - row.mean) * (x - row.mean);
      row.stderr_ = std::sqrt(ss / double(v.size() - 1) / double(v.size()));
    } else {
      f.single_seed = true;
    }
    f.rows.push_back(row);
  }
  // crossings of the mean curve (linear between swept r) with the target
  const auto& R = f.rows;
  for (std::size_t i = 0; i + 1 < R.size(); ++i) {
    const double a = R[i].mean - f.target, b = R[i + 1].mean - f.target;
    if (a == 0.0 && i > 0) continue;  // counted as the previous segment's end
    if ((a <= 0.0 && b >= 0.0) || (a >= 0.0 && b <= 0.0)) {
      if (!f.bracketed) f.r_fit = a == b ? R[i].r : R[i].r + (R[i + 1].r - R[i].r) * a / (a - b);
      f.bracketed = true;
      ++f.crossings;
    }
  }
  // 1-sigma interval: every r (fine grid, mean and stderr linear between swept r) at which
  // [mean - stderr, mean + stderr] overlaps [target_lo, target_hi]
  const int kGrid = 4000;
  const double r0 = R.front().r, r1 = R.back().r;
  std::size_t seg = 0;
  for (int k = 0; k <= kGrid; ++k) {
    const double r = k == kGrid ? r1 : r0 + (r1 - r0) * double(k) / kGrid;
    while (seg + 2 < R.size() && r > R[seg + 1].r) ++seg;
    const double w = (r - R[seg].r) / (R[seg + 1].r - R[seg].r);
    const double m = R[seg].mean + w * (R[seg + 1].mean - R[seg].mean);
    const double e = R[seg].stderr_ + w * (R[seg + 1].stderr_ - R[seg].stderr_);
    if (m - e <= f.target_hi && m + e >= f.target_lo) {
      if (!f.in_band) f.r_lo = r;
      f.in_band = true;
      f.r_hi = r;
    }
  }
  if (f.in_band) {
    f.open_lo = f.r_lo <= r0;
    f.open_hi = f.r_hi >= r1;
  }
  if (!f.bracketed) {
    const bool above = R.front().mean > f.target;
    f.hint = above ? "every mean count is above the target: extend the sweep to larger r" : "every mean count is below the target: extend the sweep to smaller r";
  }
  return f;
}

json calibrate_cohesion_from_sweep(const experiments::ExperimentOptions& o, const std::string& file_list, const CountTarget& target) {
  // Several sweeps (e.g. one per seed, run separately) are pooled: comma-separated files of the
  // same preset, model (--set overrides) and observation time.
  std::vector<std::string> files;
  for (std::size_t a = 0; a <= file_list.size();) {
    const std::size_t b = std::min(file_list.find(',', a), file_list.size());
    if (b == a) throw_input("calibrate cohesion", "--from-sweep", file_list, "empty file name in the comma-separated list");
    files.push_back(file_list.substr(a, b - a));
    a = b + 1;
  }
  std::vector<CountPoint> pts;
  double T = -1.0, width = -1.0;
  json first_meta;
  for (const auto& file : files) {
    json rep;
    try {
      rep = json::parse(io::read_file(file));
    } catch (const json::exception& e) {
      throw_input(file, "(JSON)", "", std::string("not a JSON document: ") + e.what());
    }
    if (!rep.is_object() || rep.value("experiment", std::string()) != "reduction" || !rep.contains("points") || !rep["points"].is_array())
      throw_input(file, "experiment", "", "expected the JSON written by `nipdem experiment reduction` (\"experiment\": \"reduction\", \"points\": [...])");
    if (rep.contains("meta") && rep["meta"].is_object()) {
      json m = json::object();
      for (const char* key : {"preset", "set", "config"})
        if (rep["meta"].contains(key)) m[key] = rep["meta"][key];
      if (first_meta.is_null()) first_meta = m;
      else if (m != first_meta)
        throw_input(file, "meta", m.dump(), fmt::format("every pooled sweep must have the same preset, config and --set overrides as {} ({})", files.front(), first_meta.dump()));
    }
    if (rep.contains("pile_width_m") && rep["pile_width_m"].is_number()) {
      const double w = rep["pile_width_m"].get<double>();
      if (width < 0.0) width = w;
      else if (std::abs(w - width) > 1e-9 * width) throw_input(file, "pile_width_m", fmt::format("{:g}", w), fmt::format("every pooled sweep must have the same pile width ({:g} m)", width));
    }
    std::size_t k = 0;
    for (const auto& p : rep["points"]) {
      for (const char* key : {"r", "removed", "initial_particles", "time_s"})
        if (!p.contains(key) || !p[key].is_number()) throw_input(file, fmt::format("points[{}].{}", k, key), "", "missing or not a number");
      const double tk = p["time_s"].get<double>();
      if (T < 0.0) T = tk;
      if (std::abs(tk - T) > 1e-6 * T) throw_input(file, fmt::format("points[{}].time_s", k), fmt::format("{:g}", tk), fmt::format("every point must have the same observation time ({:g} s)", T));
      pts.push_back({p["r"].get<double>(), p["removed"].get<double>(), p["initial_particles"].get<double>()});
      ++k;
    }
  }
  const std::string file = file_list;
  CountTarget t = target;
  t.time_s = T > 0.0 ? T : t.time_s;
  if (width > 0.0) t.pile_width_m = width;
  const CountFit f = fit_cohesion_from_counts(pts, t);

  std::vector<std::vector<double>> csv;
  io::Series s, raw;
  s.label = "mean over seeds (± standard error)";
  s.markers = true;
  s.line = false;
  raw.label = "each seed";
  raw.markers = true;
  raw.line = false;
  raw.marker_size = 2.5;
  for (const auto& row : f.rows) {
    csv.push_back({row.r, static_cast<double>(row.n), row.mean, row.stderr_});
    s.x.push_back(row.r);
    s.y.push_back(row.mean);
    s.y_err.push_back(row.stderr_);
  }
  for (const auto& p : pts) {
    raw.x.push_back(p.r);
    raw.y.push_back(p.removed);
  }
  io::write_csv(o.out / "cohesion.csv", {"r", "seeds", "removed_mean", "removed_stderr"}, csv, {"{:.8g}", "{:.0f}", "{:.8g}", "{:.8g}"});
  io::PlotSpec plot;
  plot.title = "Cohesion ratio from removed toner (§4.6, fig. 4.25, Table 4.3)";
  plot.x_label = "r = F_coh / F_adh";
  plot.y_label = fmt::format("toner removed in {:g} ms", 1e3 * t.time_s);
  plot.series.push_back(raw);
  plot.series.push_back(s);
  const double xa = f.rows.front().r, xb = f.rows.back().r;
  for (auto [y, lab] : {std::pair{f.target, "Table 4.3 speed as a count"}, std::pair{f.target_lo, "its range"}, std::pair{f.target_hi, ""}}) {
    io::Series tl;
    tl.label = lab;
    tl.x = {xa, xb};
    tl.y = {y, y};
    tl.dashed = true;
    plot.series.push_back(tl);
  }
  io::write_plot_png(o.out / "cohesion.png", plot);

  json rows = json::array();
  for (const auto& row : f.rows) rows.push_back({{"r", row.r}, {"seeds", row.n}, {"removed_mean", row.mean}, {"removed_stderr", row.stderr_}});
  json j{{"calibration", "cohesion"},
         {"method", "counts from a reduction sweep"},
         {"sweep", file},
         {"sweeps", files},
         {"target_speed_m_per_s", t.speed},
         {"target_speed_range_m_per_s", {t.speed_lo, t.speed_hi}},
         {"observation_time_s", t.time_s},
         {"pile_width_m", t.pile_width_m},
         {"initial_pile_mean", f.n0},
         {"target_removed", f.target},
         {"target_removed_range", {f.target_lo, f.target_hi}},
         {"rows", rows},
         {"bracketed", f.bracketed},
         {"crossings", f.crossings},
         {"single_seed_rows", f.single_seed},
         {"csv", (o.out / "cohesion.csv").string()},
         {"plot", (o.out / "cohesion.png").string()},
         {"meta", {{"git_hash", kGitHash}}}};
  if (f.bracketed) j["r_fit"] = f.r_fit;
  else j["hint"] = f.hint;
  if (f.in_band) {
    j["r_1sigma"] = {f.r_lo, f.r_hi};
    j["r_1sigma_open"] = {f.open_lo, f.open_hi};
  }
  return j;
}

json calibrate_cohesion(const experiments::ExperimentOptions& o, const CohesionOptions& c) {
  check_options(&o, c);
  json rounds = json::array(), failed = json::array();
  auto evaluate = [&](std::size_t k, const std::vector<double>& rs) {
    experiments::ExperimentOptions ro = o;
    ro.out = o.out / fmt::format("round_{}", k);
    // a distinct base seed per round: the same (seed, index) would replay round 0's piles
    ro.seed = o.seed + 1000003ULL * k;
    experiments::ReductionOptions red = c.reduction;
    red.cohesion_ratios = rs;
    if (o.progress) std::fprintf(stderr, "calibrate cohesion: round %zu/%zu, r = %s\n", k + 1, c.rounds, fmt::format("{:.4g}", fmt::join(rs, ", ")).c_str());
    const json rep = experiments::reduction(ro, red);
    io::write_file_atomic(ro.out / "reduction.json", rep.dump(2));
    std::vector<SpeedPoint> got;
    json used = json::array();
    for (const auto& p : rep["points"]) {
      if (!p.contains("reduction_speed_m_per_s")) {
        failed.push_back({{"round", k}, {"r", p["r"]}, {"error", "too few front/back samples for a reduction speed"}});
        continue;
      }
      got.push_back({p["r"].get<double>(), p["reduction_speed_m_per_s"].get<double>(), p.value("reduction_speed_stderr_m_per_s", 0.0)});
      used.push_back({{"r", p["r"]}, {"reduction_speed_m_per_s", p["reduction_speed_m_per_s"]},
                      {"reduction_speed_stderr_m_per_s", p.value("reduction_speed_stderr_m_per_s", 0.0)}, {"removed", p["removed"]}});
    }
    for (const auto& f : rep["failed"]) failed.push_back({{"round", k}, {"index", f["index"]}, {"error", f["error"]}});
    rounds.push_back({{"round", k}, {"out", ro.out.string()}, {"points", used}});
    return got;
  };
  const CohesionSearch search = search_cohesion_ratio(evaluate, c);
  const auto& pts = search.points;
  const auto& fit = search.fit;

  std::vector<std::vector<double>> csv;
  io::Series s;
  s.label = "simulated reduction speed";
  s.line = false;
  s.markers = true;
  for (const auto& p : pts) {
    csv.push_back({p.r, p.speed, p.stderr_});
    s.x.push_back(p.r);
    s.y.push_back(p.speed * 1e3);
    s.y_err.push_back(p.stderr_ * 1e3);
  }
  io::write_csv(o.out / "cohesion.csv", {"r", "reduction_speed_m_per_s", "reduction_speed_stderr_m_per_s"}, csv,
                std::vector<std::string>(3, "{:.8g}"));
  if (!pts.empty()) {
    io::PlotSpec plot;
    plot.title = "Cohesion ratio from the reduction speed (§4.6, Table 4.3)";
    plot.x_label = "r = F_coh / F_adh";
    plot.y_label = "reduction speed [mm/s]";
    plot.log_x = true;
    plot.series.push_back(s);
    io::Series t;
    t.label = "target";
    t.x = {pts.front().r, pts.back().r};
    t.y = {c.target_speed_m_per_s * 1e3, c.target_speed_m_per_s * 1e3};
    t.dashed = true;
    plot.series.push_back(t);
    if (fit.bracketed) {
      io::Series f;
      f.label = fmt::format("r fit = {:.3g}", fit.r_fit);
      f.x = {fit.r_fit};
      f.y = {c.target_speed_m_per_s * 1e3};
      f.line = false;
      f.markers = true;
      f.marker_size = 7.0;
      plot.series.push_back(f);
    }
    io::write_plot_png(o.out / "cohesion.png", plot);
  }
  json j{{"calibration", "cohesion"},
         {"target_speed_m_per_s", c.target_speed_m_per_s},
         {"bracketed", fit.bracketed},
         {"crossings", fit.crossings},
         {"pairs_against_trend_2sigma", fit.against_trend},
         {"rounds", rounds},
         {"observation_time_s", c.reduction.time_s},
         {"failed", failed},
         {"n_failed", failed.size()},
         {"csv", (o.out / "cohesion.csv").string()},
         {"meta", {{"git_hash", kGitHash}, {"preset", o.config.empty() ? o.preset : ""}, {"config", o.config}, {"set", o.sets},
                   {"seed", o.seed}, {"jobs", o.jobs}}}};
  if (fit.bracketed) {
    j["r_fit"] = fit.r_fit;
    j["bracket"] = {fit.r_lo, fit.r_hi};
    j["r_1sigma"] = {fit.r_1sigma_lo, fit.r_1sigma_hi};
  } else {
    j["hint"] = fit.hint.empty() ? "fewer than two usable reduction speeds" : fit.hint;
  }
  return j;
}

}  // namespace nipdem::calibrate
