#include "nipdem/experiments/calibrate_restitution.hpp"

#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <stdexcept>

#include "nipdem/core/error.hpp"

namespace nipdem::calibrate {

namespace {

// phi(tau) = e^-tau - 1 + tau, without cancellation for small tau.
double phi(double tau) {
  if (tau < 0.1) {
    // tau^2/2 - tau^3/6 + tau^4/24 - ...
    double term = tau * tau / 2.0, sum = 0.0;
    for (int k = 2; k < 40 && std::abs(term) > 1e-18 * std::abs(sum); ++k) {
      sum += term;
      term *= -tau / (k + 1);
    }
    return sum;
  }
  return std::expm1(-tau) + tau;
}
double dphi(double tau) { return -std::expm1(-tau); }  // 1 - e^-tau

// psi(x) = x - ln(1 + x), without cancellation for small x.
double psi(double x) {
  if (x < 0.1) {
    // x^2/2 - x^3/3 + x^4/4 - ...
    double pw = x * x, sum = 0.0;
    for (int k = 2; k < 80; ++k) {
      const double term = (k % 2 == 0 ? 1.0 : -1.0) * pw / k;
      sum += term;
      if (std::abs(term) < 1e-18 * std::abs(sum)) break;
      pw *= x;
    }
    return sum;
  }
  return x - std::log1p(x);
}
double dpsi(double x) { return x / (1.0 + x); }

// Solves f(z) = target for increasing convex f with f(0) = 0 by bracketing + Newton.
template <class F, class DF>
double solve_increasing(F f, DF df, double target, double z0) {
  double lo = 0.0, hi = std::max(z0, 1e-300);
  while (f(hi) < target) hi *= 2.0;
  double z = hi;
  for (int it = 0; it < 200; ++it) {
    const double fz = f(z) - target;
    if (fz > 0) hi = std::min(hi, z);
    else lo = std::max(lo, z);
    double zn = z - fz / df(z);
    if (!(zn > lo && zn < hi)) zn = 0.5 * (lo + hi);
    if (std::abs(zn - z) <= 1e-15 * std::abs(z)) return zn;
    z = zn;
  }
  return z;
}

struct YV {
  double y, v;
};

double drag_factor(const DragModel& d, double speed) {
  if (!d.schiller_naumann) return 1.0;
  const double re = d.air_density_kg_per_m3 * speed * 2.0 * d.radius_m / d.viscosity_Pa_s;
  return 1.0 + 0.15 * std::pow(re, 0.687);
}

YV rk4(const DragModel& d, YV s, double h) {
  const double c = 6.0 * constants::pi * d.viscosity_Pa_s * d.radius_m / d.mass_kg;
  auto f = [&](YV q) { return YV{q.v, -d.gravity_m_per_s2 - c * drag_factor(d, std::abs(q.v)) * q.v}; };
  const YV k1 = f(s);
  const YV k2 = f({s.y + 0.5 * h * k1.y, s.v + 0.5 * h * k1.v});
  const YV k3 = f({s.y + 0.5 * h * k2.y, s.v + 0.5 * h * k2.v});
  const YV k4 = f({s.y + h * k3.y, s.v + h * k3.v});
  return {s.y + h / 6 * (k1.y + 2 * k2.y + 2 * k3.y + k4.y), s.v + h / 6 * (k1.v + 2 * k2.v + 2 * k3.v + k4.v)};
}

// Flight time scale: the drag-free fall time or the fall at the Stokes terminal speed.
double time_scale(const DragModel& d, double height) {
  const double beta = d.mass_kg / (6.0 * constants::pi * d.viscosity_Pa_s * d.radius_m);
  const double g = d.gravity_m_per_s2;
  return std::max(std::sqrt(2.0 * height / g), height / (beta * g));
}

// Step size: resolves both the flight time and the Stokes relaxation time.
double step_for(const DragModel& d, double height) {
  const double beta = d.mass_kg / (6.0 * constants::pi * d.viscosity_Pa_s * d.radius_m);
  return std::min(beta / 20.0, time_scale(d, height) / 4000.0);
}

// Most RK4 steps one integration may take (~20 s); more means inputs far outside a drop test.
constexpr long kMaxSteps = 100000000L;

// Largest speed at which RK4 with step dt is still stable on the drag: the drag's rate
// d(c v f(Re))/dv = c (1 + 0.15 * 1.687 Re^0.687) times dt must stay <= 2.5 (RK4 is unstable
// from 2.79 on: the state oscillates, grows and ends in inf/NaN). Infinite for Stokes drag
// (dt c <= 1/20 by step_for) and without air.
double max_followed_speed(const DragModel& d, double dt) {
  const double k = d.air_density_kg_per_m3 * 2.0 * d.radius_m / d.viscosity_Pa_s;  // Re per speed
  if (!d.schiller_naumann || !(k > 0)) return std::numeric_limits<double>::infinity();
  const double c = 6.0 * constants::pi * d.viscosity_Pa_s * d.radius_m / d.mass_kg;
  const double re = std::pow((2.5 / (dt * c) - 1.0) / (0.15 * 1.687), 1.0 / 0.687);
  return re / k;
}

// Integrates until event(state) <= 0 and returns the state at the event (bisected step).
// Throws IntegrationLimit when the state leaves what the step can follow or the event is not
// reached within kMaxSteps (results are unchanged wherever the integration succeeds).
template <class Ev>
YV integrate_to(const DragModel& d, YV s, double dt, Ev event) {
  const double v_max = max_followed_speed(d, dt);
  if (!(std::abs(s.v) <= v_max))
    throw IntegrationLimit(fmt::format("speed {:g} m/s: the drag is too stiff for the integration step", s.v));
  for (long n = 0; n < kMaxSteps; ++n) {
    const YV next = rk4(d, s, dt);
    if (!(std::abs(next.v) <= v_max) || !std::isfinite(next.y))
      throw IntegrationLimit(fmt::format("speed {:g} m/s: the drag is too stiff for the integration step", next.v));
    if (event(next) <= 0) {
      double lo = 0, hi = dt;
      for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (event(rk4(d, s, mid)) > 0) lo = mid;
        else hi = mid;
      }
      return rk4(d, s, 0.5 * (lo + hi));
    }
    s = next;
  }
  throw IntegrationLimit(fmt::format("drop test integration did not reach its event within {} steps", kMaxSteps));
}

}  // namespace

