#include "nipdem/analysis/reduction.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"

namespace nipdem::analysis {

std::size_t RemovalCounter::count(double t0, double t1) const {
  std::size_t c = 0;
  for (const auto& e : events_)
    if (e.t >= t0 && e.t < t1) ++c;
  return c;
}

std::size_t RemovalCounter::count(double t0, double t1, const std::function<bool(const RemovalEvent&)>& select) const {
  std::size_t c = 0;
  for (const auto& e : events_)
    if (e.t >= t0 && e.t < t1 && select(e)) ++c;
  return c;
}

std::vector<std::size_t> RemovalCounter::histogram(double t0, double dt, std::size_t n) const {
  require_positive("removal histogram", "dt", dt);
  std::vector<std::size_t> h(n, 0);
  for (const auto& e : events_) {
    if (e.t < t0) continue;
    const double k = std::floor((e.t - t0) / dt);
    if (k < static_cast<double>(n)) ++h[static_cast<std::size_t>(k)];
  }
  return h;
}

Extent assembly_extent(double t, const std::vector<double>& x, const ExtentOptions& opt) {
  const std::string where = "assembly extent";
  require_range(where, "trim_fraction", opt.trim_fraction, 0.0, 0.49);
  std::vector<double> s;
  s.reserve(x.size());
  for (double v : x) {
    if (!std::isfinite(v)) throw_input(where, "x", fmt::format("{:g}", v), "particle position not finite");
    s.push_back(v);
  }
  const std::size_t k = std::max(opt.trim, static_cast<std::size_t>(std::floor(opt.trim_fraction * s.size())));
  if (s.size() <= 2 * k)
    throw_input(where, "particles", std::to_string(s.size()), fmt::format("none left after trimming {} per side", k),
                fmt::format("> {}", 2 * k));
  std::sort(s.begin(), s.end());
  const double lo = s[k], hi = s[s.size() - 1 - k];
  Extent e;
  e.t = t;
  e.front = opt.front == FrontAt::min_x ? lo : hi;
  e.back = opt.front == FrontAt::min_x ? hi : lo;
  e.size = hi - lo;
  e.n = s.size() - 2 * k;
  return e;
}

std::vector<Extent> assembly_extents(const std::vector<double>& t, const std::vector<std::vector<double>>& x,
                                     const ExtentOptions& opt) {
  if (t.size() != x.size())
    throw_input("assembly extent", "frames", fmt::format("{} times, {} frames", t.size(), x.size()), "counts differ");
  std::vector<Extent> out;
  out.reserve(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) out.push_back(assembly_extent(t[k], x[k], opt));
  return out;
}

LinearFit linear_fit(const std::vector<double>& x, const std::vector<double>& y) {
  const std::string where = "linear fit";
  if (x.size() != y.size()) throw_input(where, "data", fmt::format("{} x, {} y", x.size(), y.size()), "lengths differ");
  const std::size_t n = x.size();
  if (n < 3) throw_input(where, "points", std::to_string(n), "too few", ">= 3");
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (!(sxx > 0)) throw_input(where, "x", "all equal", "cannot fit a slope");
  LinearFit f;
  f.n = n;
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  double rss = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = y[i] - f.intercept - f.slope * x[i];
    rss += r * r;
  }
  const double s2 = rss / static_cast<double>(n - 2);
  f.slope_stderr = std::sqrt(s2 / sxx);
  f.intercept_stderr = std::sqrt(s2 * (1.0 / n + mx * mx / sxx));
  f.r2 = syy > 0 ? 1.0 - rss / syy : 1.0;
  return f;
}

ReductionSpeed reduction_speed(const std::vector<Extent>& samples) {
  std::vector<double> t, size, front, back;
  for (const auto& e : samples) {
    t.push_back(e.t);
    size.push_back(e.size);
    front.push_back(e.front);
    back.push_back(e.back);
  }
  ReductionSpeed r;
  r.size_fit = linear_fit(t, size);
  r.front_fit = linear_fit(t, front);
  r.back_fit = linear_fit(t, back);
  r.speed = -r.size_fit.slope;
  r.speed_stderr = r.size_fit.slope_stderr;
  return r;
}

}  // namespace nipdem::analysis
