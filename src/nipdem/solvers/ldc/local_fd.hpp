// Finite-difference local problem (thesis §3.10, eqs. 3.10.2-3.10.6) on a rectangle with a fine
// uniform grid, containing one or more floating conductors with prescribed charge.
//
//  * Nodes inside a conductor carry its unknown potential g_k.
//  * Discs: nodes next to a disc use the Shortley-Weller five-point stencil (arm cut at the
//    circle, value g_k there), second-order accurate. Axis-aligned rectangles (used for the
//    square hole of §3.8.1) are grid-aligned, so the plain stencil applies.
//  * Charge condition of a disc: eq. 3.10.2, q = -ε (2π r_f/N) Σ_i ∂u/∂r(x_i) at N points on a
//    circle r_f, ∂u/∂r from the gradient of the bilinear interpolant of the surrounding four nodes
//    (eq. 3.10.6). The thesis puts the circle on the disc surface (r_f = R); there the bilinear
//    cell mixes nodes at g with field nodes and underestimates |∂u/∂r| by O(1) (measured: charge
//    off by 200 % at h = R/4, docs/ldc.md). By Gauss's law the flux through any circle around
//    only this disc is q, so we take r_f = R + 1.5 h (less when another disc is that close).
//    Of a rectangle: the discrete flux through the faces around it.
//  * Rectangle sides: Dirichlet values from `boundary` (interpolated coarse solution), or Neumann
//    (mirror) where the rectangle lies on a Neumann side of the box.
// The matrix depends only on the geometry, so it is LU-factorised once; each LDC iteration only
// rebuilds the right-hand side. When the conductors move a little between two LDC solves
// (`update_conductors`), the matrix is rebuilt but the old factorisation is kept as long as no
// node changes its kind: it then serves as the preconditioner of the iterative refinement with
// the new matrix, which converges to the same round-off level as a fresh factorisation (checked
// on every solve by the componentwise backward error; otherwise the matrix is re-factorised).
#pragma once
#include <array>
#include <functional>
#include <memory>
#include <vector>

#include "nipdem/core/vec2.hpp"

namespace nipdem::ldc {

struct FdConductor {
  bool rectangle = false;
  Vec2 center;          // disc
  double radius = 0.0;  // disc
  Vec2 lo, hi;          // rectangle (closed, grid-aligned)
  double charge = 0.0;  // [C/m]
};

// Discretisation options (defaults: see docs/ldc.md for the measured comparison).
struct FdOptions {
  bool shortley_weller = true;  // false: staircase (nodes inside the disc = g, plain stencil)
  // The flux condition 3.10.2/3.10.6 is imposed on the circle r = R + flux_offset_cells * h
  // (Gauss: any contour around only this disc carries the same flux); 0 = on the disc surface.
  double flux_offset_cells = 1.5;
};

class FdLocalProblem {
 public:
  // Rectangle with lower-left corner lo, cells_x x cells_y cells of hx x hy.
  // neumann = {x_min, x_max, y_min, y_max} sides that are Neumann.
  FdLocalProblem(Vec2 lo, double hx, double hy, int cells_x, int cells_y, std::array<bool, 4> neumann,
                 std::vector<FdConductor> conductors, double eps, FdOptions opt = {});
  ~FdLocalProblem();

  // Solves with the Dirichlet data u = boundary(x) on the non-Neumann sides.
  void solve(const std::function<double(Vec2)>& boundary);

  // Moves / resizes / recharges the conductors (same number and kinds, same rectangle). Rebuilds
  // the matrix; re-factorises only if a node changed its kind (inside / outside a conductor) or
  // if the kept factorisation no longer brings the refinement to round-off within a few steps.
  // Returns true if the previous factorisation was kept.
  bool update_conductors(std::vector<FdConductor> conductors);
  // Counters since construction: LU factorisations, solves done with a factorisation of an
  // earlier matrix (stale), and iterative-refinement steps.
  struct Counters { int factorisations = 0, stale_solves = 0, refinement_steps = 0; };
  const Counters& counters() const { return counters_; }
  // Componentwise backward error max_i |b - A x|_i / (|A| |x| + |b|)_i of the last solve.
  double backward_error() const { return backward_error_; }

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  Vec2 node(int i, int j) const { return {lo_.x + i * hx_, lo_.y + j * hy_}; }
  double node_value(int i, int j) const { return u_[j * nx_ + i]; }
  double potential(int k) const { return g_[k]; }
  bool contains(Vec2 x) const;
  double value(Vec2 x) const;  // bilinear (g inside conductors)
  Vec2 field(Vec2 x) const;    // -grad of the bilinear interpolant
  // Force per unit length on disc k: ∮ σ²/(2ε) n ds, evaluated as the Maxwell stress on the
  // circle of the charge condition (bilinear field, eq. 3.10.6).
  Vec2 force(int k) const;
  // Independent charge measure: discrete flux -ε Σ (u_out - u_in)·(face/dist) through the faces
  // of a node box `margin` cells outside conductor k (only regular five-point nodes in between,
  // where the discrete flux is path independent).
  double box_flux_charge(int k, int margin) const;

 private:
  Vec2 lo_;
  double hx_, hy_, eps_;
  int nx_, ny_;
  std::array<bool, 4> neumann_;
  FdOptions opt_;
  std::vector<FdConductor> cond_;
  std::vector<int> kind_;    // per node: -2 Dirichlet boundary, -1 free, k >= 0 conductor k
  std::vector<int> unknown_; // per node: unknown index or -1
  std::vector<double> u_, g_;
  std::vector<double> flux_radius_;  // circle carrying the charge condition, per conductor
  struct Coupling { int row, node; double coef; };
  std::vector<Coupling> couplings_;  // rhs[row] -= coef * u[node] for Dirichlet nodes
  Counters counters_;
  double backward_error_ = 0.0;
  double fresh_backward_error_ = 0.0;  // reached by the last fresh factorisation
  bool stale_ = false;                 // factorisation belongs to an earlier matrix
  bool have_solution_ = false;         // impl_->x holds the previous solution (initial guess)
  void assemble();                     // kind_, unknown_, couplings_, flux_radius_, matrix
  void factorize();
  // Iterative refinement of impl_->x for impl_->rhs with the current matrix until the backward
  // error is at round-off or while the residual falls by the factor min_reduction per step (at
  // most max_steps); sets backward_error_. Returns the steps.
  int refine(int max_steps, double min_reduction);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nipdem::ldc
