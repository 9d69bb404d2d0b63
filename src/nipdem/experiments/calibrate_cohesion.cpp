#include "nipdem/experiments/calibrate_cohesion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"
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

  std::string csv = "r,reduction_speed_m_per_s,reduction_speed_stderr_m_per_s\n";
  io::Series s;
  s.label = "simulated reduction speed";
  s.line = false;
  s.markers = true;
  for (const auto& p : pts) {
    csv += fmt::format("{:.8g},{:.8g},{:.8g}\n", p.r, p.speed, p.stderr_);
    s.x.push_back(p.r);
    s.y.push_back(p.speed * 1e3);
    s.y_err.push_back(p.stderr_ * 1e3);
  }
  io::write_file_atomic(o.out / "cohesion.csv", csv);
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
