#include "nipdem/models/magnetisation.hpp"

#include <cmath>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"

namespace nipdem::magnet {

MagnetisationParams black_toner() { return {4.50e5, 0.15, 0.135}; }
MagnetisationParams color_toner() { return {1.65e6, 0.65, 0.025}; }

void validate(const MagnetisationParams& p, const std::string& where) {
  require_positive(where, "Ms_A_per_m", p.Ms_A_per_m);
  require_range(where, "Ms_A_per_m", p.Ms_A_per_m, 0.0, 1e7);
  require_positive(where, "B_sat_T", p.B_sat_T);
  require_range(where, "B_sat_T", p.B_sat_T, 0.0, 10.0);
  require_positive(where, "eta", p.eta);
  require_range(where, "eta", p.eta, 0.0, 1.0);
}

Vec2 magnetisation(const MagnetisationParams& p, Vec2 B) {
  const double b = norm(B);
  if (b == 0.0) return {0.0, 0.0};
  // Linear part: M = Ms B / B_sat; saturated part: M = Ms B/|B|.
  const double scale = b < p.B_sat_T ? p.Ms_A_per_m / p.B_sat_T : p.Ms_A_per_m / b;
  return scale * B;
}

double saturation_moment(const MagnetisationParams& p, double radius_m) {
  return 4.0 / 3.0 * constants::pi * radius_m * radius_m * radius_m * p.eta * p.Ms_A_per_m;
}

double equal_volume_radius(std::span<const double> member_radii_m) {
  if (member_radii_m.empty()) throw_input("equal_volume_radius", "member_radii_m", "[]", "needs at least one sphere");
  double v = 0.0;
  for (double r : member_radii_m) {
    require_positive("equal_volume_radius", "member_radius_m", r);
    v += r * r * r;
  }
  return std::cbrt(v);
}

}  // namespace nipdem::magnet
