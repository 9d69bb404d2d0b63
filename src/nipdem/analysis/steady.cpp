#include "nipdem/analysis/steady.hpp"

#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "nipdem/core/error.hpp"

namespace nipdem::analysis {

SteadyState detect_steady_state(const std::vector<double>& t, const std::vector<double>& y, const SteadyOptions& opt) {
  const std::string where = "steady-state detection";
  if (t.size() != y.size())
    throw_input(where, "signal", fmt::format("{} times, {} values", t.size(), y.size()), "lengths differ");
  if (opt.n_batches < 8) throw_input(where, "n_batches", std::to_string(opt.n_batches), "too few", ">= 8");
  require_range(where, "max_truncation_fraction", opt.max_truncation_fraction, 0.0, 0.9);
  require_positive(where, "z_threshold", opt.z_threshold);
  require_range(where, "drift_tolerance", opt.drift_tolerance, 0.0, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i]) || !std::isfinite(y[i]))
      throw_input(where, fmt::format("sample {}", i), fmt::format("({:g}, {:g})", t[i], y[i]), "not finite");
    if (i > 0 && t[i] < t[i - 1])
      throw_input(where, fmt::format("t[{}]", i), fmt::format("{:g}", t[i]), "time goes backwards");
  }

  SteadyState s;
  const std::size_t nb = static_cast<std::size_t>(opt.n_batches);
  const std::size_t n = y.size();
  if (n < 2 * nb) {
    s.reason = fmt::format("signal too short: {} samples, need at least {} ({} batches of 2)", n, 2 * nb, nb);
    return s;
  }
  const std::size_t b = n / nb;
  const std::size_t skip = n - b * nb;
  std::vector<double> Y(nb, 0.0);
  for (std::size_t k = 0; k < nb; ++k) {
    for (std::size_t i = 0; i < b; ++i) Y[k] += y[skip + k * b + i];
    Y[k] /= static_cast<double>(b);
  }

  // MSER over d = 0 .. max_truncation_fraction * nb (searching further lets a short, by chance
  // quiet tail win; a transient that lasts longer is caught by the drift test below).
  const std::size_t d_max = std::min(nb - 5, static_cast<std::size_t>(std::floor(opt.max_truncation_fraction * nb)));
  std::size_t best_d = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t d = 0; d <= d_max; ++d) {
    const double m = static_cast<double>(nb - d);
    double mean = 0;
    for (std::size_t k = d; k < nb; ++k) mean += Y[k];
    mean /= m;
    double ss = 0;
    for (std::size_t k = d; k < nb; ++k) ss += (Y[k] - mean) * (Y[k] - mean);
    const double v = ss / (m * m);
    if (v < best) {
      best = v;
      best_d = d;
    }
  }
  s.onset_index = best_d == 0 ? 0 : skip + best_d * b;
  s.t_onset = t[s.onset_index];

  // Drift test between the halves of the retained batches.
  const std::size_t kept = nb - best_d, h = kept / 2;
  const std::size_t a0 = best_d + (kept - 2 * h);  // drop one batch if odd so halves are equal
  double m1 = 0, m2 = 0;
  for (std::size_t k = 0; k < h; ++k) {
    m1 += Y[a0 + k];
    m2 += Y[a0 + h + k];
  }
  m1 /= h;
  m2 /= h;
  double ss = 0;
  for (std::size_t k = 0; k < h; ++k) {
    ss += (Y[a0 + k] - m1) * (Y[a0 + k] - m1);
    ss += (Y[a0 + h + k] - m2) * (Y[a0 + h + k] - m2);
  }
  const double var_b = ss / static_cast<double>(2 * h - 2);  // pooled batch-mean variance
  const double se_diff = std::sqrt(var_b * 2.0 / h);
  s.drift = m2 - m1;
  s.drift_z = se_diff > 0 ? std::abs(s.drift) / se_diff : (s.drift == 0 ? 0.0 : std::numeric_limits<double>::infinity());

  // Values from the onset on.
  s.n_used = n - s.onset_index;
  double mean = 0;
  for (std::size_t i = s.onset_index; i < n; ++i) mean += y[i];
  mean /= static_cast<double>(s.n_used);
  double var = 0;
  for (std::size_t i = s.onset_index; i < n; ++i) var += (y[i] - mean) * (y[i] - mean);
  s.value = mean;
  s.std = std::sqrt(var / static_cast<double>(s.n_used > 1 ? s.n_used - 1 : 1));
  double vb = 0, mb = 0;
  for (std::size_t k = best_d; k < nb; ++k) mb += Y[k];
  mb /= kept;
  for (std::size_t k = best_d; k < nb; ++k) vb += (Y[k] - mb) * (Y[k] - mb);
  s.stderr_mean = std::sqrt(vb / static_cast<double>(kept - 1) / static_cast<double>(kept));

  const bool within_tol = opt.drift_tolerance > 0 && std::abs(s.drift) <= opt.drift_tolerance;
  if (s.drift_z > opt.z_threshold && !within_tol) {
    s.reason = fmt::format("still drifting: mean changed by {:g} between the halves of the part after t = {:g} ({:.1f} "
                           "standard errors > {:g}){}",
                           s.drift, s.t_onset, s.drift_z, opt.z_threshold,
                           best_d == d_max ? "; the transient may not have ended (onset at the search limit)" : "");
    return s;
  }
  s.steady = true;
  return s;
}

FlowBalance flow_balance(const std::vector<double>& t, const std::vector<std::int64_t>& cumulative_in,
                         const std::vector<std::int64_t>& cumulative_out, double t_from) {
  const std::string where = "flow balance";
  if (t.size() != cumulative_in.size() || t.size() != cumulative_out.size())
    throw_input(where, "counts", fmt::format("{} times, {} inflow, {} outflow counts", t.size(), cumulative_in.size(), cumulative_out.size()),
                "lengths differ");
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (!(t[i] >= t[i - 1])) throw_input(where, fmt::format("t[{}]", i), fmt::format("{:g}", t[i]), "time goes backwards");
    if (cumulative_in[i] < cumulative_in[i - 1] || cumulative_out[i] < cumulative_out[i - 1])
      throw_input(where, fmt::format("sample {}", i), fmt::format("in {}, out {}", cumulative_in[i], cumulative_out[i]),
                  "cumulative counts decrease");
  }
  std::size_t k = 0;
  while (k < t.size() && t[k] < t_from) ++k;
  if (k == t.size()) throw_input(where, "t_from", fmt::format("{:g}", t_from), "after the last sample");
  const std::size_t last = t.size() - 1;
  FlowBalance b;
  b.t_from = t[k];
  b.t_to = t[last];
  b.inflow = cumulative_in[last] - cumulative_in[k];
  b.outflow = cumulative_out[last] - cumulative_out[k];
  b.outflow_over_inflow = b.inflow > 0 ? static_cast<double>(b.outflow) / static_cast<double>(b.inflow)
                                       : std::numeric_limits<double>::quiet_NaN();
  b.growth_per_s = b.t_to > b.t_from ? static_cast<double>(b.inflow - b.outflow) / (b.t_to - b.t_from) : 0.0;
  return b;
}

}  // namespace nipdem::analysis
