#include "nipdem/solvers/ldc/problem.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"

namespace nipdem::ldc {

const char* to_string(LocalMethod m) {
  switch (m) {
    case LocalMethod::analytic: return "analytic";
    case LocalMethod::schwarz: return "schwarz";
    case LocalMethod::finite_difference: return "finite_difference";
  }
  return "?";
}

void validate(const Params& p) {
  const std::string where = "ldc";
  constexpr double inf = std::numeric_limits<double>::infinity();
  // Bounds on the scales of the problem (SI, but wide enough for dimensionless setups with
  // ε = 1 and a unit box, as in the verification problems): within them every potential, field
  // and force stays far inside double range (with ε = 1e308 or 1e-300, a side at 1e308 V or a box
  // of 1e308 m the solve "succeeded" with null forces and potentials).
  for (auto [key, v] : {std::pair{"box.x_min_m", p.x_min_m}, {"box.x_max_m", p.x_max_m}, {"box.y_min_m", p.y_min_m},
                        {"box.y_max_m", p.y_max_m}})
    if (!(std::abs(v) <= kMaxCoordinate_m))
      throw_input(where, key, fmt::format("{}", v), "box corner out of range",
                  fmt::format("finite, within +-{:g} m", kMaxCoordinate_m));
  if (!(p.x_max_m > p.x_min_m))
    throw_input(where, "x_max_m", fmt::format("{}", p.x_max_m), "box has zero or negative width",
                fmt::format("> x_min_m = {}", p.x_min_m));
  if (!(p.y_max_m > p.y_min_m))
    throw_input(where, "y_max_m", fmt::format("{}", p.y_max_m), "box has zero or negative height",
                fmt::format("> y_min_m = {}", p.y_min_m));
  if (!(p.x_max_m - p.x_min_m >= kMinBox_m))
    throw_input(where, "box.x_max_m", fmt::format("{}", p.x_max_m), "box narrower than the smallest allowed",
                fmt::format(">= x_min_m + {:g} m", kMinBox_m));
  if (!(p.y_max_m - p.y_min_m >= kMinBox_m))
    throw_input(where, "box.y_max_m", fmt::format("{}", p.y_max_m), "box lower than the smallest allowed",
                fmt::format(">= y_min_m + {:g} m", kMinBox_m));
  // Upper bounds keep every node count within int and the factorisation within memory (the
  // grids used are <= 320 x 320 nodes; 2048^2 cells ~ 4.2e6 nodes: the factorisation took 100 s of
  // CPU and 3.4 GB, measured 2026-12-07; `ldc solve` says so on stderr before it starts).
  constexpr int kMaxCells = 2048;
  if (p.cells_x < 2 || p.cells_x > kMaxCells)
    throw_input(where, "cells_x", std::to_string(p.cells_x), "coarse grid size out of range", "[2, 2048]");
  if (p.cells_y < 2 || p.cells_y > kMaxCells)
    throw_input(where, "cells_y", std::to_string(p.cells_y), "coarse grid size out of range", "[2, 2048]");
  const double ratio = p.hx() / p.hy();
  if (ratio > 4.0 || ratio < 0.25)
    throw_input(where, "cells_x/cells_y", fmt::format("hx/hy = {}", ratio), "coarse cells too elongated",
                "0.25 <= hx/hy <= 4");
  require_range(where, "permittivity_F_per_m", p.permittivity_F_per_m, kMinPermittivity, kMaxPermittivity);
  require_range(where, "local_radius_factor", p.local_radius_factor, 1.2, inf);
  require_range(where, "local_min_cells", p.local_min_cells, 1.0, inf);
  require_range(where, "gamma_points_per_cell", p.gamma_points_per_cell, 0.25, 64.0);
  require_range(where, "fd_refinement", p.fd_refinement, 1, 64);
  require_range(where, "fd_min_points_per_radius", p.fd_min_points_per_radius, 1.0, 64.0);
  require_range(where, "safety_m", p.safety_m, 0.0, inf);
  require_range(where, "tolerance", p.tolerance, 1e-15, 1.0);
  require_range(where, "max_iterations", p.max_iterations, 1, 1e6);
  require_range(where, "schwarz_max_iterations", p.schwarz_max_iterations, 1, 1e6);
  require_range(where, "schwarz_tolerance", p.schwarz_tolerance, 1e-16, 1.0);
  require_range(where, "initial_potential_V", p.initial_potential_V, -inf, inf);
  if (p.bottom.kind == SideKind::neumann && p.top.kind == SideKind::neumann && p.left.kind == SideKind::neumann &&
      p.right.kind == SideKind::neumann)
    throw_input(where, "boundary", "all sides Neumann", "the potential would be undefined up to a constant",
                "at least one Dirichlet side");
  for (auto [name, s] : {std::pair{"bottom", &p.bottom}, {"top", &p.top}, {"left", &p.left}, {"right", &p.right}})
    require_range(where, std::string("boundary.") + name + ".value_V", s->value_V, -kMaxPotential_V, kMaxPotential_V);
}

void validate_discs(const Params& p, std::span<const Disc> discs) {
  const std::string where = "ldc";
  for (std::size_t k = 0; k < discs.size(); ++k) {
    const Disc& d = discs[k];
    const std::string key = fmt::format("discs[{}]", k);
    if (!std::isfinite(d.center_m.x) || !std::isfinite(d.center_m.y))
      throw_input(where, key + ".center_m", fmt::format("({}, {})", d.center_m.x, d.center_m.y), "not finite");
    if (!(d.radius_m > 0.0) || !std::isfinite(d.radius_m))
      throw_input(where, key + ".radius_m", fmt::format("{}", d.radius_m), "radius must be positive", "> 0");
    if (!(d.radius_m >= kMinRadius_m))
      throw_input(where, key + ".radius_m", fmt::format("{}", d.radius_m), "radius below the smallest allowed",
                  fmt::format(">= {:g} m", kMinRadius_m));
    if (!(std::abs(d.charge_C_per_m) <= kMaxCharge_C_per_m))
      throw_input(where, key + ".charge_C_per_m", fmt::format("{}", d.charge_C_per_m), "charge out of range",
                  fmt::format("finite, within +-{:g} C/m", kMaxCharge_C_per_m));
    const double r = d.radius_m;
    if (d.center_m.x - r <= p.x_min_m || d.center_m.x + r >= p.x_max_m || d.center_m.y - r <= p.y_min_m ||
        d.center_m.y + r >= p.y_max_m)
      throw_input(where, key + ".center_m", fmt::format("({}, {}) radius {}", d.center_m.x, d.center_m.y, r),
                  "disc is not strictly inside the box",
                  fmt::format("[{}, {}] x [{}, {}]", p.x_min_m, p.x_max_m, p.y_min_m, p.y_max_m));
    for (std::size_t j = 0; j < k; ++j) {
      const double dist = norm(d.center_m - discs[j].center_m);
      if (dist <= r + discs[j].radius_m)
        throw_input(where, key, fmt::format("centre distance {} to discs[{}]", dist, j), "discs overlap or touch",
                    fmt::format("> sum of radii = {}", r + discs[j].radius_m));
    }
  }
}

}  // namespace nipdem::ldc
