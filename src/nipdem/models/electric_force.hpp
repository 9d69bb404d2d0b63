// Electric (Coulomb) force on a grounded conducting sphere near a plate on voltage V,
// thesis §2.5.2–§2.5.4. All functions are pure; inputs in SI units.
//
// Geometry (thesis fig. 2.20): sphere radius R [m], gap d [m] between the sphere surface
// and the plate, plate potential V [V] relative to the (grounded) sphere. Only the
// potential difference matters, so this is the sphere–plane capacitor problem; the force
// is attractive (towards the plate) for either sign of V and scales as eps0*V^2*f(d/R).
//
// Models (ForceModel):
//  - exact : capacitance-coefficient series F = 1/2 V^2 |dC/dD| with
//            C = 4 pi eps0 R sinh(alpha) sum_{n>=1} csch(n alpha), cosh(alpha) = (R+d)/R,
//            which gives F = 2 pi eps0 V^2 sum_{n>=2} csch(n alpha) [n coth(n alpha) - coth(alpha)].
//            Every term is positive; the difference in brackets is formed without
//            cancellation. Summed to relative 1e-15 (about 37/alpha terms).
//  - series: the thesis bispherical series eqs. 2.5.31, 2.5.40, 2.5.41, with the
//            misprint corrected: as printed, 4 pi eps0 V^2 (F1+F2+F3) equals -2 x the
//            exact force (the Maxwell-stress factor 1/2 is missing in eq. 2.5.24 and the
//            sign is the x-component, x pointing from the plate to the sphere). The
//            corrected form is F = -2 pi eps0 V^2 (F2 + F3). See docs/electric.md.
//  - approx: eq. 2.5.42, F = a 4 pi eps0 R V^2 / d with a = 0.45 (thesis).
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace nipdem::electric {

enum class ForceModel { exact, series, approx };

// "exact" | "series" | "approx"; throws InputError naming `where`/`key` otherwise.
ForceModel parse_force_model(const std::string& name, const std::string& where = "electric force",
                             const std::string& key = "model");
const char* to_string(ForceModel m);

// Thesis eq. 2.5.42 coefficient.
inline constexpr double kThesisApproxCoefficient = 0.45;
// SiOx layer of the DI drum (§2.5.1): thickness [m] and relative permittivity [-].
inline constexpr double kSiOxThickness_m = 600e-9;
inline constexpr double kSiOxPermittivity = 5.0;

struct ElectricForceParams {
  ForceModel model = ForceModel::exact;
  double approx_coefficient = kThesisApproxCoefficient;  // a of eq. 2.5.42 [-]
  // Throws InputError naming "electric force" and the key if out of range.
  void validate() const;
};

// Sphere–plane capacitance [F] (sphere and grounded plane), radius R [m], gap d [m] > 0.
double sphere_plane_capacitance(double R, double d);

// Magnitudes of the attractive force [N] for radius R [m] > 0, plate voltage V [V], gap d [m] > 0.
double force_exact(double R, double V, double d);
double force_series(double R, double V, double d);  // thesis series, corrected (see above)
double force_approx(double R, double V, double d, double a = kThesisApproxCoefficient);

// Thesis eqs. 2.5.31 + 2.5.40 + 2.5.41 evaluated exactly as printed (signed; equals
// -2 * force_exact). Kept only to document and test the misprint.
double force_series_as_printed(double R, double V, double d);

// Dispatch on params.model; validates R > 0, d > 0, V finite (InputError otherwise).
double force(const ElectricForceParams& p, double R, double V, double d);

// Eq. 2.5.43: effective gap d = l + d_l / eps_r [m] for a particle whose surface is at
// distance l [m] >= 0 from the dielectric surface of the drum.
double effective_gap(double l, double layer_thickness = kSiOxThickness_m, double eps_r = kSiOxPermittivity);

// Eq. 2.5.10 (bulk estimate) as printed: F = eps_r eps0 alpha R^2 V^2 / d_l^2 [N]; alpha =
// 2 sqrt(3) for a dense (hexagonal) packing, 4 for a square packing. Like eq. 2.5.24 it uses
// sigma*E; the Maxwell stress on a conductor bounded by the dielectric is (1/2) sigma E, so
// force_bulk_corrected = force_bulk / 2 (docs/electric.md).
double force_bulk(double R, double V, double alpha = 3.4641016151377544, double layer_thickness = kSiOxThickness_m,
                  double eps_r = kSiOxPermittivity);
double force_bulk_corrected(double R, double V, double alpha = 3.4641016151377544,
                            double layer_thickness = kSiOxThickness_m, double eps_r = kSiOxPermittivity);

// Small-gap asymptote (d << R): F = pi eps0 V^2 [R/d - ln(R/d)/3 - c0],
// c0 = ln(2)/3 + 2 gamma/3 - 1/9 (derived in docs/electric.md). leading_only drops the
// last two terms (F = pi eps0 R V^2 / d, the proximity/parallel-plate limit).
double force_small_gap_asymptote(double R, double V, double d, bool leading_only = false);
// Large-gap limit (d >> R): sphere charge q = 4 pi eps0 R V and its image,
// F = pi eps0 R^2 V^2 / D^2 (1 + R/D), D = R + d the centre–plate distance.
double force_large_gap_asymptote(double R, double V, double d);

// `force electric` -- the one check and computation of the CLI command and of Python's
// nipdem.force_electric. An empty optional is an option not given (its default applies); one
// given where it has no effect is refused, never ignored.
struct ForceQuery {
  double radius_m = 0, voltage_V = 0, gap_m = 0;
  std::string model = "exact";
  std::optional<double> approx_coefficient;  // [-], default kThesisApproxCoefficient; only with model approx
  bool dielectric_layer = false;             // gap_m is the distance l to the coated drum (eq. 2.5.43)
  std::optional<double> layer_thickness_m;   // [m], default kSiOxThickness_m; only with dielectric_layer
  std::optional<double> layer_permittivity;  // [-], default kSiOxPermittivity; only with dielectric_layer
  // --layer-thickness / --layer-permittivity as the user typed them, quoted by the "no effect"
  // message (the CLI's); empty: the value's {:g}.
  std::string layer_thickness_text, layer_permittivity_text;
};
struct ForceAnswer {
  ElectricForceParams params;
  double layer_thickness_m = 0, layer_permittivity = 0;  // as used (the defaults where not given)
  double effective_gap_m = 0;       // gap_m, or eq. 2.5.43 with the layer
  double force_N = 0;               // the model's
  double force_exact_N = 0;
  double force_small_gap_limit_N = 0;  // leading term
  double capacitance_F = 0;
};
// Checks (InputError naming `force electric` and the option: --model; --approx-coefficient,
// --layer-thickness, --layer-permittivity without effect; --radius in [1e-9, 1e-2] m, --gap in
// [1e-12, 1] m, --voltage in [-1e6, 1e6] V, --approx-coefficient in [1e-3, 100], with the layer
// --layer-thickness in [0, 1e-2] m and --layer-permittivity in [1, 1e5]), then computes; a
// result that is not finite is refused too.
ForceAnswer force_query(const ForceQuery& q);

// Tabulated exact force for the engine's inner loop: F = eps0 V^2 f(d/R) with log f
// interpolated by cubic Hermite in log(d/R) on [x_min, x_max]; outside the table range
// it falls back to force_exact. Relative error < 1e-9 with the default 4000 nodes.
class ElectricForceTable {
 public:
  explicit ElectricForceTable(double x_min = 1e-4, double x_max = 1e3, int nodes = 4000);
  double force(double R, double V, double d) const;
  double dimensionless(double x) const;  // f(x) = F / (eps0 V^2)

 private:
  double lx0_, dlx_;
  std::vector<double> lf_, dlf_;  // log f and d(log f)/d(log x) at the nodes
};

}  // namespace nipdem::electric
