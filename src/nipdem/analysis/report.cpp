#include "nipdem/analysis/report.hpp"

#include <cmath>

#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/csv.hpp"

namespace nipdem::analysis {

namespace {
nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }
}  // namespace

nlohmann::json to_json(const EdgeFit& f) {
  return {{"x0_m", num(f.x0)},          {"w_m", num(f.w)},
          {"width_10_90_m", num(f.width_10_90)}, {"width_stderr_m", num(f.width_stderr)},
          {"x10_m", num(f.x10)},        {"x90_m", num(f.x90)},
          {"floor", num(f.floor)},      {"ceiling", num(f.ceiling)},
          {"rms_residual", num(f.rms_residual)}, {"converged", f.converged},
          {"iterations", f.iterations}, {"points", f.n_points}};
}

nlohmann::json edge_sharpness_json(const LineEdgesBootstrap& b, std::size_t realizations) {
  nlohmann::json j{{"edge_front_m", num(b.fit.front.width_10_90)},
                   {"edge_back_m", num(b.fit.back.width_10_90)},
                   {"edge_front_ci_m", {num(b.front_width_ci.lo), num(b.front_width_ci.hi)}},
                   {"edge_back_ci_m", {num(b.back_width_ci.lo), num(b.back_width_ci.hi)}},
                   {"edge_front_std_m", num(b.front_width_std)},
                   {"edge_back_std_m", num(b.back_width_std)},
                   {"confidence_level", b.level},
                   {"bootstrap_resamples", b.n_boot},
                   {"bootstrap_failed", b.n_failed},
                   {"fit",
                    {{"front", to_json(b.fit.front)},
                     {"back", to_json(b.fit.back)},
                     {"floor", num(b.fit.floor)},
                     {"ceiling", num(b.fit.ceiling)},
                     {"rms_residual", num(b.fit.rms_residual)},
                     {"converged", b.fit.converged}}}};
  if (realizations > 0) j["realizations"] = realizations;
  return j;
}

nlohmann::json to_json(const SteadyState& s) {
  return {{"steady", s.steady},         {"reason", s.reason},          {"value", num(s.value)},
          {"std", num(s.std)},          {"stderr", num(s.stderr_mean)}, {"t_onset_s", num(s.t_onset)},
          {"drift", num(s.drift)},      {"drift_z", num(s.drift_z)},   {"samples_used", s.n_used}};
}

nlohmann::json to_json(const ReductionSpeed& r) {
  return {{"reduction_speed_m_per_s", num(r.speed)},
          {"reduction_speed_stderr_m_per_s", num(r.speed_stderr)},
          {"size_intercept_m", num(r.size_fit.intercept)},
          {"size_r2", num(r.size_fit.r2)},
          {"front_speed_m_per_s", num(r.front_fit.slope)},
          {"back_speed_m_per_s", num(r.back_fit.slope)},
          {"samples", r.size_fit.n}};
}

nlohmann::json to_json(const VoStatistics& v) {
  nlohmann::json per = nlohmann::json::array();
  for (double x : v.vo_V) per.push_back(x);
  return {{"vo_mean_V", num(v.mean_V)},
          {"vo_std_V", num(v.std_V)},
          {"vo_stderr_V", num(v.stderr_V)},
          {"vo_per_seed_V", per},
          {"seeds_not_found", v.seeds_not_found}};
}

void write_coverage_csv(const std::filesystem::path& path, const std::vector<double>& x,
                        const std::vector<double>& c, const LineEdgesFit& fit) {
  std::vector<double> model;
  model.reserve(x.size());
  for (double v : x) model.push_back(evaluate(fit, v));
  io::write_file_atomic(path, io::format_csv_columns({"x_m", "coverage", "fit"}, {x, c, model}));
}

io::PlotSpec coverage_plot(const std::vector<double>& x, const std::vector<double>& c, const LineEdgesFit& fit,
                           const std::string& title, double line_start_m, double line_end_m) {
  io::PlotSpec p;
  p.title = title;
  p.x_label = "drum surface position s [µm]";
  p.y_label = "coverage (fraction of lines covering the bin) [-]";
  io::Series data, model;
  data.label = "average coverage";
  data.line = false;
  data.markers = true;
  data.marker_size = 1.8;
  model.label = "sigmoid fit";
  for (std::size_t i = 0; i < x.size() && i < c.size(); ++i) {
    data.x.push_back(x[i] * 1e6);
    data.y.push_back(c[i]);
    model.x.push_back(x[i] * 1e6);
    model.y.push_back(evaluate(fit, x[i]));
  }
  p.series = {data, model};
  if (line_end_m > line_start_m) {
    io::Series line;
    line.label = "intended line (track voltage on)";
    line.dashed = true;
    line.color = std::array<double, 3>{0.3, 0.3, 0.3};
    const double a = 1e6 * line_start_m, b = 1e6 * line_end_m;
    line.x = {a, a, b, b};
    line.y = {0.0, 1.0, 1.0, 0.0};
    p.series.push_back(line);
  }
  return p;
}

}  // namespace nipdem::analysis