double fall_speed_numeric(const DragModel& d, double y0) {
  const YV impact = integrate_to(d, {y0, 0.0}, step_for(d, y0), [](YV s) { return s.y; });
  return -impact.v;
}

double rise_height_numeric(const DragModel& d, double v_up) {
  if (v_up <= 0) return 0.0;
  const double h_est = v_up * v_up / (2.0 * d.gravity_m_per_s2);
  return integrate_to(d, {0.0, v_up}, step_for(d, h_est), [](YV s) { return s.v; }).y;
}

DropTestResult drop_test_restitution(const DropTestParams& p) {
  const std::string where = "calibrate restitution";
  const double inf = std::numeric_limits<double>::infinity();
  require_positive(where, "y0", p.y0_m);
  require_positive(where, "y1", p.y1_m);
  if (p.y1_m > p.y0_m)
    throw_input(where, "y1", fmt::format("{:g}", p.y1_m),
                fmt::format("rebound higher than the drop height y0 = {:g} m (e_n > 1 is unphysical)", p.y0_m),
                fmt::format("(0, {:g}]", p.y0_m));
  require_positive(where, "radius", p.radius_m);
  require_positive(where, "density", p.density_kg_per_m3);
  require_positive(where, "viscosity", p.viscosity_Pa_s);
  require_positive(where, "gravity", p.gravity_m_per_s2);
  require_range(where, "air_density", p.air_density_kg_per_m3, 0.0, inf);

  const double g = p.gravity_m_per_s2;
  DropTestResult r;
  r.mass_kg = 4.0 / 3.0 * constants::pi * std::pow(p.radius_m, 3) * p.density_kg_per_m3;
  r.beta_s = r.mass_kg / (6.0 * constants::pi * p.viscosity_Pa_s * p.radius_m);
  const double beta = r.beta_s;
  r.terminal_speed_m_per_s = beta * g;
  r.restitution_no_drag = std::sqrt(p.y1_m / p.y0_m);
  r.impact_speed_no_drag_m_per_s = std::sqrt(2.0 * g * p.y0_m);

  // Fall: beta^2 g phi(tau) = y0.
  const double bbg = beta * beta * g;
  const double tau0 = std::sqrt(2.0 * p.y0_m / g) / beta;  // drag-free fall time / beta
  const double tau = solve_increasing(phi, dphi, p.y0_m / bbg, tau0);
  r.fall_time_s = tau * beta;
  r.impact_speed_m_per_s = beta * g * dphi(tau);

  // Rise: y1 = beta^2 g psi(v_f / (beta g)).
  const double x0 = std::sqrt(2.0 * g * p.y1_m) / (beta * g);
  const double x = solve_increasing(psi, dpsi, p.y1_m / bbg, x0);
  r.rebound_speed_m_per_s = x * beta * g;
  r.rise_time_s = beta * std::log1p(x);
  r.restitution = r.rebound_speed_m_per_s / r.impact_speed_m_per_s;
  r.reynolds_at_impact = p.air_density_kg_per_m3 * r.impact_speed_m_per_s * 2.0 * p.radius_m / p.viscosity_Pa_s;
  if (r.restitution > 1.0)
    throw_input(where, "y1", fmt::format("{:g}", p.y1_m),
                fmt::format("with Stokes drag this rebound needs e_n = {:.4f} > 1 (energy gain); check y0, y1 and the "
                            "drag parameters",
                            r.restitution));
  // Schiller–Naumann cross-check: solve rise_height(v_f) = y1 for v_f by bisection.
  // Inputs it cannot integrate (a fall of more than 5e6 relaxation times, or speeds at which the
  // drag is too stiff for the explicit step) are refused naming the options, never a null result.
  const DragModel d{r.mass_kg, p.radius_m, p.viscosity_Pa_s, p.air_density_kg_per_m3, g, true};
  const std::string keys = "--y0, --y1, --radius, --density, --viscosity, --gravity, --air-density";
  const double fall_steps = time_scale(d, p.y0_m) / step_for(d, p.y0_m);
  if (!(fall_steps <= static_cast<double>(kMaxSteps)))
    throw_input(where, keys, "",
                fmt::format("the Schiller-Naumann cross-check would need {:.3g} integration steps for the fall "
                            "(fall time {:.3g} s, relaxation time beta = {:.3g} s)",
                            fall_steps, time_scale(d, p.y0_m), beta),
                fmt::format("a drop test whose fall needs at most {:g} steps (fall time / beta <= 5e6)",
                            static_cast<double>(kMaxSteps)));
  try {
    const double vi = fall_speed_numeric(d, p.y0_m);
    double lo = 0.0, hi = std::sqrt(2.0 * g * p.y1_m);
    while (rise_height_numeric(d, hi) < p.y1_m) hi *= 2.0;
    for (int i = 0; i < 60 && hi - lo > 1e-13 * hi; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (rise_height_numeric(d, mid) < p.y1_m) lo = mid;
      else hi = mid;
    }
    r.restitution_schiller_naumann = 0.5 * (lo + hi) / vi;
  } catch (const IntegrationLimit& e) {
    throw_input(where, keys, "",
                fmt::format("the Schiller-Naumann cross-check cannot be integrated ({}; Reynolds number at impact {:.3g})",
                            e.what(), r.reynolds_at_impact),
                "a drop test the explicit integration can follow (a smaller Reynolds number: lower --air-density, "
                "higher --viscosity or a shorter fall)");
  }
  if (!std::isfinite(r.restitution_schiller_naumann))
    throw_input(where, keys, "", "the Schiller-Naumann cross-check gives no finite restitution",
                "a drop test the explicit integration can follow");
  return r;
}

}  // namespace nipdem::calibrate
