#include "nipdem/models/electric_force.hpp"

#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"

namespace nipdem::electric {
namespace {

constexpr const char* kWhere = "electric force";

// g(x) = x coth(x) - 1 without cancellation for small x (Taylor series, Bernoulli numbers).
double xcothx_minus_1(double x) {
  if (x < 0.1) {
    const double x2 = x * x;
    return x2 * (1.0 / 3 + x2 * (-1.0 / 45 + x2 * (2.0 / 945 + x2 * (-1.0 / 4725 + x2 * (2.0 / 93555)))));
  }
  return x / std::tanh(x) - 1.0;
}

// csch(x) for x > 0 without overflow.
double csch(double x) {
  const double e = std::exp(-x);
  return 2.0 * e / (1.0 - e * e);
}

double alpha_of(double R, double d) {
  // cosh(alpha) = 1 + d/R; acosh(1+t) = log1p(t + sqrt(t(t+2))) is accurate for small t.
  const double t = d / R;
  return std::log1p(t + std::sqrt(t * (t + 2.0)));
}

void check_geometry(double R, double V, double d) {
  require_positive(kWhere, "radius", R);
  require_positive(kWhere, "gap", d);
  if (!std::isfinite(V)) throw_input(kWhere, "voltage", fmt::format("{:g}", V), "must be finite", "(-inf, inf)");
}

constexpr double kEulerGamma = 0.57721566490153286;
constexpr double kAsymptoteBelow = 1e-6;  // two-term asymptote error < 1e-12 there (docs/electric.md)

// Dimensionless exact force f(x) = F / (eps0 V^2), x = d/R.
double exact_dimensionless(double x) {
  if (x < kAsymptoteBelow) {
    // The series would need ~37/sqrt(2x) > 2.6e7 terms; its small-gap expansion is exact to
    // O(x ln x) absolute, i.e. < 1e-12 relative here.
    const double c0 = std::log(2.0) / 3.0 + 2.0 * kEulerGamma / 3.0 - 1.0 / 9.0;
    return constants::pi * (1.0 / x - std::log(1.0 / x) / 3.0 - c0);
  }
  const double a = std::log1p(x + std::sqrt(x * (x + 2.0)));
  const double ga = xcothx_minus_1(a);
  double s = 0.0;
  for (long n = 2;; ++n) {
    const double na = static_cast<double>(n) * a;
    const double term = csch(na) * (xcothx_minus_1(na) - ga);  // > 0
    s += term;
    if (term <= 1e-17 * s || na > 745.0) break;
  }
  return 2.0 * constants::pi * s / a;
}

}  // namespace

ForceModel parse_force_model(const std::string& name, const std::string& where, const std::string& key) {
  if (name == "exact") return ForceModel::exact;
  if (name == "series") return ForceModel::series;
  if (name == "approx") return ForceModel::approx;
  throw_input(where, key, name, "unknown electric force model", "exact, series, approx");
}

const char* to_string(ForceModel m) {
  switch (m) {
    case ForceModel::exact: return "exact";
    case ForceModel::series: return "series";
    case ForceModel::approx: return "approx";
  }
  return "?";
}

void ElectricForceParams::validate() const { require_positive(kWhere, "approx_coefficient", approx_coefficient); }

double sphere_plane_capacitance(double R, double d) {
  require_positive(kWhere, "radius", R);
  require_positive(kWhere, "gap", d);
  const double a = alpha_of(R, d);
  double s = 0.0;
  for (long n = 1;; ++n) {
    const double na = static_cast<double>(n) * a;
    const double term = csch(na);
    s += term;
    if (term <= 1e-17 * s || na > 745.0) break;
  }
  return 4.0 * constants::pi * constants::eps0 * R * std::sinh(a) * s;
}

double force_exact(double R, double V, double d) {
  check_geometry(R, V, d);
  return constants::eps0 * V * V * exact_dimensionless(d / R);
}

double force_series_as_printed(double R, double V, double d) {
  check_geometry(R, V, d);
  // eta0 from sinh(eta0) = a/R, a = sqrt((d + 2R) d)  (text below eq. 2.5.11).
  const double eta = alpha_of(R, d);
  const double ch = std::cosh(eta), sh = std::sinh(eta);
  double F2 = 0.0, F3 = 0.0;
  for (long n = 0;; ++n) {
    const double m = static_cast<double>(n) + 0.5;
    const double c0 = 1.0 / std::tanh(m * eta), c1 = 1.0 / std::tanh((m + 1.0) * eta);
    const double e0 = std::exp(-m * eta), e1 = std::exp(-(m + 1.0) * eta);
    // eq. 2.5.40
    const double t2 = c0 * e0 * e0 * sh * (static_cast<double>(n) * std::exp(eta) - (n + 1.0) * std::exp(-eta));
    // eq. 2.5.41
    const double t3 = c0 * e0 * (-m * c0 * e0 + (n + 1.0) * ch * c1 * e1);
    F2 += t2;
    F3 += t3;
    if (n > 4 && std::fabs(t2) + std::fabs(t3) <= 1e-17 * std::fabs(F2 + F3)) break;
    if (m * eta > 745.0) break;
  }
  // eq. 2.5.31 with F1 = 0 (eq. 2.5.34)
  return 4.0 * constants::pi * constants::eps0 * V * V * (F2 + F3);
}

double force_series(double R, double V, double d) { return -0.5 * force_series_as_printed(R, V, d); }

double force_approx(double R, double V, double d, double a) {
  check_geometry(R, V, d);
  require_positive(kWhere, "approx_coefficient", a);
  return a * 4.0 * constants::pi * constants::eps0 * R * V * V / d;
}

double force(const ElectricForceParams& p, double R, double V, double d) {
  switch (p.model) {
    case ForceModel::exact: return force_exact(R, V, d);
    case ForceModel::series: return force_series(R, V, d);
    case ForceModel::approx: return force_approx(R, V, d, p.approx_coefficient);
  }
  return 0.0;
}

double effective_gap(double l, double layer_thickness, double eps_r) {
  require_range(kWhere, "distance", l, 0.0, std::numeric_limits<double>::infinity());
  require_range(kWhere, "layer_thickness", layer_thickness, 0.0, std::numeric_limits<double>::infinity());
  require_positive(kWhere, "layer_permittivity", eps_r);
  return l + layer_thickness / eps_r;
}

double force_bulk(double R, double V, double alpha, double layer_thickness, double eps_r) {
  require_positive(kWhere, "radius", R);
  require_positive(kWhere, "packing_alpha", alpha);
  require_positive(kWhere, "layer_thickness", layer_thickness);
  require_positive(kWhere, "layer_permittivity", eps_r);
  return eps_r * constants::eps0 * alpha * R * R * V * V / (layer_thickness * layer_thickness);
}

double force_bulk_corrected(double R, double V, double alpha, double layer_thickness, double eps_r) {
  return 0.5 * force_bulk(R, V, alpha, layer_thickness, eps_r);
}

double force_small_gap_asymptote(double R, double V, double d, bool leading_only) {
  check_geometry(R, V, d);
  const double k = constants::pi * constants::eps0 * V * V;
  if (leading_only) return k * R / d;
  const double c0 = std::log(2.0) / 3.0 + 2.0 * kEulerGamma / 3.0 - 1.0 / 9.0;
  return k * (R / d - std::log(R / d) / 3.0 - c0);
}

double force_large_gap_asymptote(double R, double V, double d) {
  check_geometry(R, V, d);
  const double D = R + d;
  return constants::pi * constants::eps0 * R * R * V * V / (D * D) * (1.0 + R / D);
}

ElectricForceTable::ElectricForceTable(double x_min, double x_max, int nodes) {
  if (!(x_min > 0.0 && x_max > x_min && nodes >= 8)) {
    throw_input("electric force table", "range", fmt::format("[{:g}, {:g}] with {} nodes", x_min, x_max, nodes),
                "invalid table", "0 < x_min < x_max, nodes >= 8");
  }
  lx0_ = std::log(x_min);
  dlx_ = (std::log(x_max) - lx0_) / (nodes - 1);
  std::vector<double> ext(nodes + 4);
  for (int i = 0; i < nodes + 4; ++i) ext[i] = std::log(exact_dimensionless(std::exp(lx0_ + (i - 2) * dlx_)));
  lf_.resize(nodes);
  dlf_.resize(nodes);
  for (int i = 0; i < nodes; ++i) {
    const int j = i + 2;
    lf_[i] = ext[j];
    // 5-point central difference, O(h^4).
    dlf_[i] = (ext[j - 2] - 8.0 * ext[j - 1] + 8.0 * ext[j + 1] - ext[j + 2]) / (12.0 * dlx_);
  }
}

double ElectricForceTable::dimensionless(double x) const {
  const double lx = std::log(x);
  const double u = (lx - lx0_) / dlx_;
  const int n = static_cast<int>(lf_.size());
  if (!(u >= 0.0) || u >= n - 1) return exact_dimensionless(x);
  const int i = static_cast<int>(u);
  const double t = u - i, t2 = t * t, t3 = t2 * t;
  const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
  const double lf = h00 * lf_[i] + h10 * dlx_ * dlf_[i] + h01 * lf_[i + 1] + h11 * dlx_ * dlf_[i + 1];
  return std::exp(lf);
}

double ElectricForceTable::force(double R, double V, double d) const {
  return constants::eps0 * V * V * dimensionless(d / R);
}

ForceAnswer force_query(const ForceQuery& q) {
  const std::string w = "force electric";
  ForceAnswer a;
  a.params.model = parse_force_model(q.model, w, "--model");
  const double coef = q.approx_coefficient.value_or(kThesisApproxCoefficient);
  a.layer_thickness_m = q.layer_thickness_m.value_or(kSiOxThickness_m);
  a.layer_permittivity = q.layer_permittivity.value_or(kSiOxPermittivity);
  // An option that would have no effect is refused rather than silently ignored.
  if (q.approx_coefficient && a.params.model != ForceModel::approx)
    throw_input(w, "--approx-coefficient", fmt::format("{:g}", coef), fmt::format("has no effect with --model {}", to_string(a.params.model)),
                "--approx-coefficient with --model approx");
  const auto no_layer = [&](const char* key, const std::optional<double>& v, const std::string& text) {
    if (v && !q.dielectric_layer)
      throw_input(w, key, text.empty() ? fmt::format("{:g}", *v) : text, "has no effect without --dielectric-layer",
                  std::string(key) + " together with --dielectric-layer");
  };
  no_layer("--layer-thickness", q.layer_thickness_m, q.layer_thickness_text);
  no_layer("--layer-permittivity", q.layer_permittivity, q.layer_permittivity_text);
  // Physical ranges (far beyond toner's: R ~ 5 um, l ~ 1 um, 40 V, a = 0.45, SiOx 600 nm with
  // eps_r = 5), so that no result overflows into null (issue 21); named by option.
  require_range(w, "--radius", q.radius_m, 1e-9, 1e-2);
  require_range(w, "--gap", q.gap_m, 1e-12, 1.0);
  require_range(w, "--voltage", q.voltage_V, -1e6, 1e6);
  require_range(w, "--approx-coefficient", coef, 1e-3, 100.0);
  if (q.dielectric_layer) {
    require_range(w, "--layer-thickness", a.layer_thickness_m, 0.0, 1e-2);
    require_range(w, "--layer-permittivity", a.layer_permittivity, 1.0, 1e5);
  }
  a.params.approx_coefficient = coef;
  a.params.validate();
  const double R = q.radius_m, V = q.voltage_V;
  const double d = q.dielectric_layer ? effective_gap(q.gap_m, a.layer_thickness_m, a.layer_permittivity) : q.gap_m;
  a.effective_gap_m = d;
  a.force_N = force(a.params, R, V, d);
  a.force_exact_N = force_exact(R, V, d);
  if (!std::isfinite(a.force_N) || !std::isfinite(a.force_exact_N))  // not reached within the ranges above
    throw_input(w, "--radius, --gap, --voltage, --approx-coefficient, --layer-thickness, --layer-permittivity",
                fmt::format("{:g} m, {:g} m, {:g} V, {:g}, {:g} m, {:g}", R, q.gap_m, V, coef, a.layer_thickness_m, a.layer_permittivity),
                "the force is not representable for these inputs");
  a.force_small_gap_limit_N = force_small_gap_asymptote(R, V, d, true);
  a.capacitance_F = sphere_plane_capacitance(R, d);
  return a;
}

}  // namespace nipdem::electric
