#include "nipdem/geometry/neighbor_list.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nipdem::geometry {

bool NeighborList::needs_rebuild(std::span<const double> x, std::span<const double> y) const {
  if (x.size() != x0_.size()) return true;
  // Called every step: no libm call (nearbyint is not inlined without SSE4.1) and no early
  // exit inside the loop, so it vectorises; a moved disc is rare.
  const std::size_t n = x.size();
  const double* px = x.data(); const double* py = y.data();
  const double* qx = x0_.data(); const double* qy = y0_.data();
  const double L = params_.x_hi - params_.x_lo, hL = 0.5 * L;
  const bool periodic = params_.periodic_x;
  const double lim = half_skin2_;
  bool moved = false;
  constexpr std::size_t kBlock = 256;
  for (std::size_t b0 = 0; b0 < n && !moved; b0 += kBlock) {
    const std::size_t b1 = std::min(n, b0 + kBlock);
    int any = 0;
    for (std::size_t i = b0; i < b1; ++i) {
      double dx = px[i] - qx[i];
      const double dy = py[i] - qy[i];
      if (periodic) {  // a disc that crossed the periodic boundary moved by about +-L
        dx = dx > hL ? dx - L : dx;
        dx = dx < -hL ? dx + L : dx;
      }
      any |= (dx * dx + dy * dy > lim);
    }
    moved = any != 0;
  }
  return moved;
}

void NeighborList::rebuild(std::span<const double> x, std::span<const double> y, std::span<const double> r,
                           std::span<const int> body, std::span<const int> old_of_new,
                           const NeighborListParams& p) {
  const std::size_t n = x.size();
  params_ = p;
  half_skin2_ = 0.25 * p.skin * p.skin;
  ++builds_;
  new_start_.assign(n + 1, 0);
  new_nbr_.clear();
  new_eta_.clear();
  new_slide_.clear();
  if (n == 0) {
    row_start_ = new_start_;
    nbr_.clear(); eta_.clear(); slide_.clear();
    x0_.clear(); y0_.clear();
    return;
  }
  double rmax = 0.0, xmin = x[0], xmax = x[0], ymin = y[0], ymax = y[0];
  for (std::size_t i = 0; i < n; ++i) {
    rmax = std::max(rmax, r[i]);
    xmin = std::min(xmin, x[i]); xmax = std::max(xmax, x[i]);
    ymin = std::min(ymin, y[i]); ymax = std::max(ymax, y[i]);
  }
  const double reach = p.skin + p.extra_range;
  double cell = 2.0 * rmax + reach;
  const double L = p.x_hi - p.x_lo;
  int nx, ny;
  if (p.periodic_x) {
    xmin = p.x_lo;
    nx = std::max(1, static_cast<int>(std::floor(L / cell)));
  } else {
    nx = std::max(1, static_cast<int>((xmax - xmin) / cell) + 1);
  }
  ny = std::max(1, static_cast<int>((ymax - ymin) / cell) + 1);
  // Guard against absurd grids (e.g. one disc flung far away): cap the cell count.
  while (static_cast<double>(nx) * ny > 8.0 * static_cast<double>(n) + 1024.0) {
    cell *= 1.5;
    nx = p.periodic_x ? std::max(1, static_cast<int>(std::floor(L / cell))) : std::max(1, static_cast<int>((xmax - xmin) / cell) + 1);
    ny = std::max(1, static_cast<int>((ymax - ymin) / cell) + 1);
  }
  const double cwx = p.periodic_x ? L / nx : cell;
  cell_head_.assign(static_cast<std::size_t>(nx) * ny, -1);
  cell_next_.assign(n, -1);
  auto cell_x = [&](double xi) {
    int c = static_cast<int>(std::floor((xi - xmin) / cwx));
    if (p.periodic_x) { c %= nx; if (c < 0) c += nx; }
    return std::clamp(c, 0, nx - 1);
  };
  auto cell_y = [&](double yi) { return std::clamp(static_cast<int>((yi - ymin) / cell), 0, ny - 1); };
  // Insert in reverse so each cell's chain runs in increasing index order.
  for (std::size_t ii = n; ii-- > 0;) {
    const int c = cell_y(y[ii]) * nx + cell_x(x[ii]);
    cell_next_[ii] = cell_head_[c];
    cell_head_[c] = static_cast<int>(ii);
  }
  std::vector<int> row;  // reused per row (small)
  row.reserve(64);
  const bool has_old = !old_of_new.empty();
  for (std::size_t i = 0; i < n; ++i) {
    row.clear();
    const int cx = cell_x(x[i]), cy = cell_y(y[i]);
    for (int dyc = -1; dyc <= 1; ++dyc) {
      const int yy = cy + dyc;
      if (yy < 0 || yy >= ny) continue;
      for (int dxc = -1; dxc <= 1; ++dxc) {
        int xx = cx + dxc;
        if (p.periodic_x) {
          if (nx < 3 && dxc != 0 && (xx < 0 || xx >= nx)) { /* tiny box: wrap duplicates filtered below */ }
          xx = ((xx % nx) + nx) % nx;
        } else if (xx < 0 || xx >= nx) {
          continue;
        }
        for (int j = cell_head_[yy * nx + xx]; j >= 0; j = cell_next_[j]) {
          if (j <= static_cast<int>(i) || body[j] == body[i]) continue;
          double dx = x[j] - x[i], dy = y[j] - y[i];
          if (p.periodic_x) dx -= L * std::nearbyint(dx / L);
          const double rc = r[i] + r[j] + reach;
          if (dx * dx + dy * dy < rc * rc) row.push_back(j);
        }
      }
    }
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    for (int j : row) {
      new_nbr_.push_back(j);
      double eta = 0.0;
      std::uint8_t sl = 0;
      // Carry history over: find the pair in the old list (row min(oi,oj), sorted).
      int oi = static_cast<int>(i), oj = j;
      if (has_old) { oi = old_of_new[i]; oj = old_of_new[j]; }
      if (oi >= 0 && oj >= 0 && !row_start_.empty()) {
        const int a = std::min(oi, oj), b = std::max(oi, oj);
        if (static_cast<std::size_t>(a) + 1 < row_start_.size()) {
          auto first = nbr_.begin() + row_start_[a], last = nbr_.begin() + row_start_[a + 1];
          auto it = std::lower_bound(first, last, b);
          if (it != last && *it == b) {
            const auto k = static_cast<std::size_t>(it - nbr_.begin());
            eta = eta_[k];
            sl = slide_[k];
          }
        }
      }
      new_eta_.push_back(eta);
      new_slide_.push_back(sl);
    }
    new_start_[i + 1] = static_cast<int>(new_nbr_.size());
  }
  row_start_.swap(new_start_);
  nbr_.swap(new_nbr_);
  eta_.swap(new_eta_);
  slide_.swap(new_slide_);
  x0_.assign(x.begin(), x.end());
  y0_.assign(y.begin(), y.end());
}

}  // namespace nipdem::geometry
