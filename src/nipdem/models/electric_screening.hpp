// Electric screening (thesis §2.5.4): which particles feel the electric force of the drum.
//
// A particle is "printable" (is a capacitor to the drum, feels eq. 2.5.31) iff
//  (1) its surface is within `range_m` (d50, §2.5.4 / §2.5.5) of the drum surface, and
//  (2) no other particle is placed between it and the drum.
// "Between" is defined here as: another disc j intersects the corridor from the particle
// centre p to its foot point f on the drum surface (the nearest drum point), widened to a
// half-width w = corridor_fraction * r_p, i.e. the rectangle {p + s n + t n_perp :
// 0 < s < |f - p|, |t| <= w} with n the unit normal from p towards the drum. With the
// default corridor_fraction = 0 this is the line of sight from the centre to the foot point.
// corridor_fraction must be < 1: at 1 a touching neighbour in the same layer at the drum
// (slightly overlapping, as DEM contacts are) would screen its neighbour, which is wrong.
// See docs/electric.md for the justification.
//
// Drum: a circle (centre, radius) with the toner outside it, or locally a plane (a point on
// it and the unit normal pointing into the toner). Distances in metres.
#pragma once
#include <span>

#include "nipdem/core/vec2.hpp"

namespace nipdem::electric {

struct Disc {
  Vec2 centre;
  double radius = 0.0;  // [m]
};

struct DrumSurface {
  enum class Kind { circle, plane };
  Kind kind = Kind::circle;
  Vec2 point;          // circle centre, or a point on the plane [m]
  double radius = 0.0; // circle radius [m] (circle only)
  Vec2 normal{0, 1};   // unit normal into the toner (plane only)
  static DrumSurface circle(Vec2 centre, double radius);
  static DrumSurface plane(Vec2 point, Vec2 normal_into_toner);
};

struct ScreeningParams {
  double range_m = 10.5e-6;        // d50 of black toner (Table 2.1) [m]
  double corridor_fraction = 0.0;  // w / r_p in [0, 1)
  void validate() const;           // InputError naming "electric screening" and the key
};

struct ScreeningResult {
  double gap_m = 0.0;      // surface distance l from the particle to the drum [m] (< 0: overlap)
  Vec2 foot;               // nearest point on the drum surface
  Vec2 normal;             // unit vector from the particle centre towards the drum
  bool within_range = false;
  bool screened = false;
  int screened_by = -1;    // index in `others` of the first screening disc, -1 if none
  bool printable() const { return within_range && !screened; }
};

// `others` are candidate neighbours (e.g. from the neighbour list); an entry at index
// `self_index` (if >= 0) is skipped. Discs are only tested when within_range is true.
ScreeningResult screening(const Disc& particle, const DrumSurface& drum, std::span<const Disc> others,
                          const ScreeningParams& p, int self_index = -1);

// True if disc `d` intersects the corridor of `particle` towards `foot` (see above).
bool blocks_corridor(const Disc& particle, Vec2 foot, const Disc& d, double half_width);

// How far from a particle's centre a disc that screens it can be centred, when the particle is
// within range and both radii are <= r_max_m: the corridor (length gap + r_p <= range + r_max,
// half-width w < r_max) widened by the disc's radius on both sides, range + 4 r_max [m]. A
// caller may leave out discs farther than this (ElectricForce: along x) and get the same flag.
double screening_reach(const ScreeningParams& p, double r_max_m);

}  // namespace nipdem::electric
