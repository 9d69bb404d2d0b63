// Edge-sharpness analysis (thesis §1.4, §5.3, fig. 1.8): sigmoid fits to coverage curves,
// 10–90 % widths and bootstrap confidence intervals over realizations.
//
// Coverage model of one edge (logistic):
//   c(x) = floor + (ceiling - floor) / (1 + exp(-(x - x0) / w)),
// w > 0 for a rising edge, w < 0 for a falling one. Between 10 % and 90 % of the step the
// logistic argument goes from -ln 9 to +ln 9, so the 10–90 % width is 2 ln 9 |w| ≈ 4.394 |w|.
// The thesis scales the maximum coverage to 100 %; fitting `ceiling` (default) does exactly
// that, and the width does not depend on floor/ceiling.
//
// A printed line (a rise then a fall) is fitted jointly with the product of two logistics,
//   c(x) = floor + (ceiling - floor) L((x - x_rise)/w_rise) L(-(x - x_fall)/w_fall),
// which stays correct for short lines without a full-coverage plateau; each edge's sharpness is
// 2 ln 9 w of its own factor. Fits use Levenberg–Marquardt (Eigen) with analytic Jacobians;
// initial values come from the half-level crossings of a smoothed curve.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace nipdem::analysis {

// 2 ln 9: 10–90 % width of a logistic of scale w is kLogistic1090 * |w|.
inline constexpr double kLogistic1090 = 4.394449154672439;

// ---- Levenberg–Marquardt: the one fitter of nipdem ------------------------------------------
// Used by the sigmoid fits below, the adhesion and magnetisation calibrations and the probe-
// circuit fit (calibrate_rc, with fixed parameters, a search box and a step cap).
// `model(p, r, J)` fills residuals r (size n) and Jacobian J = dr/dp (n x m).
using LmModel = std::function<void(const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd& J)>;
struct LmResult {
  Eigen::VectorXd p;
  Eigen::MatrixXd covariance;  // (J^T J)^-1 * rss / (n - m): parameter covariance estimate
  double rss = 0;              // sum of squared residuals
  int iterations = 0;          // iterations run
  bool converged = false;
};
struct LmOptions {
  int max_iterations = 200;
  // When an accepted step ends the fit:
  //  relative: rss drop <= tol_drop * rss before the step, rss = 0, or the step, measured in
  //            the metric of the curvature, <= tol_step * sqrt(rss) (scale-free across parameters);
  //  absolute: rss drop <= tol_drop * rss after the step + 1e-300, or max |change of p| < tol_step.
  enum class Stop { relative, absolute } stop = Stop::relative;
  double tol_drop = 1e-10;
  double tol_step = 1e-8;
  std::vector<bool> free;          // empty: every parameter free; a fixed one keeps its start value
  Eigen::VectorXd lower, upper;    // empty: no bounds; trial points are clamped into the box
  double max_step = std::numeric_limits<double>::infinity();  // largest |step| of one parameter
  // Damping of each parameter: lambda * max(its curvature, damping_floor * the largest one).
  double damping_floor = 0.0;
  bool strict_decrease = false;    // accept a step that lowers the rss (false: that does not raise it)
  // A fit with no downhill step left is at a minimum: the damping above lambda_cap, or
  // max_tries rejected steps in one iteration (0: no limit).
  double lambda_cap = 1e14;
  int max_tries = 0;
};
LmResult levenberg_marquardt(const LmModel& model, Eigen::VectorXd p0, std::size_t n_residuals, const LmOptions& opt);
LmResult levenberg_marquardt(const LmModel& model, Eigen::VectorXd p0, std::size_t n_residuals,
                             int max_iterations = 200, double rel_tol = 1e-10);

// ---- Sigmoid fits -------------------------------------------------------------------------
struct SigmoidOptions {
  bool fit_floor = false;   // false: floor fixed at `floor`
  double floor = 0.0;
  bool fit_ceiling = true;  // true: the plateau is fitted (maximum coverage scaled to 100 %)
  double ceiling = 1.0;     // used when fit_ceiling is false
  int max_iterations = 200;
  // > 0: the curve is an average of this many presence/absence realizations, so its noise is
  // binomial with variance p(1-p)/N. The fit then iterates weighted least squares with weights
  // 1 / max(p(1-p), 1/N) from the previous pass (3 reweighting passes), which is the maximum-
  // likelihood fit and ~1.5x more precise on the narrow edge than unweighted least squares.
  // The floor 1/N keeps a single stray particle far in the tail from dominating.
  int binomial_realizations = 0;
};

