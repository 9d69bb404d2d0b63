// Magnetisation curve of magnetisable toner and its induced dipole moment (thesis §2.4.2, §4.5).
//
// The VSM hysteresis curves of the pigments (fig. 4.20) show almost no hysteresis; §4.5 replaces
// them by a linear part and a constant (saturated) part. We read Table 2.2's "saturation magnetic
// flux" B_sat as the EXTERNAL flux density at which the linear part reaches saturation (it is not
// mu0*Ms; see docs/magnetic.md and PHYSICS-NOTES.md):
//
//   M(B) = Ms * min(|B| / B_sat, 1) * B/|B|                      [A/m]
//   m(B) = (4/3) pi R^3 eta M(B)                                  [A m^2]   (eq. 4.5.1)
//
// The moment is induced along the external field B (isotropic pigment, no remanence).
// Per §4.5 the curve is a function of the external field only: in a dense packing the field of
// the surrounding toner is already contained in the bulk VSM curve, so B here is the magnet field.
#pragma once
#include <span>
#include <string>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/vec2.hpp"

namespace nipdem::magnet {

// Magnetic properties of one toner kind.
struct MagnetisationParams {
  double Ms_A_per_m = 4.50e5;  // saturation magnetisation of the pigment [A/m] (Table 2.2)
  double B_sat_T = 0.15;       // external flux density at which the pigment saturates [T] (Table 2.2)
  double eta = 0.135;          // volume fraction of magnetic pigment in the toner [-] (Table 2.1)
};

// Black toner: iron-oxide FO2 (Fe3O4), eta = 13.5 % (Tables 2.1, 2.2).
MagnetisationParams black_toner();
// Colour toner: carbonyl iron caFe, eta = 2.5 % (Tables 2.1, 2.2).
MagnetisationParams color_toner();

// Throws InputError naming `where` and the key when a parameter is out of its physical range:
// Ms in (0, 1e7] A/m (pure iron is 1.7e6), B_sat in (0, 10] T, eta in (0, 1].
void validate(const MagnetisationParams& p, const std::string& where = "magnetisation");

// Magnetisation vector M(B) [A/m]; zero for B = 0.
Vec2 magnetisation(const MagnetisationParams& p, Vec2 B);

// Moment at saturation (4/3) pi R^3 eta Ms [A m^2] of a sphere of radius R [m] (eq. 4.5.1).
double saturation_moment(const MagnetisationParams& p, double radius_m);

// Induced moment m(B) of a sphere of radius R [m] in the external field B [T] (eq. 4.5.1).
inline Vec2 induced_moment(const MagnetisationParams& p, double radius_m, Vec2 B) {
  return (4.0 / 3.0) * constants::pi * radius_m * radius_m * radius_m * p.eta * magnetisation(p, B);
}

// Radius of the sphere whose volume equals the summed volume of the member spheres of a cluster,
// R = (sum r_k^3)^(1/3) [m]. Overlap between members is ignored (the cluster's mass is also the sum
// of its spheres), so a 3-disc toner of member radius r has R = 3^(1/3) r. Use it as the R of
// eq. 4.5.1 for a clustered toner particle; the moment acts at the cluster's centre of mass.
// Throws InputError for an empty list or a non-positive radius.
double equal_volume_radius(std::span<const double> member_radii_m);

}  // namespace nipdem::magnet
