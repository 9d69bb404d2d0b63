// Calibration of the cohesion ratio r = F_coh / F_adh (eq. 4.6.1) against a measured
// reduction speed (thesis §4.6, Table 4.3): a 1-D root search over reduction experiments.
//
// The reduction speed v(r) of the simulated assembly is noisy and, by the thesis's reading of
// fig. 4.25, falls as r grows (cohesion keeps the assembly together against the sleeve). We do
// not assume more than that v(r) - v_target changes sign somewhere in [r_min, r_max]:
//  1. round 0 runs the reduction experiment at `points` log-spaced r in [r_min, r_max];
//  2. the bracket is the adjacent pair (in r) whose speeds straddle the target (the lowest such
//     pair if noise makes several; all are reported);
//  3. each further round runs `points` new r log-spaced strictly inside the bracket
//     (a `points`-section search: the bracket shrinks by points + 1 per round);
//  4. r_fit interpolates v linearly in ln r between the final bracket's ends; the 1-sigma
//     range maps the larger standard error of the two speeds through that slope.
// Every round is an ordinary `experiment reduction` in OUT/round_<k>/ (resumable).
#pragma once
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/experiments/reduction.hpp"

namespace nipdem::calibrate {

struct SpeedPoint {
  double r = 0;            // cohesion ratio [-], > 0
  double speed = 0;        // reduction speed [m/s]
  double stderr_ = 0;      // its standard error [m/s] (0 if unknown)
};

struct CohesionFit {
  bool bracketed = false;
  double r_fit = 0;                    // [-]
  double r_lo = 0, r_hi = 0;           // the bracket used
  double r_1sigma_lo = 0, r_1sigma_hi = 0;
  std::size_t crossings = 0;           // adjacent pairs straddling the target
  // adjacent pairs (in r) whose change opposes the overall trend (last vs first point) by more
  // than twice their combined standard error: the noise is not only statistical, or v(r) is
  // not monotone; r_1sigma then understates the uncertainty
  std::size_t against_trend = 0;
  std::string hint;                    // why not bracketed, and what to do
};

// Pure analysis: points in any order (r > 0, distinct). Throws InputError for r <= 0, fewer
// than two points, or a non-finite speed.
CohesionFit fit_cohesion_ratio(std::vector<SpeedPoint> points, double target_speed);

// The r values of the next round: n log-spaced values strictly inside (lo, hi).
std::vector<double> interior_log_points(double lo, double hi, std::size_t n);

// One round's evaluation: the reduction speeds at the given r (a point may be missing if its
// run gave no speed). `round` counts from 0.
using SpeedEvaluator = std::function<std::vector<SpeedPoint>(std::size_t round, const std::vector<double>& r)>;

struct CohesionSearch {
  CohesionFit fit;
  std::vector<SpeedPoint> points;                  // every evaluated point, sorted by r
  std::vector<std::vector<double>> rounds_r;       // the r asked for in each round
};

struct CohesionOptions {
  double target_speed_m_per_s = 0;     // e.g. Table 4.3: black 7.6e-4, colour 2.5e-4
  double r_min = 0.1, r_max = 100.0;
  std::size_t points = 4;              // r values per round
  std::size_t rounds = 2;              // round 0 + refinements
  experiments::ReductionOptions reduction;  // observation time, pile (cohesion_ratios ignored)
};

// The search of steps 1-4 on any evaluator (tested on analytic v(r)).
CohesionSearch search_cohesion_ratio(const SpeedEvaluator& evaluate, const CohesionOptions& c);

// ---- r from the removal counts of a finished sweep (the thesis's own reading of §4.6) ----
// Table 4.3 gives size-reduction speeds; the thesis turns them into counts of removed toner per
// 100 ms ("less than 200 black, 70 colour"). We do the same for the simulated pile: a pile of
// n0 toner over a width W at full height loses n0/W toner per metre it shrinks, so a speed v
// over the observation time T is N = v T n0 / W toner (docs/reduction.md). The sweep gives
// removed(r) at each r over seeds; r is where the mean curve (linear between the swept r)
// meets N, and the 1-sigma interval is every r at which mean +- standard error (over seeds)
// reaches the target band [N(v_lo), N(v_hi)] (Table 4.3's three experiments).
struct CountPoint {
  double r = 0;            // cohesion ratio [-], >= 0
  double removed = 0;      // toner removed in the observation time
  double initial = 0;      // toner in the pile at the start
};
struct CountTarget {
  double speed = 0, speed_lo = 0, speed_hi = 0;  // measured size-reduction speed and its range [m/s]
  double time_s = 0.1;                            // observation time of the sweep [s]
  double pile_width_m = 400e-6;                   // initial pile width [m]
};
struct CountRow {
  double r = 0;
  std::size_t n = 0;       // seeds at this r
  double mean = 0, stderr_ = 0;  // removed: mean and standard error over seeds (0 for one seed)
};
struct CountFit {
  std::vector<CountRow> rows;            // sorted by r
  double n0 = 0;                         // mean initial pile
  double target = 0, target_lo = 0, target_hi = 0;  // removed toner the speeds imply
  bool bracketed = false;                // the mean curve meets the target inside the sweep
  double r_fit = 0;                      // lowest crossing of the mean curve
  std::size_t crossings = 0;
  bool in_band = false;                  // some r has mean +- stderr inside the target band
  double r_lo = 0, r_hi = 0;             // 1-sigma interval (smallest / largest r in band)
  bool open_lo = false, open_hi = false; // the interval reaches the end of the sweep
  bool single_seed = false;              // some r has one seed only (no error estimate there)
  std::string hint;
};
// Throws InputError for fewer than two distinct r, negative/non-finite values, or a bad target.
CountFit fit_cohesion_from_counts(const std::vector<CountPoint>& points, const CountTarget& target);

// `calibrate cohesion --from-sweep FILE`: reads an `experiment reduction` JSON, fits, writes
// OUT/cohesion.{csv,png} and returns the report (no simulation is run).
nlohmann::json calibrate_cohesion_from_sweep(const experiments::ExperimentOptions& o, const std::string& sweep_json,
                                             const CountTarget& target);

// ---- one r for several units (the thesis chose one r for black and colour, §4.6) ----
// Each unit is the pooled count fit of its own sweep (a `calibrate cohesion --from-sweep`
// report: rows of mean and standard error over seeds at each swept r, and the Table 4.3 band as
// counts). The joint r minimises
//   chi2(r) = sum_u (mean_u(r) - target_u)^2 / (stderr_u(r)^2 + halfband_u^2),
// mean and stderr linear between the swept r as in fit_cohesion_from_counts, on the r range
// every unit covers; the interval is chi2 <= chi2_min + 1 (one fitted parameter).
struct JointUnit {
  std::string name;
  std::string source;                         // where the rows came from (error messages); name if empty
  std::vector<CountRow> rows;                 // at least two distinct r, sorted or not
  double target = 0, target_lo = 0, target_hi = 0;  // removed toner (counts)
};
struct JointCohesionFit {
  double r_fit = 0;
  double r_lo = 0, r_hi = 0;               // chi2 <= chi2_min + 1
  bool open_lo = false, open_hi = false;   // the interval reaches an end of the common range
  double r_min = 0, r_max = 0;             // the common range searched
  double chi2_min = 0;
  std::vector<double> chi2_unit;           // each unit's term at r_fit
  std::size_t dof = 0;                     // units - 1
  std::vector<std::pair<double, double>> curve;  // (r, chi2) on the search grid
};
// Throws InputError for fewer than two units, a unit with fewer than two r, non-finite or
// negative values, a target outside its band, no common r range, or a zero denominator (one seed
// and no band at some r: no error estimate).
JointCohesionFit fit_joint_cohesion(const std::vector<JointUnit>& units);

// `calibrate cohesion-joint REPORT,REPORT,...`: reads `calibrate cohesion --from-sweep` JSON
// reports (a unit is named by its file's stem), fits, writes OUT/cohesion_joint.csv (chi2 curve),
// OUT/removed_vs_r.csv and OUT/removed_vs_r.png (fig. 4.25 analogue) and returns the report.
nlohmann::json calibrate_cohesion_joint(const experiments::ExperimentOptions& o, const std::string& report_list);

// Runs the rounds (threads only: each round depends on the last) and returns the JSON report
// (CLI.md keys: r_fit, bracket, points, rounds, ...). Writes OUT/cohesion.csv and
// OUT/cohesion.png (speed vs r with the target).
nlohmann::json calibrate_cohesion(const experiments::ExperimentOptions& o, const CohesionOptions& c);

}  // namespace nipdem::calibrate
