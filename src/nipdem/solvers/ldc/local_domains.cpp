#include "nipdem/solvers/ldc/local_domains.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"

#include "nipdem/solvers/ldc/schwarz.hpp"

namespace nipdem::ldc {

namespace {
constexpr int kMaxGapRefinement = 32;
constexpr double kMaxFineNodes = 4e5;

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) { return parent[a] == a ? a : parent[a] = find(parent[a]); }
  bool unite(int a, int b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    parent[b] = a;
    return true;
  }
};

double wall_distance(const Params& p, Vec2 c) {
  return std::min({c.x - p.x_min_m, p.x_max_m - c.x, c.y - p.y_min_m, p.y_max_m - c.y});
}

// Distance from point c to the rectangle [lo, hi] (0 inside).
double rect_distance(Vec2 lo, Vec2 hi, Vec2 c) {
  const double dx = std::max({lo.x - c.x, 0.0, c.x - hi.x});
  const double dy = std::max({lo.y - c.y, 0.0, c.y - hi.y});
  return std::hypot(dx, dy);
}
// A disc of a finite-difference group with no fine node inside it (the fine grid is capped at
// kMaxFineNodes) would give the local matrix a zero column for its potential: the LU fails
// ("singular") after seconds of work. That happens when a disc much smaller than a coarse cell sits
// within about a coarse cell of the box side or of another disc (e.g. a 5 um disc 0.5 mm from the
// side of the default 1 m box with 20 cells). Refused here, naming the disc, with the radius that
// a fine cell of this grid needs (half its diagonal: a circle that large always holds a node).
void check_fd_resolution(const CoarseGrid& grid, std::span<const Disc> discs, const std::vector<LocalGroup>& groups) {
  for (const LocalGroup& g : groups) {
    if (g.method != LocalMethod::finite_difference) continue;
    // The fine grid exactly as FdLocalProblem lays it out (local_fd.cpp: node(), assemble()).
    const Vec2 lo = grid.node(g.i0, g.j0);
    const double hx = grid.hx() / g.refinement, hy = grid.hy() / g.refinement, hmin = std::min(hx, hy);
    const int nx = (g.i1 - g.i0) * g.refinement + 1, ny = (g.j1 - g.j0) * g.refinement + 1;
    const bool neu[4] = {g.i0 == 0 && grid.neumann_x_min(), g.i1 == grid.nx() - 1 && grid.neumann_x_max(),
                         g.j0 == 0 && grid.neumann_y_min(), g.j1 == grid.ny() - 1 && grid.neumann_y_max()};
    for (int k : g.members) {
      const Disc& d = discs[k];
      const double fi = (d.center_m.x - lo.x) / hx, fj = (d.center_m.y - lo.y) / hy;
      bool has_node = false;
      for (double ci : {std::floor(fi), std::ceil(fi)})
        for (double cj : {std::floor(fj), std::ceil(fj)}) {
          if (ci < 0 || cj < 0 || ci > nx - 1 || cj > ny - 1) continue;
          if ((ci == 0 && !neu[0]) || (ci == nx - 1 && !neu[1]) || (cj == 0 && !neu[2]) || (cj == ny - 1 && !neu[3]))
            continue;  // a Dirichlet side node, never a conductor node
          const Vec2 x{lo.x + int(ci) * hx, lo.y + int(cj) * hy};
          has_node = has_node || norm(x - d.center_m) <= d.radius_m + 1e-3 * hmin;
        }
      if (has_node) continue;
      const double needed = 0.5 * std::hypot(hx, hy);
      throw_input("ldc", fmt::format("discs[{}].radius_m", k), fmt::format("{:g}", d.radius_m),
                  fmt::format("disc too small for the coarse grid: it is within about one coarse cell (H = {:g} m) of "
                              "the box side or another disc, so it needs a finite-difference local problem, whose fine "
                              "grid (at most {:g} nodes) has cells of {:g} x {:g} m and no node inside the disc",
                              std::max(grid.hx(), grid.hy()), kMaxFineNodes, hx, hy),
                  fmt::format("radius_m >= {:g} m with this box and box.cells_x/cells_y, or more cells or a smaller box "
                              "(the default box is 1 m x 1 m with 20 x 20 cells)",
                              needed));
    }
  }
}
}  // namespace

double local_radius(const Params& p, const Disc& d) {
  const double h = std::max(p.hx(), p.hy());
  const double r2 = std::max(p.local_radius_factor * d.radius_m, d.radius_m + p.local_min_cells * h);
  return std::min(r2, wall_distance(p, d.center_m));
}

