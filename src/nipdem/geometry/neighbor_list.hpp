// Verlet neighbour list built with a cell list (linked-cell binning), so building and using
// it costs O(N). Half list in CSR form: row i holds neighbours j > i sorted by j, each with
// its contact history (tangential stretch, sliding flag) so the pair loop has no lookups.
// History survives rebuilds and renumbering (bodies removed/added): see rebuild().
#pragma once
#include <cstdint>
#include <span>
#include <vector>

namespace nipdem::geometry {

struct NeighborListParams {
  double skin = 1e-6;           // extra distance beyond the interaction range [m]
  double extra_range = 0.0;     // interaction range beyond touching (adhesion cut-off) [m]
  bool periodic_x = false;      // minimum-image convention along x
  double x_lo = 0.0, x_hi = 0.0;  // periodic box along x [m] (used if periodic_x)
};

class NeighborList {
 public:
  // Rebuilds the list for discs at (x, y) with radii r; body[i] == body[j] pairs are skipped
  // (discs of one rigid cluster never interact). old_of_new[i] is the index disc i had at the
  // previous build (-1 if new); history of pairs present in both lists is carried over.
  // Pass an empty span if no disc was renumbered since the last build.
  void rebuild(std::span<const double> x, std::span<const double> y, std::span<const double> r,
               std::span<const int> body, std::span<const int> old_of_new, const NeighborListParams& p);

  // True if some disc moved more than skin/2 since the last build (then rebuild()).
  bool needs_rebuild(std::span<const double> x, std::span<const double> y) const;

  // Per-disc form of needs_rebuild() for fused loops: true if disc i, now at (x, y), moved
  // more than skin/2 since the last build. Requires size() == number of discs.
  bool moved(std::size_t i, double x, double y) const {
    double dx = x - x0_[i];
    const double dy = y - y0_[i];
    if (params_.periodic_x) {  // a disc that crossed the periodic boundary moved by about +-L
      const double L = params_.x_hi - params_.x_lo;
      dx = dx > 0.5 * L ? dx - L : dx;
      dx = dx < -0.5 * L ? dx + L : dx;
    }
    return dx * dx + dy * dy > half_skin2_;
  }

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
  double half_skin2_ = 0.0;
  NeighborListParams params_;
  int builds_ = 0;
  // scratch reused across builds (no per-step allocation)
  std::vector<int> cell_head_, cell_next_;
  std::vector<int> new_start_, new_nbr_;
  std::vector<double> new_eta_;
  std::vector<std::uint8_t> new_slide_;
};

}  // namespace nipdem::geometry
