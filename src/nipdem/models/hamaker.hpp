// Hamaker adhesion/cohesion between two spheres, thesis eq. 2.3.2:
//   F = A R1 R2 / (12 (R1 + R2) d^2),  A = Hamaker coefficient [J], radii [m], d [m].
// The thesis takes d = centre distance. We offer that ("centre") and the physically usual
// surface separation regularised by a minimum separation D0 ("surface", the default):
//   d = max(s, 0) + D0,  s = |x1 - x2| - R1 - R2 (negative while the contact overlaps),
// so the force is finite in contact and falls as 1/s^2 outside it. Beyond the cut-off
// separation s_cut the force is zero. For a wall, R2 -> infinity: F = A R1 / (12 d^2).
// See docs/adhesion.md for the choice and its consequences.
#pragma once
#include <cmath>
#include <limits>

namespace nipdem::models {

struct HamakerParams {
  enum class Distance { surface, centre };
  double hamaker_J = 0.0;         // A [J]; 0 switches adhesion off
  double min_separation_m = 4e-10;  // D0 [m] (surface mode)
  double cutoff_m = 4e-9;         // s_cut [m]: no force for surface separation s > s_cut
  Distance distance = Distance::surface;
};

// Effective radius R1 R2 / (R1 + R2); R2 = +inf gives R1 (wall).
inline double effective_radius(double r1, double r2) {
  const double both = r1 * r2 / (r1 + r2);  // (NaN for a wall, then not selected)
  return std::isinf(r2) ? r1 : both;
}

// Attractive force magnitude [N] at surface separation s [m] (s < 0: overlapping) between
// spheres of radii r1, r2 (r2 may be +inf for a wall). Returns 0 beyond the cut-off.
inline double hamaker_force(const HamakerParams& p, double r1, double r2, double s) {
  // Every branch is computed and one selected (no branch on the data): the engine's batched
  // pair kernel evaluates this for several pairs per instruction (engine/kernels.hpp).
  const double d_surface = (s > 0.0 ? s : 0.0) + p.min_separation_m;
  const double d_centre = std::isinf(r2) ? s + r1  // centre-to-wall distance
                                         : s + r1 + r2;  // centre-to-centre distance
  const double d = p.distance == HamakerParams::Distance::surface ? d_surface : d_centre;
  const double f = p.hamaker_J * effective_radius(r1, r2) / (12.0 * d * d);
  return (p.hamaker_J == 0.0 || s > p.cutoff_m) ? 0.0 : f;
}

// Potential energy [J] whose negative derivative w.r.t. s is -hamaker_force (attractive),
// for s outside the contact (s >= 0) and below the cut-off; used by energy tests.
inline double hamaker_energy(const HamakerParams& p, double r1, double r2, double s) {
  if (p.hamaker_J == 0.0 || s > p.cutoff_m) return 0.0;
  double d;
  if (p.distance == HamakerParams::Distance::surface) d = (s > 0.0 ? s : 0.0) + p.min_separation_m;
  else d = std::isinf(r2) ? s + r1 : s + r1 + r2;
  return -p.hamaker_J * effective_radius(r1, r2) / (12.0 * d);
}

// Hamaker coefficient that gives force F at contact (s = 0) for the radii given (inverse of
// eq. 2.3.2); lets users specify adhesion by a force, as the thesis calibrates it (§4.6).
inline double hamaker_for_contact_force(const HamakerParams& p, double r1, double r2, double force) {
  const double d = p.distance == HamakerParams::Distance::surface
                       ? p.min_separation_m
                       : (std::isinf(r2) ? r1 : r1 + r2);
  return force * 12.0 * d * d / effective_radius(r1, r2);
}

}  // namespace nipdem::models
