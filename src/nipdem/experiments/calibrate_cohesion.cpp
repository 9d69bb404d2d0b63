#include "nipdem/experiments/calibrate_cohesion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <array>
#include <filesystem>
#include <limits>
#include <map>
#include <tuple>
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

// Mean and standard error at r, linear between the swept r of `rows` (sorted by r, >= 2 rows);
// `seg` is the segment to start from and is advanced (calls with growing r walk the rows once).
std::pair<double, double> interp_rows(const std::vector<CountRow>& rows, double r, std::size_t& seg) {
  while (seg + 2 < rows.size() && r > rows[seg + 1].r) ++seg;
  const CountRow &a = rows[seg], &b = rows[seg + 1];
  const double w = (r - a.r) / (b.r - a.r);
  return {a.mean + w * (b.mean - a.mean), a.stderr_ + w * (b.stderr_ - a.stderr_)};
}

// "a.json,b.json" -> {"a.json", "b.json"}; an empty name is an InputError naming `option`.
std::vector<std::string> split_file_list(const std::string& list, const char* where, const char* option) {
  std::vector<std::string> files;
  for (std::size_t a = 0; a <= list.size();) {
    const std::size_t b = std::min(list.find(',', a), list.size());
    if (b == a) throw_input(where, option, list, "empty file name in the comma-separated list");
    files.push_back(list.substr(a, b - a));
    a = b + 1;
  }
  return files;
}

