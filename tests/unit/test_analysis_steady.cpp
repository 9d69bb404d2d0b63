// Steady-state detection of a time signal (e.g. front position vs time, thesis §5.1).
#include <gtest/gtest.h>

#include <cmath>

#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/analysis/steady.hpp"

using namespace nipdem;
using namespace nipdem::analysis;

namespace {
struct Signal {
  std::vector<double> t, y;
};
// y = a + b exp(-t/tau) + slope t + sigma * noise, n samples on [0, T).
Signal make(double a, double b, double tau, double slope, double sigma, double T, int n, std::uint64_t seed) {
  Signal s;
  Rng r(seed);
  for (int i = 0; i < n; ++i) {
    const double t = T * i / n;
    s.t.push_back(t);
    s.y.push_back(a + b * std::exp(-t / tau) + slope * t + sigma * r.normal());
  }
  return s;
}
}  // namespace

TEST(AnalysisSteady, ExponentialApproachFindsValueAndOnset) {
  // y = 1 + 2 exp(-t/tau) + N(0, 0.05^2), tau = 1, t in [0, 30). The transient falls below the
  // noise level at t = tau ln(2/0.05) = 3.7; with 20 batches of 1.5 tau the MSER onset must
  // fall between 1.5 tau (one batch) and 9 tau (transient < 2.5e-4, far below the noise).
  // Value: standard error 0.05/sqrt(2700) = 1e-3 plus the leftover transient after the onset
  // (< 2 e^-1.5 / 28 = 0.016 at the earliest allowed onset), so 0.02 is a safe tolerance, and
  // the fluctuation std must be the noise sigma within 10 % (2700 samples: std uncertain by 1.4 %
  // plus the leftover transient).
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const Signal s = make(1.0, 2.0, 1.0, 0.0, 0.05, 30.0, 3000, seed);
    const SteadyState r = detect_steady_state(s.t, s.y);
    ASSERT_TRUE(r.steady) << r.reason;
    EXPECT_NEAR(r.value, 1.0, 0.02);
    EXPECT_GE(r.t_onset, 1.5);
    EXPECT_LE(r.t_onset, 9.0);
    EXPECT_NEAR(r.std, 0.05, 0.005);
    EXPECT_GT(r.stderr_mean, 0.0);
    EXPECT_LT(r.stderr_mean, 0.005);
    std::printf("[ info ] seed %llu: steady value %.4f +- %.4f, std %.4f, onset t = %.2f tau, drift z %.2f\n",
                static_cast<unsigned long long>(seed), r.value, r.stderr_mean, r.std, r.t_onset, r.drift_z);
  }
}

TEST(AnalysisSteady, StationaryNoiseIsSteadyFromTheStart) {
  // No transient: MSER must keep (almost) everything: onset within the first quarter.
  const Signal s = make(-3.0, 0.0, 1.0, 0.0, 0.2, 10.0, 2000, 11);
  const SteadyState r = detect_steady_state(s.t, s.y);
  ASSERT_TRUE(r.steady) << r.reason;
  EXPECT_LE(r.t_onset, 2.5);
  EXPECT_NEAR(r.value, -3.0, 5 * 0.2 / std::sqrt(1500.0));  // 5 standard errors
}

TEST(AnalysisSteady, RampIsNotSteady) {
  // A pure ramp never stops drifting, with or without noise.
  for (double sigma : {0.0, 0.05, 1.0}) {
    const Signal s = make(0.0, 0.0, 1.0, 0.1, sigma, 30.0, 3000, 5);
    const SteadyState r = detect_steady_state(s.t, s.y);
    EXPECT_FALSE(r.steady) << "sigma " << sigma;
    EXPECT_NE(r.reason.find("drifting"), std::string::npos) << r.reason;
  }
  // A transient that lasts the whole record (tau = T) is not steady either.
  const Signal s = make(1.0, 2.0, 30.0, 0.0, 0.01, 30.0, 3000, 6);
  EXPECT_FALSE(detect_steady_state(s.t, s.y).steady);
}

TEST(AnalysisSteady, DriftToleranceAcceptsSmallKnownDrift) {
  // A slow ramp of 1e-3 over the record is statistically detectable with tiny noise, but
  // accepted when the caller allows 0.01 absolute drift.
  const Signal s = make(5.0, 0.0, 1.0, 1e-3 / 30.0, 1e-4, 30.0, 3000, 8);
  EXPECT_FALSE(detect_steady_state(s.t, s.y).steady);
  SteadyOptions o;
  o.drift_tolerance = 0.01;
  EXPECT_TRUE(detect_steady_state(s.t, s.y, o).steady);
}

