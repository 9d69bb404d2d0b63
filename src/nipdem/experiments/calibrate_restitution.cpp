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

// Step size: resolves both the flight time and the Stokes relaxation time.
double step_for(const DragModel& d, double height) {
  const double beta = d.mass_kg / (6.0 * constants::pi * d.viscosity_Pa_s * d.radius_m);
  const double g = d.gravity_m_per_s2;
  const double T = std::max(std::sqrt(2.0 * height / g), height / (beta * g));
  return std::min(beta / 20.0, T / 4000.0);
}

// Integrates until event(state) <= 0 and returns the state at the event (bisected step).
template <class Ev>
YV integrate_to(const DragModel& d, YV s, double dt, Ev event) {
  for (long n = 0; n < 100000000L; ++n) {
    const YV next = rk4(d, s, dt);
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
  throw std::runtime_error("drop test integration did not reach its event");
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
  {
    const DragModel d{r.mass_kg, p.radius_m, p.viscosity_Pa_s, p.air_density_kg_per_m3, g, true};
    const double vi = fall_speed_numeric(d, p.y0_m);
    double lo = 0.0, hi = std::sqrt(2.0 * g * p.y1_m);
    while (rise_height_numeric(d, hi) < p.y1_m) hi *= 2.0;
    for (int i = 0; i < 60 && hi - lo > 1e-13 * hi; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (rise_height_numeric(d, mid) < p.y1_m) lo = mid;
      else hi = mid;
    }
    r.restitution_schiller_naumann = 0.5 * (lo + hi) / vi;
  }
  return r;
}

}  // namespace nipdem::calibrate
