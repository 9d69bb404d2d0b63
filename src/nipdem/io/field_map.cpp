#include "nipdem/io/field_map.hpp"

#include "nipdem/io/csv.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fmt/format.h>
#include <map>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::io {

namespace {

// Largest |Bx|, |By| a map file may hold [T]: far above any magnet (a few T), and small enough that
// the force and the gradients stay finite. A larger value is refused naming file, line and column.
constexpr double kMaxFieldMapB_T = 100.0;

// 4th-order first derivative (in index units) of samples v[k*stride], k = 0..n-1, at index i.
double d1(const double* v, int n, int stride, int i) {
  auto f = [&](int k) { return v[static_cast<std::ptrdiff_t>(k) * stride]; };
  if (i >= 2 && i <= n - 3) return (f(i - 2) - 8 * f(i - 1) + 8 * f(i + 1) - f(i + 2)) / 12.0;
  if (i == 0) return (-25 * f(0) + 48 * f(1) - 36 * f(2) + 16 * f(3) - 3 * f(4)) / 12.0;
  if (i == 1) return (-3 * f(0) - 10 * f(1) + 18 * f(2) - 6 * f(3) + f(4)) / 12.0;
  if (i == n - 1) return (25 * f(n - 1) - 48 * f(n - 2) + 36 * f(n - 3) - 16 * f(n - 4) + 3 * f(n - 5)) / 12.0;
  return (3 * f(n - 1) + 10 * f(n - 2) - 18 * f(n - 3) + 6 * f(n - 4) - f(n - 5)) / 12.0;  // i == n-2
}

std::string trim(std::string_view s) {
  std::size_t a = 0, b = s.size();
  while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r')) ++a;
  while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\r')) --b;
  return std::string(s.substr(a, b - a));
}

std::vector<std::string> split(std::string_view line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t c = line.find(',', start);
    out.push_back(trim(line.substr(start, c == std::string_view::npos ? std::string_view::npos : c - start)));
    if (c == std::string_view::npos) break;
    start = c + 1;
  }
  return out;
}

// Unit factor of a header column `name` = base + "_" + unit, with allowed units; InputError otherwise.
double unit_factor(const std::string& where, int col, const std::string& name, const std::string& base,
                   const std::vector<std::pair<std::string, double>>& units) {
  std::string allowed;
  for (const auto& [u, f] : units) {
    if (name == base + "_" + u) return f;
    allowed += (allowed.empty() ? "" : ", ") + base + "_" + u;
  }
  const std::string problem = name.rfind(base + "_", 0) == 0 ? "unknown unit"
                              : name == base             ? "missing unit suffix"
                                                         : "unexpected column (order is x, y, Bx, By)";
  throw_input(where, fmt::format("header column {}", col + 1), "'" + name + "'", problem, allowed);
}

// Groups sorted values into distinct grid coordinates; checks uniform spacing.
std::vector<double> grid_axis(const std::string& where, const std::string& name, std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const double range = v.back() - v.front();
  const double tol = 1e-9 * std::max(range, 1e-300);
  std::vector<double> u;
  for (double x : v)
    if (u.empty() || x - u.back() > tol) u.push_back(x);
  if (u.size() < 5)
    throw_input(where, name, fmt::format("{} distinct values", u.size()), "grid too small", ">= 5 nodes per axis");
  const double h = (u.back() - u.front()) / static_cast<double>(u.size() - 1);
  for (std::size_t i = 0; i < u.size(); ++i) {
    if (std::abs(u[i] - (u.front() + static_cast<double>(i) * h)) > 1e-3 * h)  // FEM exports print ~6 digits
      throw_input(where, name, fmt::format("{:.9g}", u[i]),
                  fmt::format("grid is not regular (node {} deviates from uniform spacing {:g})", i, h),
                  "uniformly spaced values");
  }
  return u;
}

}  // namespace

