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

// `force dipole` -- the one check and computation of the CLI command and of Python's
// nipdem.force_dipole (fields in the order of their arguments).
struct DipoleQuery {
  double moment_Am2 = 3.7e-11;  // the moment's size [A m^2]; its direction is angle_deg
  double distance_m = 13e-6;    // centre distance [m]
  double angle_deg = 0.0;       // field angle to the line of centres [deg]
  double radius_m = 6e-6;       // toner radius [m]
  int pigments = 1, samples = 1000;
  std::uint64_t seed = 1;
};
struct DipoleAnswer {
  PigmentStudyResult study;
  double cherry_pit_force_N = 0;  // eq. 2.4.39 with both moments at the centres, for comparison
};
// Checks (InputError naming `force dipole` and the option: --moment in (0, 1e-3] A m^2,
// --distance in [1e-9, 1] m, --radius in [1e-9, 1e-2] m, --distance > 2 x --radius, --angle in
// [-5e4, 5e4] deg, --pigments in [1, 1e6], --samples in [1, 1e7] (also with one pigment),
// pigments^2 x samples <= 1e9 (about 10 s)), then runs pigment_study; a force that is not
// finite is refused too.
DipoleAnswer force_dipole_query(const DipoleQuery& q);

}  // namespace nipdem::dipole
