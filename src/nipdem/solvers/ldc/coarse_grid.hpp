// Global coarse grid of the LDC method (thesis eqs. 3.2.2-3.2.3, 3.2.6-3.2.7): a uniform node grid
// on the box, the standard five-point Laplacian with central differences (Neumann sides by
// mirroring), and a direct solver that is factorised once and reused for every right-hand side.
//
// Why a factorised sparse Cholesky (Eigen SimplicialLDLT) and not multigrid: the LDC iteration
// solves the same coarse matrix 10-30 times per field solve, and in a DEM the matrix only changes
// when a coarse node enters or leaves a disc. A back-substitution on the grids used here
// (<= 320x320 nodes) costs less than one multigrid V-cycle would, and the factorisation is
// amortised; docs/ldc.md gives the measurement (bench_ldc prints it).
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "nipdem/core/vec2.hpp"
#include "nipdem/solvers/ldc/problem.hpp"

namespace nipdem::ldc {

class CoarseGrid {
 public:
  explicit CoarseGrid(const Params& p);

  int nx() const { return nx_; }  // nodes in x (cells_x + 1)
  int ny() const { return ny_; }
  int size() const { return nx_ * ny_; }
  double hx() const { return hx_; }
  double hy() const { return hy_; }
  int index(int i, int j) const { return j * nx_ + i; }
  Vec2 node(int i, int j) const { return {x0_ + i * hx_, y0_ + j * hy_}; }
  Vec2 node(int n) const { return node(n % nx_, n / nx_); }
  Vec2 lower() const { return {x0_, y0_}; }
  Vec2 upper() const { return {x0_ + (nx_ - 1) * hx_, y0_ + (ny_ - 1) * hy_}; }
  const Params& params() const { return p_; }

  // Box boundary: -1 free (interior or Neumann side), otherwise this node has Dirichlet value
  // box_value(n).
  bool box_dirichlet(int n) const { return box_dirichlet_[n] != 0; }
  double box_value(int n) const { return box_value_[n]; }
  bool neumann_x_min() const { return p_.left.kind == SideKind::neumann; }
  bool neumann_x_max() const { return p_.right.kind == SideKind::neumann; }
  bool neumann_y_min() const { return p_.bottom.kind == SideKind::neumann; }
  bool neumann_y_max() const { return p_.top.kind == SideKind::neumann; }

  // Five-point Laplacian of the node function w at node (i,j), mirroring across Neumann sides.
  double laplacian(std::span<const double> w, int i, int j) const;
  // Bilinear interpolation of the node function u at x (clamped to the box).
  double interpolate(std::span<const double> u, Vec2 x) const;
  // -grad u at x: central differences at nodes, interpolated bilinearly (field E = -grad u).
  Vec2 field(std::span<const double> u, Vec2 x) const;

 private:
  Params p_;
  int nx_, ny_;
  double x0_, y0_, hx_, hy_;
  std::vector<std::uint8_t> box_dirichlet_;
  std::vector<double> box_value_;
};

// Direct solver for  L u = s  at free nodes, u given at Dirichlet nodes (box sides and nodes
// inside conductors), L the five-point Laplacian of CoarseGrid. Factorised once per Dirichlet set.
class CoarseSolver {
 public:
  explicit CoarseSolver(const CoarseGrid& grid);
  ~CoarseSolver();
  CoarseSolver(CoarseSolver&&) noexcept;
  CoarseSolver& operator=(CoarseSolver&&) noexcept;

  // Marks extra Dirichlet nodes (conductors). Refactorises only if the set changed.
  // Returns true if a new factorisation was computed.
  bool set_extra_dirichlet(std::span<const std::uint8_t> mask);
  // Solves L u = source at free nodes; u must hold the Dirichlet values at Dirichlet nodes on
  // entry (box values are written here); free entries are overwritten.
  void solve(std::span<const double> source, std::span<double> u);
  bool is_dirichlet(int n) const { return free_index_[n] < 0; }
  int factorisations() const { return factorisations_; }
  double last_factor_seconds() const { return last_factor_seconds_; }

 private:
  void factorise();
  const CoarseGrid* grid_;
  std::vector<std::uint8_t> extra_;
  std::vector<int> free_index_;  // node -> unknown index, -1 for Dirichlet
  std::vector<int> free_nodes_;
  std::vector<double> row_scale_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int factorisations_ = 0;
  double last_factor_seconds_ = 0.0;
};

}  // namespace nipdem::ldc