FieldMap::FieldMap(double x0, double y0, double hx, double hy, int nx, int ny, std::vector<double> Bx,
                   std::vector<double> By, std::string where)
    : x0_(x0), y0_(y0), hx_(hx), hy_(hy), nx_(nx), ny_(ny), where_(std::move(where)) {
  if (nx < 5 || ny < 5) throw_input(where_, "grid", fmt::format("{} x {}", nx, ny), "grid too small", ">= 5 x 5 nodes");
  require_positive(where_, "hx_m", hx);
  require_positive(where_, "hy_m", hy);
  if (!std::isfinite(x0) || !std::isfinite(y0)) throw_input(where_, "origin", "", "must be finite");
  const auto n = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  if (Bx.size() != n || By.size() != n)
    throw_input(where_, "values", fmt::format("{} / {}", Bx.size(), By.size()), "wrong number of values",
                fmt::format("{} = nx*ny", n));
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(Bx[k]) || !std::isfinite(By[k]))
      throw_input(where_, "B", fmt::format("node ({:g}, {:g})", x0 + (k % nx) * hx, y0 + (k / nx) * hy),
                  "value is NaN or infinite", "finite values");
  }
  auto build = [&](const std::vector<double>& f, std::vector<Node>& out) {
    out.resize(n);
    std::vector<double> fy(n);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const std::size_t k = static_cast<std::size_t>(j) * nx + i;
        out[k].f = f[k];
        out[k].fx = d1(&f[static_cast<std::size_t>(j) * nx], nx, 1, i);
        fy[k] = d1(&f[static_cast<std::size_t>(i)], ny, nx, j);
        out[k].fy = fy[k];
      }
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const std::size_t k = static_cast<std::size_t>(j) * nx + i;
        out[k].fxy = d1(&fy[static_cast<std::size_t>(j) * nx], nx, 1, i);
      }
  };
  std::vector<Node> bx, by;
  build(Bx, bx);
  build(By, by);
  nodes_.resize(n);
  for (std::size_t k = 0; k < n; ++k) nodes_[k].c[0] = bx[k], nodes_[k].c[1] = by[k];
}

bool FieldMap::contains(Vec2 p) const {
  const double tx = 1e-9 * hx_, ty = 1e-9 * hy_;
  return p.x >= x_min() - tx && p.x <= x_max() + tx && p.y >= y_min() - ty && p.y <= y_max() + ty;
}

magnet::Sample FieldMap::at(Vec2 p) const {
  if (!contains(p))
    throw_input(where_, "point", fmt::format("({:g}, {:g}) m", p.x, p.y), "outside the field map",
                fmt::format("x in [{:g}, {:g}], y in [{:g}, {:g}] m", x_min(), x_max(), y_min(), y_max()));
  const double sx = (p.x - x0_) / hx_, sy = (p.y - y0_) / hy_;
  const int i = std::clamp(static_cast<int>(std::floor(sx)), 0, nx_ - 2);
  const int j = std::clamp(static_cast<int>(std::floor(sy)), 0, ny_ - 2);
  const double u = sx - i, v = sy - j;
  // Hermite basis: A0 (value at 0), A1 (value at 1), D0 (slope at 0), D1 (slope at 1), and derivatives.
  const double u2 = u * u, u3 = u2 * u, v2 = v * v, v3 = v2 * v;
  const double Au[2] = {2 * u3 - 3 * u2 + 1, -2 * u3 + 3 * u2}, Du[2] = {u3 - 2 * u2 + u, u3 - u2};
  const double dAu[2] = {6 * u2 - 6 * u, -6 * u2 + 6 * u}, dDu[2] = {3 * u2 - 4 * u + 1, 3 * u2 - 2 * u};
  const double Av[2] = {2 * v3 - 3 * v2 + 1, -2 * v3 + 3 * v2}, Dv[2] = {v3 - 2 * v2 + v, v3 - v2};
  const double dAv[2] = {6 * v2 - 6 * v, -6 * v2 + 6 * v}, dDv[2] = {3 * v2 - 4 * v + 1, 3 * v2 - 2 * v};
  // Factored tensor-product evaluation: first along x for both node rows (b = 0, 1), then along y.
  double val[2] = {0, 0}, du[2] = {0, 0}, dv[2] = {0, 0};
  for (int b = 0; b < 2; ++b) {
    const Node2& n0 = nodes_[static_cast<std::size_t>(j + b) * nx_ + i];
    const Node2& n1 = nodes_[static_cast<std::size_t>(j + b) * nx_ + i + 1];
    for (int c = 0; c < 2; ++c) {
      const Node& a0 = n0.c[c];
      const Node& a1 = n1.c[c];
      const double P = a0.f * Au[0] + a1.f * Au[1] + a0.fx * Du[0] + a1.fx * Du[1];
      const double Q = a0.fy * Au[0] + a1.fy * Au[1] + a0.fxy * Du[0] + a1.fxy * Du[1];
      const double dP = a0.f * dAu[0] + a1.f * dAu[1] + a0.fx * dDu[0] + a1.fx * dDu[1];
      const double dQ = a0.fy * dAu[0] + a1.fy * dAu[1] + a0.fxy * dDu[0] + a1.fxy * dDu[1];
      val[c] += P * Av[b] + Q * Dv[b];
      du[c] += dP * Av[b] + dQ * Dv[b];
      dv[c] += P * dAv[b] + Q * dDv[b];
    }
  }
  magnet::Sample s;
  s.B = {val[0], val[1]};
  s.dB.xx = du[0] / hx_;
  s.dB.xy = dv[0] / hy_;
  s.dB.yx = du[1] / hx_;
  s.dB.yy = dv[1] / hy_;
  return s;
}

