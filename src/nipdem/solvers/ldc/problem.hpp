// Problem description for the Local Defect Correction (LDC) electrostatic solver (thesis §3.2,
// eq. 3.2.1): Laplace's equation in a rectangle with Dirichlet/Neumann sides and any number of
// floating conducting discs, each with a prescribed charge q (integrated flux condition) and an
// unknown constant potential g.
//
// This is a truly 2D problem: a "disc" is the cross-section of an infinitely long cylinder, so
// charges are per unit length [C/m] and forces per unit length [N/m] (see docs/ldc.md).
//
// Sign convention (physical, Gauss): -eps * \oint du/dn ds = q with n pointing away from the disc
// into the field region, i.e. a positive charge has a potential that decreases outward. (The
// thesis mixes orientations: eq. 3.4.3 uses du/dr, eq. 3.8.1 the normal of Ω; verify.cpp says
// which reading reproduces its tables.)
#pragma once
#include <span>
#include <string>
#include <vector>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/vec2.hpp"

namespace nipdem::ldc {

enum class SideKind { dirichlet, neumann };

// Boundary condition on one side of the box: u = value_V (Dirichlet) or du/dn = 0 (Neumann).
struct SideCondition {
  SideKind kind = SideKind::dirichlet;
  double value_V = 0.0;
};

// A floating conductor seen by the solver: only position, radius and charge per unit length.
struct Disc {
  Vec2 center_m;
  double radius_m = 0.0;
  double charge_C_per_m = 0.0;
};

// How the local problem around a disc is solved (§3.4, §3.9, §3.10).
enum class LocalMethod { analytic, schwarz, finite_difference };
const char* to_string(LocalMethod m);

struct Params {
  // Rectangle [x_min, x_max] x [y_min, y_max] [m] and its coarse grid (cells_x x cells_y cells).
  double x_min_m = 0.0, x_max_m = 1.0, y_min_m = 0.0, y_max_m = 1.0;
  int cells_x = 20, cells_y = 20;
  SideCondition bottom, top, left, right;  // y = y_min, y = y_max, x = x_min, x = x_max
  double permittivity_F_per_m = constants::eps0;
  // Local domain radius R2 = max(local_radius_factor * R1, R1 + local_min_cells * H).
  double local_radius_factor = 3.0;
  double local_min_cells = 2.0;
  // Shrink annuli to d/2 between neighbours when that keeps R2 >= R1 + local_min_cells * H, so
  // that overlapping (Schwarz) groups only form where annuli would otherwise be too thin.
  bool prefer_separate_annuli = true;
  // Samples 2N+1 of u on each circle Γ (eqs. 3.4.4-3.4.5): about this many per coarse cell length.
  double gamma_points_per_cell = 1.0;
  // Fine grid of finite-difference local problems: h = H / fd_refinement, raised automatically so
  // that every disc radius spans at least fd_min_points_per_radius fine cells.
  int fd_refinement = 4;
  double fd_min_points_per_radius = 4.0;
  // Safety region width eps [m] (eq. 3.2.7-3.2.8): no defect at coarse nodes closer than this to Γ.
  double safety_m = 0.0;
  // LDC stops when the change of all disc potentials and of the coarse solution on every Γ
  // between two iterations is below tolerance * (potential scale of the problem).
  double tolerance = 1e-8;
  int max_iterations = 200;
  // Aitken extrapolation of the LDC iteration when it converges with a steady factor (dense
  // configurations, docs/ldc.md). Off reproduces the plain iteration of §3.2.
  bool aitken = true;
  int schwarz_max_iterations = 500;
  double schwarz_tolerance = 1e-12;  // relative to the potential scale
  double initial_potential_V = 0.0;   // u_guess of eq. 3.2.2 for a cold start
  // true: coarse nodes inside a disc are Dirichlet nodes u = g (eq. 3.2.2, as in the thesis);
  // the coarse problem then learns the charge only through g, and the iteration converges with
  // the factor log(R3/R2)/log(R3/R1) of §3.7, slow when the box is large (R3 >> R2).
  // false: they are ordinary coarse unknowns carrying the defect of the local solution (= g
  // inside the disc), so the defect holds the whole charge from the first correction and the
  // monopole error disappears in one step; the coarse matrix never changes (docs/ldc.md).
  bool dirichlet_conductor_nodes = false;
  // Force the finite-difference local solution for every disc (testing); default: automatic.
  bool force_finite_difference = false;

  double hx() const { return (x_max_m - x_min_m) / cells_x; }
  double hy() const { return (y_max_m - y_min_m) / cells_y; }
};

// Ranges of the problem's scales checked by validate() / validate_discs(). SI units, but wide
// enough for dimensionless problems (ε = 1, unit box, q ~ 1: the verification problems). Inside
// them every potential, field and force of a solve is far from overflow or underflow.
inline constexpr double kMaxCoordinate_m = 1e3;      // |box corner|
inline constexpr double kMinBox_m = 1e-9;            // box width and height
inline constexpr double kMinPermittivity = 1e-12;    // F/m (vacuum: 8.854e-12)
inline constexpr double kMaxPermittivity = 1e3;      // F/m
inline constexpr double kMaxPotential_V = 1e9;       // |Dirichlet side value|
inline constexpr double kMaxCharge_C_per_m = 1e3;    // |disc charge per unit length|
inline constexpr double kMinRadius_m = 1e-9;         // disc radius

// Throws InputError naming the key for an invalid grid/box/parameter.
void validate(const Params& p);
// Throws InputError for discs outside the box, overlapping discs, non-positive radius or
// non-finite values.
void validate_discs(const Params& p, std::span<const Disc> discs);

}  // namespace nipdem::ldc
