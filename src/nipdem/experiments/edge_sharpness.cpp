#include "nipdem/experiments/edge_sharpness.hpp"

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/analysis/analysis.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"

namespace nipdem::experiments {

using nlohmann::json;

namespace {
void check(const EdgeOptions& e) {
  if (e.realizations < 2 || e.realizations > 100000)
    throw_input("experiment edge-sharpness", "--realizations", std::to_string(e.realizations), "out of range", "[2, 100000]");
  if (e.bootstrap < 0 || e.bootstrap > 1000000)
    throw_input("experiment edge-sharpness", "--bootstrap", std::to_string(e.bootstrap), "out of range", "[0, 1000000]");
  check_print_options("experiment edge-sharpness", e.print);
}

// The common analysis grid over all realizations: bins of d50/4 from line start - margin to
// line end + margin.
struct Grid {
  double bin, lo, hi;
  int n;
  std::vector<double> centres() const {
    std::vector<double> x(n);
    for (int k = 0; k < n; ++k) x[k] = lo + (k + 0.5) * bin;
    return x;
  }
};

// The coverage curve of each realization on the grid; printed_total summed over them.
std::vector<std::vector<double>> coverage_curves(const ExperimentOptions& o, const ensemble::Summary& sum, const Grid& g, long& printed_total) {
  std::vector<std::vector<double>> curves;
  printed_total = 0;
  for (const auto& r : sum.records) {
    if (!r.ok) continue;
    // Drum still inside the window at the run's end is unobserved, not uncovered: a realization
    // (e.g. resumed from a folder made with a shorter run) must have observed the whole grid.
    const double seen = r.result.contains("s_observed_m") ? r.result["s_observed_m"].get<double>() : -1.0;
    if (seen < g.hi - 0.5 * g.bin)
      throw_input((o.out / "edge_sharpness" / "realizations").string(), "realization " + std::to_string(r.index) + " s_observed_m",
                  r.result.contains("s_observed_m") ? fmt::format("{:.10g}", seen) : "missing (made by an older nipdem)",
                  fmt::format("every line must have observed the drum up to the analysis range's end, line end + margin = {:.4g} m; use a new --out", g.hi));
    std::vector<double> c(g.n, 0.0);
    for (auto& b : r.result["bins_s_covered"]) {
      const int k = static_cast<int>(std::floor((b[0].get<double>() + 0.5 * g.bin - g.lo) / g.bin));
      if (k >= 0 && k < g.n && b[1].get<int>()) c[k] = 1.0;
    }
    printed_total += r.result["printed"].get<long>();
    curves.push_back(c);
  }
  return curves;
}

// One row per line (failed ones too): enough to redo the analysis on another grid.
void write_lines_csv(const std::filesystem::path& file, const ensemble::Summary& sum) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& r : sum.records) {
    std::vector<std::string> row = {std::to_string(r.index), std::to_string(r.seed), r.ok ? "1" : "0", fmt::format("{:.1f}", r.wall_s)};
    if (!r.ok) {
      row.insert(row.end(), {"", "", ""});
    } else {
      std::string starts;
      for (auto& b : r.result["bins_s_covered"])
        if (b[1].get<int>()) starts += (starts.empty() ? "" : ";") + fmt::format("{:.3f}", 1e6 * b[0].get<double>());
      row.insert(row.end(), {std::to_string(r.result["printed"].get<long>()), fmt::format("{:.1f}", 1e6 * r.result["s_observed_m"].get<double>()), starts});
    }
    rows.push_back(std::move(row));
  }
  io::write_file_atomic(file, io::format_csv_cells({"index", "seed", "ok", "wall_s", "printed", "s_observed_um", "covered_bin_starts_um"}, rows));
}
}  // namespace

json edge_sharpness(const ExperimentOptions& o, const EdgeOptions& e) {
  check(e);
  // The line is printed at the configuration's print.voltage_V (default 40 V, §5.3).
  reject_fixed_sets(o, "edge-sharpness", print_fixed_keys(e.print, false));
  const nip::NipConfig base = base_config(o);
  const nip::NipConfig line = print_config(base, e.print, std::nullopt, std::nullopt);
  require_range("experiment edge-sharpness", "--margin", e.margin_m, 20e-6, 5e-3);
  const double volts = line.electric.pattern.segments().empty() ? 40.0 : line.electric.pattern.segments()[0].voltage_V;
  auto task = [&](std::size_t, std::uint64_t seed) {
    const auto pr = print_line(o, base, e.print, volts, seed, e.margin_m);
    json bins = json::array();
    for (const auto& b : pr.coverage) bins.push_back({b.s0, b.covered ? 1 : 0});
    return json{{"printed", pr.printed}, {"bins_s_covered", bins}, {"s_observed_m", pr.s_observed_m}};
  };
  const auto sum = ensemble::run(task, ensemble_options(o, static_cast<std::size_t>(e.realizations), "edge_sharpness"));
  if (!sum.is_root) return {};
  Grid g;
  g.bin = 0.25 * line.size.d50;
  g.lo = e.print.line_start_m - e.margin_m;
  g.hi = e.print.line_start_m + e.print.line_length_m + e.margin_m;
  g.n = static_cast<int>(std::lround((g.hi - g.lo) / g.bin));
  const std::vector<double> x = g.centres();
  long printed_total = 0;
  const auto curves = coverage_curves(o, sum, g, printed_total);
  write_lines_csv(o.out / "lines.csv", sum);
  json out = {{"experiment", "edge-sharpness"}, {"voltage_V", volts}, {"realizations", curves.size()}, {"printed_particles", printed_total},
              {"failed", failures(sum)}, {"n_failed", sum.n_failed}, {"lines_file", (o.out / "lines.csv").string()}, {"meta", meta(o, &sum)}};
  const auto avg = curves.empty() ? std::vector<double>(g.n, 0.0) : analysis::average_curve(curves);
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