std::string FieldMap::describe() const {
  return fmt::format("field map {} ({} x {} nodes, x [{:g}, {:g}] m, y [{:g}, {:g}] m, bicubic Hermite)", where_, nx_,
                     ny_, x_min(), x_max(), y_min(), y_max());
}

FieldMap FieldMap::from_csv(std::string_view text, const std::string& where) {
  std::vector<double> xs, ys, bxs, bys;
  double fx = 0, fy = 0, fb = 0, fb2 = 0;
  bool have_header = false;
  std::size_t line_no = 0, pos = 0;
  while (pos <= text.size()) {
    std::size_t e = text.find('\n', pos);
    if (e == std::string_view::npos) e = text.size();
    const std::string line = trim(text.substr(pos, e - pos));
    pos = e + 1;
    ++line_no;
    if (line.empty() || line[0] == '#') {
      if (e == text.size()) break;
      continue;
    }
    const auto cols = split(line);
    const std::string lw = fmt::format("{}:{}", where, line_no);
    if (!have_header) {
      if (cols.size() != 4)
        throw_input(lw, "header", "'" + line + "'", "expected 4 columns with units", "x_m,y_m,Bx_T,By_T");
      const std::vector<std::pair<std::string, double>> len{{"m", 1.0}, {"mm", 1e-3}, {"um", 1e-6}};
      const std::vector<std::pair<std::string, double>> flux{{"T", 1.0}, {"mT", 1e-3}};
      fx = unit_factor(lw, 0, cols[0], "x", len);
      fy = unit_factor(lw, 1, cols[1], "y", len);
      fb = unit_factor(lw, 2, cols[2], "Bx", flux);
      fb2 = unit_factor(lw, 3, cols[3], "By", flux);
      have_header = true;
      if (e == text.size()) break;
      continue;
    }
    if (cols.size() != 4)
      throw_input(lw, "row", "'" + line + "'", fmt::format("expected 4 values, found {}", cols.size()), "x,y,Bx,By");
    double v[4];
    static const char* names[4] = {"x", "y", "Bx", "By"};
    for (int c = 0; c < 4; ++c) {
      const char* s = cols[static_cast<std::size_t>(c)].c_str();
      char* end = nullptr;
      errno = 0;
      v[c] = std::strtod(s, &end);
      if (end == s || *end != '\0' || errno == ERANGE)
        throw_input(lw, names[c], "'" + cols[static_cast<std::size_t>(c)] + "'", "not a number");
      if (!std::isfinite(v[c]))
        throw_input(lw, names[c], "'" + cols[static_cast<std::size_t>(c)] + "'", "value is NaN or infinite",
                    "finite numbers");
    }
    // A flux density no magnet makes (a typo, a wrong unit, 1e308) would overflow the force or
    // its gradients: refused here, with its line and column, not met later as a NaN.
    for (int c = 2; c < 4; ++c) {
      const double b = v[c] * (c == 2 ? fb : fb2);
      if (!(std::abs(b) <= kMaxFieldMapB_T))
        throw_input(lw, fmt::format("{} (column {})", names[c], c + 1), "'" + cols[static_cast<std::size_t>(c)] + "'",
                    fmt::format("not a physical flux density ({:g} T)", b), fmt::format("|{}| <= {:g} T", names[c], kMaxFieldMapB_T));
    }
    xs.push_back(v[0] * fx);
    ys.push_back(v[1] * fy);
    bxs.push_back(v[2] * fb);
    bys.push_back(v[3] * fb2);
    if (e == text.size()) break;
  }
  if (!have_header) throw_input(where, "header", "", "missing header line with units", "x_m,y_m,Bx_T,By_T");
  if (xs.empty()) throw_input(where, "rows", "0", "no data rows");
  const auto ux = grid_axis(where, "x", xs);
  const auto uy = grid_axis(where, "y", ys);
  const int nx = static_cast<int>(ux.size()), ny = static_cast<int>(uy.size());
  const double hx = (ux.back() - ux.front()) / (nx - 1), hy = (uy.back() - uy.front()) / (ny - 1);
  const std::size_t n = static_cast<std::size_t>(nx) * ny;
  // Every node exactly once means as many rows as nodes: checked before the grid is allocated,
  // so scattered points (nx, ny ~ rows) cannot make a small file ask for rows^2 values.
  if (xs.size() != n)
    throw_input(where, "rows", fmt::format("{} rows for {} x {} = {} grid nodes", xs.size(), nx, ny, n),
                xs.size() < n ? "ragged grid: nodes are missing" : "grid nodes given twice",
                "every node of the nx x ny grid exactly once");
  std::vector<double> Bx(n, 0.0), By(n, 0.0);
  std::vector<char> seen(n, 0);
  for (std::size_t r = 0; r < xs.size(); ++r) {
    const double si = (xs[r] - ux.front()) / hx, sj = (ys[r] - uy.front()) / hy;
    const long i = std::lround(si), j = std::lround(sj);
    if (std::abs(si - i) > 1e-3 || std::abs(sj - j) > 1e-3)
      throw_input(where, "row", fmt::format("({:g}, {:g})", xs[r], ys[r]), "point is not on the regular grid");
    const std::size_t k = static_cast<std::size_t>(j) * nx + static_cast<std::size_t>(i);
    if (seen[k]) throw_input(where, "row", fmt::format("({:g}, {:g})", xs[r], ys[r]), "grid node given twice");
    seen[k] = 1;
    Bx[k] = bxs[r];
    By[k] = bys[r];
  }
  for (std::size_t k = 0; k < n; ++k)
    if (!seen[k])
      throw_input(where, "rows", fmt::format("{} of {}", xs.size(), n),
                  fmt::format("ragged grid: node ({:g}, {:g}) is missing", ux[k % nx], uy[k / nx]),
                  "every node of the nx x ny grid exactly once");
  return FieldMap(ux.front(), uy.front(), hx, hy, nx, ny, std::move(Bx), std::move(By), where);
}