TEST(AnalysisSteady, ShortSignalAndBadInput) {
  const SteadyState r = detect_steady_state({0, 1, 2}, {1, 1, 1});
  EXPECT_FALSE(r.steady);
  EXPECT_NE(r.reason.find("too short"), std::string::npos);
  EXPECT_THROW(detect_steady_state({0, 1}, {1}), InputError);
  EXPECT_THROW(detect_steady_state({0, 2, 1}, {1, 1, 1}), InputError);
  SteadyOptions o;
  o.n_batches = 2;
  EXPECT_THROW(detect_steady_state({0, 1}, {1, 1}, o), InputError);
}

// Particle balance of an open region: a Poisson stream of rate lambda enters, each particle
// stays exactly tau and leaves. Over [t0, T] with t0 >= tau the region is full: outflow equals
// inflow up to the stream's shot noise (expected in and out differ by a few sqrt(lambda tau)).
// From t0 = 0 it is filling for the first tau: outflow/inflow = (T - tau) / T.
TEST(AnalysisFlowBalance, PoissonStreamWithFixedResidenceTime) {
  const double lambda = 2e4, tau = 2e-3, T = 20e-3, dt = 1e-4;  // 20 per 0.1 ms, 40 inside
  Rng r(17);
  std::vector<double> arrivals;
  for (double ta = 0.0;;) {
    ta += -std::log(1.0 - r.uniform(0.0, 1.0)) / lambda;
    if (ta > T) break;
    arrivals.push_back(ta);
  }
  std::vector<double> t;
  std::vector<std::int64_t> in, out;
  for (int k = 0; k * dt <= T + 1e-12; ++k) {
    const double now = k * dt;
    t.push_back(now);
    std::int64_t a = 0, l = 0;
    for (double ta : arrivals) {
      if (ta <= now) ++a;
      if (ta + tau <= now) ++l;
    }
    in.push_back(a);
    out.push_back(l);
  }
  const FlowBalance full = flow_balance(t, in, out, tau);
  const double n = static_cast<double>(full.inflow);
  EXPECT_NEAR(n, lambda * (T - tau), 4.0 * std::sqrt(lambda * (T - tau)));  // 4 sigma
  // in - out over the full part = content(T) - content(tau), two nearly independent Poisson(40)
  // counts (18 ms apart, residence 2 ms): std sqrt(2 lambda tau) ~ 8.9; 4 sigma
  EXPECT_LE(std::abs(full.inflow - full.outflow), 4.0 * std::sqrt(2.0 * lambda * tau));
  EXPECT_NEAR(full.outflow_over_inflow, 1.0, 4.0 * std::sqrt(2.0 * lambda * tau) / n);
  EXPECT_NEAR(full.growth_per_s, 0.0, 4.0 * std::sqrt(2.0 * lambda * tau) / (T - tau));
  const FlowBalance filling = flow_balance(t, in, out, 0.0);
  // outflow / inflow from 0 = the fraction of the ~400 arrivals that came before T - tau:
  // binomial, p = 0.9, std sqrt(p (1 - p) / 400) = 0.015; 4 sigma
  const double p = (T - tau) / T;
  EXPECT_NEAR(filling.outflow_over_inflow, p, 4.0 * std::sqrt(p * (1.0 - p) / static_cast<double>(filling.inflow)));
  EXPECT_NEAR(filling.growth_per_s, lambda * tau / T, 4.0 * std::sqrt(lambda * tau) / T);
  EXPECT_DOUBLE_EQ(filling.t_from, 0.0);
  EXPECT_DOUBLE_EQ(filling.t_to, t.back());
}

TEST(AnalysisFlowBalance, EmptyStreamAndBadInput) {
  const FlowBalance b = flow_balance({0.0, 1.0, 2.0}, {5, 5, 5}, {0, 0, 0}, 0.5);
  EXPECT_EQ(b.inflow, 0);
  EXPECT_TRUE(std::isnan(b.outflow_over_inflow));
  EXPECT_DOUBLE_EQ(b.t_from, 1.0);
  EXPECT_THROW(flow_balance({0.0, 1.0}, {0}, {0, 0}, 0.0), InputError);          // lengths
  EXPECT_THROW(flow_balance({0.0, 1.0}, {3, 2}, {0, 0}, 0.0), InputError);       // count decreases
  EXPECT_THROW(flow_balance({1.0, 0.0}, {0, 0}, {0, 0}, 0.0), InputError);       // time backwards
  EXPECT_THROW(flow_balance({0.0, 1.0}, {0, 1}, {0, 0}, 2.0), InputError);       // nothing after t_from
}
