// Verlet neighbour list built with a cell list (discs binned by a counting sort), so building and using
// it costs O(N). Half list in CSR form: row i holds neighbours j > i sorted by j, each with
// its contact history (tangential stretch, sliding flag) so the pair loop has no lookups.
// History survives rebuilds and renumbering (bodies removed/added): see rebuild().
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace nipdem::geometry {

// A disc position the cell list cannot bin: not finite, or so far from the others that the cell
// indices would overflow (more than kMaxCellsPerAxis cells of 2 r_max + skin between them). The
// state has blown up; rebuild() refuses it instead of binning garbage (UB) or looping.
class BadPositionError : public std::runtime_error {
 public:
  BadPositionError(std::size_t disc, double x, double y, const std::string& what)
      : std::runtime_error(what), disc_(disc), x_(x), y_(y) {}
  std::size_t disc() const { return disc_; }
  double x() const { return x_; }
  double y() const { return y_; }

 private:
  std::size_t disc_;
  double x_, y_;
};

struct NeighborListParams {
  double skin = 1e-6;           // extra distance beyond the interaction range [m]
  double extra_range = 0.0;     // interaction range beyond touching (adhesion cut-off) [m]
  bool periodic_x = false;      // minimum-image convention along x
  double x_lo = 0.0, x_hi = 0.0;  // periodic box along x [m] (used if periodic_x)
  int threads = 1;              // OpenMP threads for the row search (same list for any count)
};

class NeighborList {
 public:
  // Rebuilds the list for discs at (x, y) with radii r; body[i] == body[j] pairs are skipped
  // (discs of one rigid cluster never interact). old_of_new[i] is the index disc i had at the
  // previous build (-1 if new); history of pairs present in both lists is carried over.
  // Pass an empty span if no disc was renumbered since the last build.
  // half_skin (optional, one per disc, each >= 0 and finite): skins of their own. Pair (i, j)
  // is then listed within r_i + r_j + extra + h_i + h_j, and the list holds while no disc has
  // moved farther than its own h_i (track(), needs_rebuild()): a fast disc can be given a wide
  // skin without widening everyone's. Empty: the one skin p.skin, with the two-largest criterion.
  // Throws BadPositionError (list unchanged) for a position that cannot be binned (see there).
  // No exception leaves the parallel row search: one thrown there (bad_alloc) is rethrown after it.
  void rebuild(std::span<const double> x, std::span<const double> y, std::span<const double> r,
               std::span<const int> body, std::span<const int> old_of_new, const NeighborListParams& p,
               std::span<const double> half_skin = {});

  // True if the list may miss a pair: the two largest displacements since the last build
  // add up to more than the skin (no two discs can then have closed the skin between them;
  // a plain max > skin/2 test rebuilds up to twice as often when a few discs move fast); with
  // skins per disc, some disc moved farther than its own.
  bool needs_rebuild(std::span<const double> x, std::span<const double> y) const;

  // Per-disc squared displacement since the last build, for fused loops that track the two
  // largest themselves (then exceeds()). Requires size() == number of discs.
  double displacement2(std::size_t i, double x, double y) const {
    double dx = x - x0_[i];
    const double dy = y - y0_[i];
    if (params_.periodic_x) {  // a disc that crossed the periodic boundary moved by about +-L
      const double L = params_.x_hi - params_.x_lo;
      dx = dx > 0.5 * L ? dx - L : dx;
      dx = dx < -0.5 * L ? dx + L : dx;
    }
    return dx * dx + dy * dy;
  }
  // True if the two largest squared displacements d1 >= d2 call for a rebuild.
  bool exceeds(double d1, double d2) const { return std::sqrt(d1) + std::sqrt(d2) > skin_; }
  // Folds disc i at (x, y) into the running (d1, d2) that exceeds() then judges: its squared
  // displacement into the top two, or with skins per disc, infinity if it moved beyond its own.
  void track(std::size_t i, double x, double y, double& d1, double& d2) const {
    const double d = displacement2(i, x, y);
    if (inv_h2_.empty()) top2(d, d1, d2);
    else if (!(d * inv_h2_[i] <= 1.0)) d1 = std::numeric_limits<double>::infinity();  // (NaN too)
  }
  bool per_disc() const { return !inv_h2_.empty(); }
  // With skins per disc: 1 / h_i^2 per disc, and the positions at the last build, for fused
  // loops that judge the displacements themselves (a disc moved too far: d^2 / h_i^2 > 1).
  const double* inv_skin2() const { return inv_h2_.data(); }
  const double* x0() const { return x0_.data(); }
  const double* y0() const { return y0_.data(); }
  // The farthest disc i can move before the list must be rebuilt [m]: the skin (one disc may
  // use all of it while the others stand still), or its own skin.
  double max_move(std::size_t i) const { return inv_h2_.empty() ? skin_ : h_[i]; }
  // Discs searched beyond their 3 x 3 cells at the last build (their skins reach farther).
  std::size_t wide_discs() const { return wide_; }
  // Folds squared displacement d into the running top two (d1 >= d2). A NaN (a disc whose
  // position became NaN) counts as infinitely far, so that it forces a rebuild and rebuild()
  // refuses it; compared as NaN it would be dropped by the next comparison.
  static void top2(double d, double& d1, double& d2) {
    if (d != d) d = std::numeric_limits<double>::infinity();
    if (d > d2) {
      if (d > d1) { d2 = d1; d1 = d; } else { d2 = d; }
    }
  }
  // Cells along one axis beyond which a disc counts as flung away (BadPositionError): 2^30 cells
  // of ~10 um are ~10 km, far outside any nip; below it the cell count is capped (O(N) memory).
  static constexpr double kMaxCellsPerAxis = 1073741824.0;

  std::size_t size() const { return row_start_.empty() ? 0 : row_start_.size() - 1; }
  std::size_t pair_count() const { return nbr_.size(); }
  int builds() const { return builds_; }

  // CSR access.
  std::vector<int> row_start_;
  std::vector<int> nbr_;
  std::vector<double> eta_;
  std::vector<std::uint8_t> slide_;

 private:
  std::vector<double> x0_, y0_;  // positions at the last build
  std::vector<double> h_, inv_h2_;  // skins per disc and 1 / their squares (empty: one skin for all)
  std::size_t wide_ = 0;
  double skin_ = 0.0;
  NeighborListParams params_;
  int builds_ = 0;
  // scratch reused across builds (no per-step allocation)
  struct Binned { double x, y, r; int index, body; };  // a disc in cell order
  std::vector<int> cell_start_, cell_fill_, cell_of_, cell_last_;
  std::vector<Binned> binned_;
  std::vector<double> binned_h_;  // skins per disc, in cell order
  // pairs (i < j) found by the wide search of discs whose skins reach beyond their 3 x 3 cells,
  // in CSR by row i (merged into the rows by the row search)
  std::vector<std::pair<int, int>> wide_pairs_;
  std::vector<int> wide_start_, wide_nbr_;
  std::vector<int> new_start_, new_nbr_;
  std::vector<int> part_off_;  // where each thread's rows start in the joined list
  bool join_ok_ = false;       // (shared by the build's threads)
  std::vector<double> new_eta_;
  std::vector<std::uint8_t> new_slide_;
  // One thread's consecutive rows during a build. On cache lines of its own: the vectors' ends
  // are written at every pair, and two threads writing one line take it from each other at
  // every write (false sharing).
  struct alignas(64) Rows {
    std::vector<int> nbr, row;
    std::vector<double> eta;
    std::vector<std::uint8_t> slide;
  };
  std::vector<Rows> rows_;
};

}  // namespace nipdem::geometry