std::vector<LocalGroup> build_local_groups(const CoarseGrid& grid, std::span<const Disc> discs, const Params& p) {
  const int n = int(discs.size());
  const double h = std::max(p.hx(), p.hy());
  std::vector<double> r2(n);
  std::vector<char> need_fd(n, 0);
  for (int k = 0; k < n; ++k) {
    r2[k] = local_radius(p, discs[k]);
    // Shrink the annulus so that it contains no other disc (condition 3.9.16 for Schwarz),
    // keeping 20 % of the gap free.
    for (int j = 0; j < n; ++j) {
      if (j == k) continue;
      const double d = norm(discs[k].center_m - discs[j].center_m);
      const double gap = d - discs[k].radius_m - discs[j].radius_m;
      r2[k] = std::min(r2[k], d - discs[j].radius_m - 0.2 * gap);
      // Prefer separate annuli (analytic) over Schwarz where both keep at least
      // R + 1.5 H: large overlapping clusters make the Schwarz sweeps slow.
      if (p.prefer_separate_annuli && 0.5 * d >= discs[k].radius_m + 1.5 * h) r2[k] = std::min(r2[k], 0.5 * d);
    }
    // An annulus thinner than one coarse cell has no coarse node for the defect.
    if (p.force_finite_difference || r2[k] < discs[k].radius_m + h) need_fd[k] = 1;
  }

  std::vector<LocalGroup> groups;
  std::vector<std::pair<int, int>> joined;  // discs forced into one group by rectangle contact
  for (;;) {
    // Analytic/Schwarz discs group with analytic/Schwarz discs whose annulus overlaps theirs;
    // finite-difference discs with finite-difference discs (rectangle merging below).
    UnionFind uf(n);
    for (int k = 0; k < n; ++k)
      for (int j = k + 1; j < n; ++j)
        if (need_fd[k] == need_fd[j] && norm(discs[k].center_m - discs[j].center_m) < r2[k] + r2[j]) uf.unite(k, j);
    for (auto [a, b] : joined) uf.unite(a, b);
    groups.clear();
    std::vector<int> group_of_root(n, -1);
    for (int k = 0; k < n; ++k) {
      const int r = uf.find(k);
      if (group_of_root[r] < 0) {
        group_of_root[r] = int(groups.size());
        groups.emplace_back();
      }
      LocalGroup& g = groups[group_of_root[r]];
      g.members.push_back(k);
      g.r2.push_back(r2[k]);
    }
    for (LocalGroup& g : groups) {
      bool fd = false;
      for (int k : g.members) fd = fd || need_fd[k];
      if (!fd && g.members.size() > 1) {
        std::vector<Disc> ds;
        for (int k : g.members) ds.push_back(discs[k]);
        fd = !SchwarzSolver::applicable(ds, g.r2);
      }
      g.method = fd ? LocalMethod::finite_difference : g.members.size() > 1 ? LocalMethod::schwarz : LocalMethod::analytic;
      if (!fd) continue;
      Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
      double rmin = 1e300;
      for (std::size_t m = 0; m < g.members.size(); ++m) {
        const Disc& d = discs[g.members[m]];
        const double rr = std::max(g.r2[m], d.radius_m + h);
        lo = {std::min(lo.x, d.center_m.x - rr), std::min(lo.y, d.center_m.y - rr)};
        hi = {std::max(hi.x, d.center_m.x + rr), std::max(hi.y, d.center_m.y + rr)};
        rmin = std::min(rmin, d.radius_m);
      }
      const Vec2 o = grid.lower();
      g.i0 = std::clamp(int(std::floor((lo.x - o.x) / grid.hx() + 1e-9)), 0, grid.nx() - 1);
      g.i1 = std::clamp(int(std::ceil((hi.x - o.x) / grid.hx() - 1e-9)), 0, grid.nx() - 1);
      g.j0 = std::clamp(int(std::floor((lo.y - o.y) / grid.hy() + 1e-9)), 0, grid.ny() - 1);
      g.j1 = std::clamp(int(std::ceil((hi.y - o.y) / grid.hy() - 1e-9)), 0, grid.ny() - 1);
      const double hmax = std::max(grid.hx(), grid.hy());
      double gap = 1e300;  // closest approach of two member discs
      for (std::size_t a = 0; a < g.members.size(); ++a)
        for (std::size_t b = a + 1; b < g.members.size(); ++b) {
          const Disc& da = discs[g.members[a]];
          const Disc& db = discs[g.members[b]];
          gap = std::min(gap, norm(da.center_m - db.center_m) - da.radius_m - db.radius_m);
        }
      int m = std::max(p.fd_refinement, int(std::ceil(p.fd_min_points_per_radius * hmax / rmin)));
      // Resolve the gap with ~3 fine cells so the flux condition keeps its offset (local_fd.hpp);
      // capped, beyond the cap the flux circle moves towards the disc surface.
      m = std::max(m, std::min(kMaxGapRefinement, int(std::ceil(3.0 * hmax / gap))));
      // Keep the local LU affordable: at most kMaxFineNodes fine nodes (but never coarser than
      // fd_refinement).
      const double cells = double(g.i1 - g.i0) * double(g.j1 - g.j0);
      while (m > p.fd_refinement && cells * m * m > kMaxFineNodes) --m;
      g.refinement = m;
    }
    // A finite-difference rectangle must not cut or contain a disc
    // that is not one of its conductors, nor overlap another rectangle: such discs join it.
    // Overlap with another group's annulus is harmless (both local solutions are valid in the
    // charge-free overlap, and neither domain contains a foreign disc).
    bool merged = false;
    for (const LocalGroup& g : groups) {
      if (g.method != LocalMethod::finite_difference) continue;
      const Vec2 lo = grid.node(g.i0, g.j0), hi = grid.node(g.i1, g.j1);
      for (const LocalGroup& o : groups) {
        if (&o == &g) continue;
        bool touch = false;
        if (o.method == LocalMethod::finite_difference) {
          touch = o.i0 < g.i1 && g.i0 < o.i1 && o.j0 < g.j1 && g.j0 < o.j1;
        } else {
          for (int k : o.members) touch = touch || rect_distance(lo, hi, discs[k].center_m) < discs[k].radius_m;
        }
        if (touch) {
          for (int k : o.members) {
            need_fd[k] = 1;
          }
          joined.emplace_back(g.members[0], o.members[0]);
          merged = true;
        }
      }
    }
    if (!merged) break;
  }
  check_fd_resolution(grid, discs, groups);
  return groups;
}

}  // namespace nipdem::ldc