FieldMap FieldMap::sample(const magnet::MagnetField& field, double x0, double x1, int nx, double y0, double y1, int ny) {
  if (nx < 5 || ny < 5) throw_input("FieldMap::sample", "nx/ny", fmt::format("{}/{}", nx, ny), "grid too small", ">= 5");
  if (!(x1 > x0) || !(y1 > y0)) throw_input("FieldMap::sample", "x1/y1", "", "empty region", "x1 > x0, y1 > y0");
  const double hx = (x1 - x0) / (nx - 1), hy = (y1 - y0) / (ny - 1);
  std::vector<double> bx, by;
  bx.reserve(static_cast<std::size_t>(nx) * ny);
  by.reserve(static_cast<std::size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const auto s = field.at({x0 + i * hx, y0 + j * hy});
      bx.push_back(s.B.x);
      by.push_back(s.B.y);
    }
  return FieldMap(x0, y0, hx, hy, nx, ny, std::move(bx), std::move(by), "sampled " + field.describe());
}

FieldMap FieldMap::from_file(const std::filesystem::path& path) { return from_csv(read_file(path), path.string()); }

std::string field_to_csv(const magnet::MagnetField& field, double x0, double x1, int nx, double y0, double y1, int ny,
                         const std::string& comment) {
  if (nx < 2 || ny < 2) throw_input("field_to_csv", "nx/ny", fmt::format("{}/{}", nx, ny), "too few nodes", ">= 2");
  std::vector<std::vector<double>> rows;
  rows.reserve(static_cast<std::size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = x0 + (x1 - x0) * i / (nx - 1), y = y0 + (y1 - y0) * j / (ny - 1);
      const auto s = field.at({x, y});
      rows.push_back({x, y, s.B.x, s.B.y});
    }
  return (comment.empty() ? std::string() : "# " + comment + "\n") +
         format_csv({"x_m", "y_m", "Bx_T", "By_T"}, rows, {"{:.17g}", "{:.17g}", "{:.17g}", "{:.17g}"});
}

}  // namespace nipdem::io
