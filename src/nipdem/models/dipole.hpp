// Magnetic dipole-dipole interaction between magnetised toner particles (thesis §2.4.2,
// eqs. 2.4.38-2.4.39), "cherry-pit" model: each toner is one point dipole at its centre carrying the
// particle's whole moment (eq. 4.5.1).
//
// Field of dipole m_j at r_j:   B(r) = mu0/(4 pi) [3 r (m_j.r)/|r|^5 - m_j/|r|^3],  r = x - r_j (2.4.38)
// Force on m_i at r_i:          F_i = (m_i . grad) B_j(r_i)                                    (2.4.39)
//                                   = 3 mu0/(4 pi r^4) [(m_i.e) m_j + (m_j.e) m_i + (m_i.m_j) e
//                                                       - 5 (m_i.e)(m_j.e) e],   e = r/|r|
// Energy:                       U = mu0/(4 pi r^3) [m_i.m_j - 3 (m_i.e)(m_j.e)],   F_i = -grad_{r_i} U
//
// Units: m [A m^2], r [m], B [T], F [N], U [J]. These are 3D sphere formulas; in the 2D engine the
// centres and moments lie in the plane (z = 0), so Vec2 carries them exactly.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "nipdem/core/vec2.hpp"
#include "nipdem/models/magnet_field.hpp"

namespace nipdem::dipole {

// Force on dipole m_i [A m^2] from dipole m_j, r_ij = r_i - r_j [m] (non-zero). Returns N.
// Newton's third law holds exactly: dipole_force(m_j, m_i, -r) = -dipole_force(m_i, m_j, r).
Vec2 dipole_force(Vec2 m_i, Vec2 m_j, Vec2 r_ij);
// Interaction energy [J] of the pair (eq. 2.4.38 with U = -m_i . B_j).
double dipole_energy(Vec2 m_i, Vec2 m_j, Vec2 r_ij);
// Field B [T] and gradient [T/m] of dipole m [A m^2] at displacement r [m] from it (eq. 2.4.38),
// in the plane of the moment. Summing these over neighbours gives B_a of eq. 2.4.33.
magnet::Sample dipole_field(Vec2 m, Vec2 r);

// Same laws in 3D (used by the pigment study, where pigments fill the sphere volume).
struct Vec3 {
  double x = 0, y = 0, z = 0;
};
// Force [N] on m_i from m_j, r_ij = r_i - r_j.
Vec3 dipole_force3(Vec3 m_i, Vec3 m_j, Vec3 r_ij);

// ---- sum over all pairs within a cut-off (the dipole-dipole pass of the nip) ----------------
// F_i = sum over j != i with |r_i - r_j| < r_c of dipole_force(m_i, m_j, r_i - r_j)   (eq. 2.4.39)
//
// PairSum evaluates this with a persistent Verlet pair list: pairs closer than r_c + skin are
// listed once (half list, Newton's third law: each pair force is computed once and added to
// i, subtracted from j), and the list is reused until the two largest displacements since it
// was built add up to more than the skin, or the caller says the particle set changed. Every
// pass still tests |r| < r_c exactly, so the result is the plain cut-off sum: the list only
// saves the search.
// A pair (a < b) is listed in row a if a + b is even, else in row b, so rows are balanced
// whatever the particle order; rows are sorted by partner index and the rows are split
// between threads by index (not by list content). The summation order therefore depends only
// on the particles and the thread count, never on when the list was built: a run restored
// from a checkpoint (the list is not saved; it is rebuilt at the first pass) is bitwise
// identical to an uninterrupted one. Units: positions [m], moments [A m^2], forces [N].
// sort_row: the partners cand[0, m) (distinct indices) of row `row` in ascending order. Those
// within +-2048 of the row are marked in `bits` (all clear before and after) and read back in
// order; a row with one farther away is sorted. Particles in spatial order have their partners
// near their own index, and a sort of ~30 numbers per row was ~40 % of a list build (the edge
// study's profile).
using RowSortBits = std::array<std::uint64_t, 64>;
void sort_row(int* cand, int m, int row, RowSortBits& bits);

struct PairSumParams {
  double cutoff_m = 42e-6;  // r_c
  double skin_m = 2e-6;     // list reach beyond r_c
  int threads = 1;          // OpenMP threads (results are bitwise reproducible per thread count)
};

class PairSum {
 public:
  explicit PairSum(PairSumParams p = {});
  // Forces on every particle into fx, fy (resized to n). same_set = false when the particles
  // or their order changed since the last call (forces a rebuild). run_threads (1..threads;
  // 0 = threads) runs the `threads` parts on fewer threads, with the same sums.
  void compute(std::span<const double> x, std::span<const double> y, std::span<const Vec2> m, bool same_set,
               std::vector<double>& fx, std::vector<double>& fy, int run_threads = 0);
  void invalidate() { built_n_ = -1; }  // the next compute() rebuilds the list
  const PairSumParams& params() const { return p_; }
  int builds() const { return builds_; }
  std::size_t listed_pairs() const { return nbr_.size(); }