struct EdgeFit {
  double x0 = 0;             // 50 % position [x units]
  double w = 0;              // logistic scale, signed (>0 rising) [x units]
  double floor = 0, ceiling = 1;
  double width_10_90 = 0;    // 2 ln 9 |w| [x units]
  double width_stderr = 0;   // from the fit covariance (assumes independent residuals)
  double x0_stderr = 0;
  double x10 = 0, x90 = 0;   // where the fit is at 10 % and 90 % of the step
  double rms_residual = 0;
  int iterations = 0;
  bool converged = false;
  std::size_t n_points = 0;
};

// Fits one edge. Throws InputError on mismatched sizes, < 5 points or non-finite data.
EdgeFit fit_edge(const std::vector<double>& x, const std::vector<double>& c, const SigmoidOptions& opt = {});
double evaluate(const EdgeFit& f, double x);

// Which edge of a line is the "front" (printed first): the one at low x or at high x.
enum class FrontSide { low_x, high_x };

struct LineEdgesFit {
  EdgeFit rise;   // edge at low x (w > 0)
  EdgeFit fall;   // edge at high x (w < 0)
  EdgeFit front;  // = rise or fall per FrontSide
  EdgeFit back;
  double floor = 0, ceiling = 1;
  double rms_residual = 0;
  int iterations = 0;
  bool converged = false;
};

LineEdgesFit fit_line_edges(const std::vector<double>& x, const std::vector<double>& c, const SigmoidOptions& opt = {},
                            FrontSide front = FrontSide::low_x);
double evaluate(const LineEdgesFit& f, double x);

// ---- Averages and bootstrap over realizations ---------------------------------------------
// Mean over realizations of curves sampled on one grid (all the same length).
std::vector<double> average_curve(const std::vector<std::vector<double>>& realizations);

// Coverage of an average curve at the two ends of its analysis range, relative to its peak:
// the mean over the first / last `edge_bins` points (default: one d50 of bins of d50/4, capped
// at a quarter of the curve). An edge that has not decayed to `threshold` of the peak there is
// cut by the range and its fitted width is biased; each such end gets a warning naming it.
struct RangeEndCoverage {
  double at_start = 0, at_end = 0;  // fraction of the peak
  bool start_cut = false, end_cut = false;
  std::vector<std::string> warnings;
};
// Throws InputError on fewer than 2 points or a curve without a positive peak.
RangeEndCoverage range_end_coverage(const std::vector<double>& avg, int edge_bins = 4, double threshold = 0.1);

struct Interval {
  double lo = 0, hi = 0;
};
// Percentile interval [ (1-level)/2, (1+level)/2 ] of `samples` (linear interpolation).
Interval percentile_interval(std::vector<double> samples, double level);

// Resamples realizations with replacement `n_boot` times (seeded, reproducible), averages each
// resample and applies `statistic`; a statistic that throws or returns an empty vector counts
// as a failed resample. Returns the statistics of the successful resamples.
struct BootstrapSamples {
  std::vector<std::vector<double>> stats;  // [resample][k]
  int n_failed = 0;
};
BootstrapSamples bootstrap_curves(const std::vector<std::vector<double>>& realizations,
                                  const std::function<std::vector<double>(const std::vector<double>& avg)>& statistic,
                                  int n_boot, std::uint64_t seed);

struct LineEdgesBootstrap {
  LineEdgesFit fit;               // fit to the average of all realizations
  std::vector<double> average;    // that average curve
  Interval front_width_ci, back_width_ci;
  double front_width_std = 0, back_width_std = 0;
  double level = 0.95;
  int n_boot = 0, n_failed = 0;   // resamples whose fit did not converge are left out
};
LineEdgesBootstrap bootstrap_line_edges(const std::vector<double>& x, const std::vector<std::vector<double>>& realizations,
                                        int n_boot, std::uint64_t seed, double level = 0.95,
                                        const SigmoidOptions& opt = {}, FrontSide front = FrontSide::low_x);

}  // namespace nipdem::analysis
