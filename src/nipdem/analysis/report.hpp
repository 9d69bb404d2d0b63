// JSON / CSV / PNG output of the analysis results, with the key names of CLI.md
// (snake_case, SI unit suffix). Kept apart from the numerics so those stay I/O-free.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/analysis/fit.hpp"
#include "nipdem/analysis/reduction.hpp"
#include "nipdem/analysis/steady.hpp"
#include "nipdem/analysis/vo.hpp"
#include "nipdem/io/plot.hpp"

namespace nipdem::analysis {

// Edge sharpness (CLI.md `experiment edge-sharpness`): "edge_front_m", "edge_back_m" (10–90 %
// widths), "edge_front_ci_m"/"edge_back_ci_m" ([lo, hi] bootstrap percentile intervals),
// "edge_front_std_m"/"edge_back_std_m", "confidence_level", "bootstrap_resamples",
// "bootstrap_failed", "realizations" (if > 0), and "fit" (positions, floor, ceiling, rms).
// x is in metres.
nlohmann::json edge_sharpness_json(const LineEdgesBootstrap& b, std::size_t realizations = 0);
nlohmann::json to_json(const EdgeFit& f);            // x0_m, w_m, width_10_90_m, ... 
nlohmann::json to_json(const SteadyState& s);        // steady, reason, value, std, stderr, t_onset_s, ...
nlohmann::json to_json(const ReductionSpeed& r);     // reduction_speed_m_per_s, ..._stderr, ...
nlohmann::json to_json(const VoStatistics& v);       // vo_mean_V, vo_std_V, vo_stderr_V, vo_per_seed_V, ...

// Coverage curve file: columns x_m, coverage, fit (the fitted model at x). Atomic write.
void write_coverage_csv(const std::filesystem::path& path, const std::vector<double>& x_m,
                        const std::vector<double>& coverage, const LineEdgesFit& fit);
// Plot of an average coverage curve with its fit (x = drum surface position, shown in µm), as in
// thesis fig. 1.8, with the intended line [line_start_m, line_end_m] (track voltage on) marked
// when line_end_m > line_start_m.
io::PlotSpec coverage_plot(const std::vector<double>& x_m, const std::vector<double>& coverage,
                           const LineEdgesFit& fit, const std::string& title, double line_start_m = 0.0,
                           double line_end_m = 0.0);

}  // namespace nipdem::analysis