 private:
  void rebuild(std::span<const double> x, std::span<const double> y, int run);  // rows in `run` parts (same list)
  bool moved(std::span<const double> x, std::span<const double> y) const;
  PairSumParams p_;
  long built_n_ = -1;
  int builds_ = 0;
  std::vector<int> row_start_, nbr_;       // CSR half list
  std::vector<double> x0_, y0_;            // positions at the last build
  struct alignas(32) Packed { double x, y, mx, my; };
  std::vector<Packed> pk_;                 // per pass: centre and moment of every particle
  std::vector<std::vector<double>> buf_;   // per-part force buffers (fx, fy interleaved)
  // per part: the particles [lo, hi) its rows write to (its own and their partners), found at
  // the first pass after each list build; only these of its buffer are cleared and read
  std::vector<int> part_lo_, part_hi_;
  int reach_builds_ = -1;
  long reach_n_ = -1;
  struct Binned { double x, y; int index; };  // a particle in cell order
  std::vector<int> cell_start_, cell_fill_, cell_of_;  // cell-list scratch (counting sort)
  std::vector<Binned> binned_;
  // rebuild(): one part's rows. On cache lines of its own: its vectors' ends and max_row are
  // written at every row, and parts run on different threads (no false sharing).
  struct alignas(64) BuildPart {
    std::vector<int> nbr, cand;
    int max_row = 0;
    RowSortBits bits{};  // sort_row's scratch, all clear between rows
  };
  std::vector<BuildPart> parts_;
  int max_row_ = 0;                        // longest row of the list
  // Per part: one row's partners within r_c (separation, moment, index) and their forces
  struct alignas(64) RowScratch { std::vector<double> dx, dy, mx, my, gx, gy; std::vector<int> j; };
  std::vector<RowScratch> rows_;
};

// The same sum by testing all N(N-1)/2 pairs (reference for tests).
void brute_force_pair_sum(std::span<const double> x, std::span<const double> y, std::span<const Vec2> m, double cutoff_m,
                          std::vector<double>& fx, std::vector<double>& fy);

// ---- cut-off -------------------------------------------------------------------------------
// The pair force decays as r^-4 and its angular factor averages to zero over a uniform ring, so in a
// homogeneous packing the tail beyond r_c cancels on average; what remains comes from density
// fluctuations and free surfaces. cutoff_radius() returns a conservative r_c from the worst case that
// all neighbours beyond r_c pull the same way, at area number density n = phi/(pi R^2) and contact
// distance 2R:
//     |F_tail| / |F_contact| <= integral_{rc}^inf (2R/r)^4 n 2 pi r dr = 16 phi R^2 / r_c^2,
// so r_c = 4 R sqrt(phi / rel_tol). For phi = 0.8, rel_tol = 0.01 this gives r_c = 36 R; the measured
// error (measure_cutoff_truncation, docs/magnetic.md) is far below this bound at much smaller r_c.
double cutoff_radius(double radius_m, double packing_fraction, double rel_tol);

// Truncation error of a cut-off on a random dense 2D packing of equal discs (radius R) that all carry
// the same moment m (uniform external field at angle `field_angle_rad`).
struct TruncationStats {
  double cutoff_m = 0;           // r_c tested
  double mean_rel_error = 0;     // mean over probe particles of |F_rc - F_ref| / |F_ref|
  double p95_rel_error = 0;      // 95th percentile of the same
  double max_rel_error = 0;      // largest
  double mean_rel_to_contact = 0;  // mean |F_rc - F_ref| / F_c, F_c = 6 mu0 m^2/(4 pi (2R)^4) (head-to-tail at contact)
  int probes = 0;                // number of probe particles (well inside the box)
};
struct TruncationSetup {
  double radius_m = 5.25e-6;       // disc radius R
  double packing_fraction = 0.75;  // area fraction of the packing (random, relaxed to small overlap)
  double box_m = 600e-6;           // side of the (periodic during relaxation) square box
  double reference_cutoff_m = 250e-6;  // "exact" force = sum over neighbours within this radius
  double probe_radius_m = 40e-6;   // probes are particles within this distance of the box centre
  double field_angle_rad = 0.0;    // direction of all moments
  std::uint64_t seed = 1;
};
// Returns one entry per cut-off in `cutoffs_m`. Throws InputError if the box cannot hold the probe
// region plus the reference radius, or if parameters are out of range.
std::vector<TruncationStats> measure_cutoff_truncation(const TruncationSetup& s, const std::vector<double>& cutoffs_m);

// Random dense packing used by measure_cutoff_truncation (exposed for tests): N = phi L^2/(pi R^2)
// random centres in a periodic box of side L, relaxed by pairwise overlap removal until the largest
// overlap is below 1 % of R or 400 sweeps have run (at phi = 0.75 the sweeps run out with the largest
// overlap ~2 % of R, irrelevant for point dipoles).
std::vector<Vec2> random_dense_packing(double radius_m, double packing_fraction, double box_m, std::uint64_t seed);

}  // namespace nipdem::dipole