json read_json_file(const std::string& file) {
  try {
    return json::parse(io::read_file(file));
  } catch (const json::exception& e) {
    throw_input(file, "(JSON)", "", std::string("not a JSON document: ") + e.what());
  }
}
}  // namespace

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
    const auto [m, e] = interp_rows(R, r, seg);
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
  const std::vector<std::string> files = split_file_list(file_list, kWhere, "--from-sweep");
  std::vector<CountPoint> pts;
  double T = -1.0, width = -1.0;
  json first_meta;
  for (const auto& file : files) {
    json rep = read_json_file(file);
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

JointCohesionFit fit_joint_cohesion(const std::vector<JointUnit>& units_in) {
  const char* where = "calibrate cohesion-joint";
  constexpr double kMaxR = 1e6;
  if (units_in.size() < 2) throw_input(where, "reports", std::to_string(units_in.size()), "a joint fit needs at least two units");
  std::vector<JointUnit> units = units_in;
  JointCohesionFit f;
  f.r_min = -std::numeric_limits<double>::infinity();
  f.r_max = std::numeric_limits<double>::infinity();
  for (auto& u : units) {
    std::sort(u.rows.begin(), u.rows.end(), [](const CountRow& a, const CountRow& b) { return a.r < b.r; });
    if (u.rows.size() < 2) throw_input(u.source.empty() ? u.name : u.source, "rows", std::to_string(u.rows.size()), "need at least two swept r");
    for (std::size_t i = 0; i < u.rows.size(); ++i) {
      const auto& row = u.rows[i];
      // r beyond 1e6 is no cohesion ratio a sweep meant (the thesis's range is 0-1000); it would
      // stretch the last segment's interpolation silently
      if (!std::isfinite(row.r) || row.r < 0.0 || row.r > kMaxR || !std::isfinite(row.mean) || row.mean < 0.0 || !std::isfinite(row.stderr_) || row.stderr_ < 0.0)
        throw_input(u.source.empty() ? u.name : u.source, fmt::format("rows[{}]", i), fmt::format("r {:g}, mean {:g}, stderr {:g}", row.r, row.mean, row.stderr_),
                    fmt::format("r in [0, {:g}], mean and stderr finite and >= 0", kMaxR));
      if (i > 0 && !(row.r > u.rows[i - 1].r)) throw_input(u.source.empty() ? u.name : u.source, fmt::format("rows[{}].r", i), fmt::format("{:g}", row.r), "every r must be distinct");
    }
    if (!std::isfinite(u.target) || !std::isfinite(u.target_lo) || !std::isfinite(u.target_hi) || !(u.target_lo <= u.target && u.target <= u.target_hi))
      throw_input(u.source.empty() ? u.name : u.source, "target_removed", fmt::format("{:g} in [{:g}, {:g}]", u.target, u.target_lo, u.target_hi), "finite, inside its range");
    f.r_min = std::max(f.r_min, u.rows.front().r);
    f.r_max = std::min(f.r_max, u.rows.back().r);
  }
  if (!(f.r_max > f.r_min))
    throw_input(where, "rows", fmt::format("common r range [{:g}, {:g}]", f.r_min, f.r_max), "the units' sweeps must overlap in r");
  constexpr int kGrid = 20000;  // step (r_max - r_min) / 2e4: 1.5e-4 for a sweep to r = 3
  std::vector<std::size_t> seg(units.size(), 0);
  f.chi2_min = std::numeric_limits<double>::infinity();
  std::vector<double> chi2(kGrid + 1);
  for (int k = 0; k <= kGrid; ++k) {
    const double r = k == kGrid ? f.r_max : f.r_min + (f.r_max - f.r_min) * double(k) / kGrid;
    double c = 0.0;
    for (std::size_t u = 0; u < units.size(); ++u) {
      const auto [m, e] = interp_rows(units[u].rows, r, seg[u]);
      const double hb = 0.5 * (units[u].target_hi - units[u].target_lo);
      const double var = e * e + hb * hb;
      if (!(var > 0.0))
        throw_input(units[u].source.empty() ? units[u].name : units[u].source, "rows", fmt::format("r = {:g}", r), "no error estimate there (one seed and no target range): pool a second seed or give the band");
      c += (m - units[u].target) * (m - units[u].target) / var;
    }
    chi2[k] = c;
    if (c < f.chi2_min) { f.chi2_min = c; f.r_fit = r; }
  }
  bool any = false;
  for (int k = 0; k <= kGrid; ++k) {
    const double r = k == kGrid ? f.r_max : f.r_min + (f.r_max - f.r_min) * double(k) / kGrid;
    if (k % 100 == 0 || k == kGrid) f.curve.emplace_back(r, chi2[k]);
    if (chi2[k] <= f.chi2_min + 1.0) {
      if (!any) f.r_lo = r;
      any = true;
      f.r_hi = r;
    }
  }
  f.open_lo = f.r_lo <= f.r_min;
  f.open_hi = f.r_hi >= f.r_max;
  for (auto& u : units) {
    std::size_t s0 = 0;
    const auto [m, e] = interp_rows(u.rows, f.r_fit, s0);
    const double hb = 0.5 * (u.target_hi - u.target_lo);
    f.chi2_unit.push_back((m - u.target) * (m - u.target) / (e * e + hb * hb));
  }
  f.dof = units.size() - 1;
  return f;
}

json calibrate_cohesion_joint(const experiments::ExperimentOptions& o, const std::string& report_list) {
  const char* where = "calibrate cohesion-joint";
  const std::vector<std::string> files = split_file_list(report_list, where, "REPORTS");
  std::vector<JointUnit> units;
  std::vector<json> reps;
  for (const auto& file : files) {
    json rep = read_json_file(file);
    if (!rep.is_object() || rep.value("calibration", std::string()) != "cohesion" || !rep.contains("rows") || !rep["rows"].is_array())
      throw_input(file, "calibration", "", "expected the JSON report of `nipdem calibrate cohesion --from-sweep` (\"calibration\": \"cohesion\", \"rows\": [...])");
    JointUnit u;
    u.name = std::filesystem::path(file).stem().string();
    u.source = file;
    for (const auto& other : units)
      if (other.name == u.name) throw_input(file, "REPORTS", u.name, "two reports with the same file name: a unit is named by its file's stem");
    std::size_t k = 0;
    for (const auto& row : rep["rows"]) {
      for (const char* key : {"r", "removed_mean", "removed_stderr"})
        if (!row.is_object() || !row.contains(key) || !row[key].is_number()) throw_input(file, fmt::format("rows[{}].{}", k, key), "", "missing or not a number");
      u.rows.push_back({row["r"].get<double>(), row.value("seeds", std::size_t{0}), row["removed_mean"].get<double>(), row["removed_stderr"].get<double>()});
      ++k;
    }
    const json& tr = rep.contains("target_removed_range") ? rep["target_removed_range"] : json();
    if (!rep.contains("target_removed") || !rep["target_removed"].is_number() || !tr.is_array() || tr.size() != 2 || !tr[0].is_number() || !tr[1].is_number())
      throw_input(file, "target_removed", "", "missing: target_removed (number) and target_removed_range ([lo, hi]) are required");
    u.target = rep["target_removed"].get<double>();
    u.target_lo = tr[0].get<double>();
    u.target_hi = tr[1].get<double>();
    units.push_back(std::move(u));
    reps.push_back(std::move(rep));
  }
  const JointCohesionFit f = fit_joint_cohesion(units);

  std::vector<std::vector<double>> curve_csv;
  for (const auto& [r, c] : f.curve) curve_csv.push_back({r, c});
  io::write_csv(o.out / "cohesion_joint.csv", {"r", "chi2"}, curve_csv, {"{:.6g}", "{:.8g}"});
  std::vector<std::string> cols{"unit", "r", "seeds", "removed_mean", "removed_stderr"};
  std::vector<std::vector<std::string>> rows_csv;
  io::PlotSpec plot;
  plot.title = "One cohesion ratio for every unit (§4.6, fig. 4.25 analogue; Table 4.3 bands)";
  plot.x_label = "r = F_coh / F_adh";
  plot.y_label = "toner removed from the pile in the observation time";
  double y_top = 0.0;
  // a unit's points and its band share a colour (black for the black unit, as in fig. 4.25)
  const std::array<std::array<double, 3>, 4> kUnitColours{{{0.1, 0.1, 0.1}, {0.12, 0.47, 0.71}, {0.58, 0.40, 0.74}, {0.17, 0.63, 0.17}}};
  for (std::size_t ui = 0; ui < units.size(); ++ui) {
    const auto& u = units[ui];
    const auto colour = u.name == "black" ? kUnitColours[0] : kUnitColours[1 + ui % 3];
    io::Series s;
    s.color = colour;
    s.label = u.name + ": mean over seeds (± standard error)";
    s.markers = true;
    s.line_only_if_resolved = true;
    for (const auto& row : u.rows) {
      s.x.push_back(row.r);
      s.y.push_back(row.mean);
      s.y_err.push_back(row.stderr_);
      y_top = std::max(y_top, row.mean + row.stderr_);
      rows_csv.push_back({u.name, fmt::format("{:.6g}", row.r), std::to_string(row.n), fmt::format("{:.8g}", row.mean), fmt::format("{:.8g}", row.stderr_)});
    }
    plot.series.push_back(s);
    for (auto [y, lab] : {std::pair{u.target_lo, u.name + ": Table 4.3 band"}, std::pair{u.target_hi, std::string()}}) {
      io::Series b;
      b.label = lab;
      b.x = {u.rows.front().r, u.rows.back().r};
      b.y = {y, y};
      b.dashed = true;
      b.line_width = 1.0;
      b.color = colour;
      plot.series.push_back(b);
    }
  }
  io::write_file_atomic(o.out / "removed_vs_r.csv", io::format_csv_cells(cols, rows_csv));
  for (auto [x, lab, dashed] : {std::tuple{f.r_fit, fmt::format("joint r = {:.3g}", f.r_fit), false},
                                std::tuple{f.r_lo, fmt::format("chi2 <= min + 1: {:.3g}-{:.3g}", f.r_lo, f.r_hi), true},
                                std::tuple{f.r_hi, std::string(), true}}) {
    io::Series v;
    v.label = lab;
    v.x = {x, x};
    v.y = {0.0, y_top};
    v.dashed = dashed;
    v.color = std::array<double, 3>{0.85, 0.45, 0.0};
    plot.series.push_back(v);
  }
  io::write_plot_png(o.out / "removed_vs_r.png", plot);

  json per_unit = json::object();
  for (std::size_t u = 0; u < units.size(); ++u) {
    json pu{{"report", files[u]}, {"chi2_at_r_fit", f.chi2_unit[u]}, {"target_removed", units[u].target},
            {"target_removed_range", {units[u].target_lo, units[u].target_hi}}};
    for (const char* key : {"r_fit", "r_1sigma", "sweeps"})
      if (reps[u].contains(key)) pu[key] = reps[u][key];
    per_unit[units[u].name] = pu;
  }
  return json{{"calibration", "cohesion-joint"},
              {"method", "chi2 over the units of the pooled reduction-sweep counts, mean and stderr linear between the swept r; interval chi2 <= min + 1"},
              {"reports", files},
              {"r_fit", f.r_fit},
              {"r_interval_dchi2_1", {f.r_lo, f.r_hi}},
              {"r_interval_open", {f.open_lo, f.open_hi}},
              {"r_range_searched", {f.r_min, f.r_max}},
              {"chi2_min", f.chi2_min},
              {"dof", f.dof},
              {"units", per_unit},
              {"csv", (o.out / "cohesion_joint.csv").string()},
              {"rows_csv", (o.out / "removed_vs_r.csv").string()},
              {"plot", (o.out / "removed_vs_r.png").string()},
              {"meta", {{"git_hash", kGitHash}}}};
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
