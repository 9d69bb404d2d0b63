// The pigment study of thesis §2.4.2 (figs. 2.13-2.15): force between two magnetised toner spheres
// whose total moment is carried by n point pigments, compared with one central "cherry-pit" dipole.
//
// Two spheres of radius R have their centres on the x axis a distance d apart (d > 2R). Each holds
// n pigments of moment m/n, all along the external field direction (cos theta, sin theta, 0). For
// n = 1 the pigment sits at the centre (cherry pit); for n > 1 the pigments are placed independently
// and uniformly in the sphere volume (point pigments may coincide: overlap between pigments does not
// matter for point dipoles, and pigment pairs inside one sphere exert no net force on it). The force
// on sphere 2 is the sum of eq. 2.4.39 over all n^2 pigment pairs.
//
// Expectation: the mean of the force over placements equals the cherry-pit force exactly (the field
// of a uniformly distributed dipole density in a sphere is, outside it, that of the central dipole,
// and the pigment positions in the two spheres are independent). The spread shrinks as 1/sqrt(n).
#pragma once
#include <cstdint>

#include "nipdem/models/dipole.hpp"

namespace nipdem::dipole {

struct PigmentStudyParams {
  double moment_Am2 = 3.7e-11;  // total moment m of one toner [A m^2] (§2.4.2)
  double radius_m = 6e-6;       // toner radius R [m]
  double distance_m = 13e-6;    // centre distance d [m], must exceed 2R
  double angle_rad = 0.0;       // field angle theta to the line of centres [rad]
  int pigments = 1;             // n pigments per toner; 1 = cherry pit (at the centre)
  int samples = 1000;           // random placements to average over (ignored for n = 1)
  std::uint64_t seed = 1;
};

struct PigmentStudyResult {
  double force_mean_abs_N = 0;  // mean of |F| over placements (the quantity plotted in fig. 2.14)
  double force_std_N = 0;       // standard deviation of |F| over placements (0 for n = 1)
  Vec3 force_mean_N;            // mean force vector on sphere 2
  double force_mean_vec_abs_N = 0;  // |mean force vector|
  Vec3 force_vec_std_N;         // standard deviation of each component
  int samples = 0;
};

// Throws InputError for d <= 2R, non-positive m or R, n < 1 or n > 1e6, samples < 1, n^2*samples > 1e11.
PigmentStudyResult pigment_study(const PigmentStudyParams& p);

}  // namespace nipdem::dipole
