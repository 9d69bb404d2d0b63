// Steady-state detection for a time signal, e.g. the front position of the toner assembly
// vs time (thesis §5.1): when has the running mean stopped drifting, what is the steady value
// and how large are its fluctuations?
//
// Method (documented in docs/analysis.md):
//  1. The signal is cut into `n_batches` equal batches (dropping the first n mod n_batches
//     samples) and reduced to batch means, which are far less autocorrelated than raw samples.
//  2. MSER truncation (White 1997) on the batch means: choose the number d of leading batches
//     to discard that minimises  sum_{i>=d} (Y_i - mean_d)^2 / (nb - d)^2 , searching d up to
//     `max_truncation_fraction` of the batches (further, a short tail that is quiet by chance
//     would win).
//  3. Drift test on the retained batches: the means of their first and second halves must
//     agree within `z_threshold` standard errors (pooled batch-mean variance), or within the
//     absolute `drift_tolerance` if one is given.
// The steady value is the mean of the raw samples from the onset on; `std` is their standard
// deviation (the fluctuation), `stderr_mean` the batch-means standard error of that value.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace nipdem::analysis {

struct SteadyOptions {
  int n_batches = 20;
  double max_truncation_fraction = 0.5;
  double z_threshold = 3.0;
  double drift_tolerance = 0.0;  // absolute, in signal units; 0 = purely statistical test
};

struct SteadyState {
  bool steady = false;
  std::string reason;        // why not steady (empty when steady)
  double value = 0;          // mean from onset on
  double std = 0;            // standard deviation of the samples from onset on
  double stderr_mean = 0;    // standard error of `value` from batch means
  double t_onset = 0;        // time at which the retained part starts
  std::size_t onset_index = 0;
  double drift = 0;          // second-half mean minus first-half mean of the retained part
  double drift_z = 0;        // |drift| / its standard error
  std::size_t n_used = 0;    // samples from onset on
};

// `t` must be non-decreasing and the same length as `y`. Throws InputError on bad input
// (length mismatch, non-finite values, bad options); a signal that is too short is reported
// as not steady.
SteadyState detect_steady_state(const std::vector<double>& t, const std::vector<double>& y, const SteadyOptions& opt = {});

// Particle balance of an open region (the nip window) over [t_from, last sample]: what came in
// and what went out, from cumulative counts sampled at times t. A steady *signal* (the front)
// does not make a steady *assembly*: while outflow/inflow is well below 1 the window is still
// filling and a slow drift may follow (docs/analysis.md, "Filling").
struct FlowBalance {
  double t_from = 0, t_to = 0;         // the interval used [s] (t_from = first sample >= the request)
  std::int64_t inflow = 0, outflow = 0;  // particles in / out over it
  double outflow_over_inflow = 0;      // NaN when nothing came in
  double growth_per_s = 0;             // (inflow - outflow) / (t_to - t_from); 0 for an empty interval
};
// `t` non-decreasing, `cumulative_in`/`cumulative_out` non-decreasing, all the same length;
// throws InputError otherwise or when no sample lies at or after t_from.
FlowBalance flow_balance(const std::vector<double>& t, const std::vector<std::int64_t>& cumulative_in,
                         const std::vector<std::int64_t>& cumulative_out, double t_from);

}  // namespace nipdem::analysis
