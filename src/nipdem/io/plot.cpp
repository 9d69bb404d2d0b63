#include "nipdem/io/plot.hpp"

#include <algorithm>
#include <atomic>
#include <cairo.h>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <memory>
#include <stdexcept>
#include <unistd.h>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::io {

namespace {

constexpr std::array<std::array<double, 3>, 8> kPalette{{{0.12, 0.47, 0.71},
                                                         {0.85, 0.33, 0.10},
                                                         {0.17, 0.63, 0.17},
                                                         {0.58, 0.40, 0.74},
                                                         {0.84, 0.15, 0.16},
                                                         {0.55, 0.34, 0.29},
                                                         {0.89, 0.47, 0.76},
                                                         {0.50, 0.50, 0.50}}};

struct Axis {
  double lo = 0, hi = 1;  // in data units
  bool log = false;
  double t(double v) const { return log ? std::log10(v) : v; }
  double tlo() const { return t(lo); }
  double thi() const { return t(hi); }
};

// Data range of a set of values (skipping NaN/inf and, on a log axis, nothing: positives are
// checked before).
void extend(double v, double& lo, double& hi) {
  if (!std::isfinite(v)) return;
  lo = std::min(lo, v);
  hi = std::max(hi, v);
}

Axis make_axis(double dlo, double dhi, std::optional<double> fixed_lo, std::optional<double> fixed_hi, bool log) {
  Axis a;
  a.log = log;
  if (!(dlo <= dhi)) {  // no finite data
    dlo = log ? 1.0 : 0.0;
    dhi = log ? 10.0 : 1.0;
  }
  if (log) {
    double l = std::log10(dlo), h = std::log10(dhi);
    if (h - l < 1e-12) { l -= 0.5; h += 0.5; }
    const double pad = 0.04 * (h - l);
    a.lo = std::pow(10.0, l - pad);
    a.hi = std::pow(10.0, h + pad);
  } else {
    if (dhi - dlo <= 1e-12 * std::max(1.0, std::abs(dhi))) {
      const double d = dlo == 0.0 ? 1.0 : 0.1 * std::abs(dlo);
      dlo -= d;
      dhi += d;
    }
    const double pad = 0.04 * (dhi - dlo);
    a.lo = dlo - pad;
    a.hi = dhi + pad;
  }
  if (fixed_lo) a.lo = *fixed_lo;
  if (fixed_hi) a.hi = *fixed_hi;
  return a;
}

struct CairoDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};

double text_width(cairo_t* cr, const std::string& s) {
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  return e.x_advance;
}

void show_text_at(cairo_t* cr, const std::string& s, double x, double y, double align_x, double align_y) {
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  cairo_font_extents_t fe;
  cairo_font_extents(cr, &fe);
  // align_y: 0 = y is the top of the capitals, 0.5 = their middle, 1 = the baseline.
  const double cap = 0.75 * fe.ascent;
  cairo_move_to(cr, x - align_x * e.x_advance, y + (1.0 - align_y) * cap);
  cairo_show_text(cr, s.c_str());
}

}  // namespace

bool draws_line(const Series& se) {
  if (!se.line) return false;
  if (!se.line_only_if_resolved) return true;
  // resolved: some pair of neighbouring points differs by more than their combined error bars
  for (std::size_t i = 0; i + 1 < se.x.size() && i + 1 < se.y.size(); ++i) {
    if (!std::isfinite(se.y[i]) || !std::isfinite(se.y[i + 1])) continue;
    const double e0 = i < se.y_err.size() ? se.y_err[i] : 0.0, e1 = i + 1 < se.y_err.size() ? se.y_err[i + 1] : 0.0;
    if (std::fabs(se.y[i + 1] - se.y[i]) > std::hypot(e0, e1)) return true;
  }
  return false;
}

std::array<double, 3> diverging_colour(double t) {
  t = std::clamp(t, -1.0, 1.0);  // display only: the data are never changed
  const std::array<double, 3> neg{0.13, 0.40, 0.67}, pos{0.70, 0.09, 0.17};
  const auto& end = t < 0 ? neg : pos;
  const double a = std::fabs(t);
  return {1 + a * (end[0] - 1), 1 + a * (end[1] - 1), 1 + a * (end[2] - 1)};
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return {lo};
  target = std::max(target, 2);
  const double raw = (hi - lo) / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw * 0.999) break;
  }
  std::vector<double> ticks;
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (int i = 0; i < 1000; ++i) {
    double v = first + i * step;
    if (v > hi + 1e-9 * step) break;
    if (std::abs(v) < 1e-9 * step) v = 0.0;
    ticks.push_back(v);
  }
  return ticks;
}

std::vector<double> log_ticks(double lo, double hi) {
  std::vector<double> ticks;
  if (!(lo > 0) || !(hi > lo)) return ticks;
  const int k0 = static_cast<int>(std::floor(std::log10(lo)));
  const int k1 = static_cast<int>(std::ceil(std::log10(hi)));
  const bool dense = (std::log10(hi) - std::log10(lo)) < 3.0;
  for (int k = k0; k <= k1; ++k) {
    for (double m : {1.0, 2.0, 5.0}) {
      if (m != 1.0 && !dense) continue;
      const double v = m * std::pow(10.0, k);
      if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) ticks.push_back(v);
    }
  }
  // A range inside a factor of ~2.5 holds at most one 1-2-5 value: label it with linear steps
  // instead (still placed on the log scale), so the axis is never left without numbers.
  if (ticks.size() < 2) {
    ticks.clear();
    for (double v : nice_ticks(lo, hi, 5))
      if (v > 0) ticks.push_back(v);
  }
  return ticks;
}

std::string tick_label(double v, double step) {
  if (v == 0.0) return "0";
  const double a = std::abs(v);
  if (a >= 1e5 || a < 1e-3) return fmt::format("{:g}", v);
  // Enough decimals to resolve the tick step.
  int dec = 0;
  if (step > 0) dec = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  if (step > 0 && std::abs(step * std::pow(10.0, dec) - std::round(step * std::pow(10.0, dec))) > 1e-6) ++dec;
  dec = std::min(dec, 8);
  return fmt::format("{:.{}f}", v, dec);
}

std::vector<std::string> tick_labels(const std::vector<double>& ticks, bool log) {
  std::vector<std::string> out;
  if (log || ticks.size() < 2) {
    for (double v : ticks) out.push_back(fmt::format("{:g}", v));
    return out;
  }
  const double step = ticks[1] - ticks[0];
  double amax = 0;
  for (double v : ticks) amax = std::max(amax, std::abs(v));
  if (step >= 1e-3 && amax < 1e5) {
    for (double v : ticks) out.push_back(tick_label(v, step));
    return out;
  }
  // Very small or very large values: one common exponent, same mantissa decimals on the axis
  // ("-1.5e-4", "-2.0e-4", ...).
  const int e = static_cast<int>(std::floor(std::log10(amax)));
  const double scale = std::pow(10.0, e);
  const double ms = step / scale;
  int dec = std::max(0, static_cast<int>(std::ceil(-std::log10(ms) - 1e-9)));
  if (std::abs(ms * std::pow(10.0, dec) - std::round(ms * std::pow(10.0, dec))) > 1e-6) ++dec;
  dec = std::min(dec, 8);
  for (double v : ticks) {
    if (std::abs(v) < 1e-9 * step) out.push_back("0");
    else out.push_back(fmt::format("{:.{}f}e{}", v / scale, dec, e));
  }
  return out;
}

void write_plot_png(const std::filesystem::path& path, const PlotSpec& spec) {
  const std::string where = "plot '" + path.string() + "'";
  if (spec.width < 100 || spec.height < 100 || spec.width > 10000 || spec.height > 10000)
    throw_input(where, "size", fmt::format("{}x{}", spec.width, spec.height), "image size out of range",
                "100..10000 px each");
  if (spec.series.empty() && !spec.heatmap) throw_input(where, "series", "none", "nothing to plot");

  // Validate data and find the ranges.
  double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo, ylo = xlo, yhi = -xlo;
  for (std::size_t s = 0; s < spec.series.size(); ++s) {
    const Series& se = spec.series[s];
    const std::string name = "series " + std::to_string(s) + (se.label.empty() ? "" : " '" + se.label + "'");
    if (se.x.size() != se.y.size())
      throw_input(where, name, fmt::format("{} x, {} y", se.x.size(), se.y.size()), "x and y lengths differ");
    if (!se.y_err.empty() && se.y_err.size() != se.y.size())
      throw_input(where, name, fmt::format("{} y_err, {} y", se.y_err.size(), se.y.size()),
                  "error bar count differs from point count");
    for (std::size_t i = 0; i < se.x.size(); ++i) {
      const double x = se.x[i], y = se.y[i];
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      if (spec.log_x && x <= 0) throw_input(where, name, fmt::format("x = {:g}", x), "not positive on a log axis");
      if (spec.log_y && y <= 0) throw_input(where, name, fmt::format("y = {:g}", y), "not positive on a log axis");
      extend(x, xlo, xhi);
      extend(y, ylo, yhi);
      if (!se.y_err.empty() && std::isfinite(se.y_err[i])) {
        const double e = std::abs(se.y_err[i]);
        if (!spec.log_y || y - e > 0) extend(y - e, ylo, yhi);
        extend(y + e, ylo, yhi);
      }
    }
  }
  // Heat map: validate, extend the ranges to the cell edges, find the colour limits.
  double zlo = 0, zhi = 0;
  std::vector<double> hx_edges, hy_edges;
  if (spec.heatmap) {
    const Heatmap& hm = *spec.heatmap;
    if (spec.log_x || spec.log_y) throw_input(where, "heatmap", "", "a heat map needs linear axes");
    if (hm.x.size() < 2 || hm.y.size() < 2)
      throw_input(where, "heatmap", fmt::format("{} x {} cells", hm.x.size(), hm.y.size()), "too few cells", ">= 2 x 2");
    if (hm.z.size() != hm.x.size() * hm.y.size())
      throw_input(where, "heatmap", fmt::format("{} values", hm.z.size()), "z size differs from nx * ny",
                  fmt::format("{}", hm.x.size() * hm.y.size()));
    auto edges = [&](const std::vector<double>& c, const char* name) {
      std::vector<double> e(c.size() + 1);
      for (std::size_t i = 0; i < c.size(); ++i)
        if (!std::isfinite(c[i]) || (i > 0 && !(c[i] > c[i - 1])))
          throw_input(where, std::string("heatmap ") + name, fmt::format("{:g}", c[i]), "not finite and strictly increasing");
      for (std::size_t i = 1; i < c.size(); ++i) e[i] = 0.5 * (c[i - 1] + c[i]);
      e[0] = c[0] - (e[1] - c[0]);
      e[c.size()] = c.back() + (c.back() - e[c.size() - 1]);
      return e;
    };
    hx_edges = edges(hm.x, "x");
    hy_edges = edges(hm.y, "y");
    extend(hx_edges.front(), xlo, xhi);
    extend(hx_edges.back(), xlo, xhi);
    extend(hy_edges.front(), ylo, yhi);
    extend(hy_edges.back(), ylo, yhi);
    double amax = 0;
    for (double z : hm.z)
      if (std::isfinite(z)) amax = std::max(amax, std::fabs(z));
    zlo = hm.z_min.value_or(-amax);
    zhi = hm.z_max.value_or(amax);
    if (!(zlo < 0 && zhi > 0) && !(amax == 0 && !hm.z_min && !hm.z_max))
      throw_input(where, "heatmap limits", fmt::format("[{:g}, {:g}]", zlo, zhi), "must bracket 0", "z_min < 0 < z_max");
    if (amax == 0 && !hm.z_min && !hm.z_max) { zlo = -1; zhi = 1; }
  }
  if (spec.log_x && ((spec.x_min && *spec.x_min <= 0) || (spec.x_max && *spec.x_max <= 0)))
    throw_input(where, "x limits", "", "not positive on a log axis");
  if (spec.log_y && ((spec.y_min && *spec.y_min <= 0) || (spec.y_max && *spec.y_max <= 0)))
    throw_input(where, "y limits", "", "not positive on a log axis");
  const Axis ax = make_axis(xlo, xhi, spec.x_min, spec.x_max, spec.log_x);
  const Axis ay = make_axis(ylo, yhi, spec.y_min, spec.y_max, spec.log_y);
  if (!(ax.hi > ax.lo)) throw_input(where, "x limits", fmt::format("[{:g}, {:g}]", ax.lo, ax.hi), "empty axis range");
  if (!(ay.hi > ay.lo)) throw_input(where, "y limits", fmt::format("[{:g}, {:g}]", ay.lo, ay.hi), "empty axis range");

  std::unique_ptr<cairo_surface_t, CairoDeleter> surf(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, spec.width, spec.height));
  if (cairo_surface_status(surf.get()) != CAIRO_STATUS_SUCCESS) throw std::runtime_error(where + ": cannot create surface");
  std::unique_ptr<cairo_t, CairoDeleter> crp(cairo_create(surf.get()));
  cairo_t* cr = crp.get();

  const double W = spec.width, H = spec.height;
  const double fs = std::clamp(std::min(W, H) / 40.0, 10.0, 20.0);  // base font size [px]
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

  // Background.
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);

  // Ticks and their labels (needed to size the left margin).
  std::vector<double> xt = ax.log ? log_ticks(ax.lo, ax.hi) : nice_ticks(ax.lo, ax.hi, 6);
  std::vector<double> yt = ay.log ? log_ticks(ay.lo, ay.hi) : nice_ticks(ay.lo, ay.hi, 6);
  cairo_set_font_size(cr, fs * 0.85);
  double ylabel_w = 0;
  const std::vector<std::string> xlab = tick_labels(xt, ax.log), ylab = tick_labels(yt, ay.log);
  for (const auto& l : ylab) ylabel_w = std::max(ylabel_w, text_width(cr, l));

  const double left = 0.9 * fs + ylabel_w + fs * 1.8;
  // Room for the colour bar: a gap, the bar, its tick labels and its rotated label.
  std::vector<double> zt;
  std::vector<std::string> zlab;
  double zlab_w = 0;
  if (spec.heatmap) {
    zt = nice_ticks(zlo, zhi, 6);
    zlab = tick_labels(zt, false);
    if (!zt.empty()) {
      if (zt.front() <= zlo) zlab.front() = "<=" + zlab.front();
      if (zt.back() >= zhi) zlab.back() = ">=" + zlab.back();
    }
    for (const auto& l : zlab) zlab_w = std::max(zlab_w, text_width(cr, l));
  }
  const double bar_w = fs * 1.1;
  const double right = spec.heatmap ? fs * 1.2 + bar_w + fs * 0.5 + zlab_w + fs * 2.0 : fs * 1.5;
  const double top = spec.title.empty() ? fs * 1.2 : fs * 2.6;
  const double bottom = fs * 4.0;
  const double pw = W - left - right, ph = H - top - bottom;
  if (pw < 20 || ph < 20) throw_input(where, "size", fmt::format("{}x{}", spec.width, spec.height), "too small for the labels");

  auto px = [&](double x) { return left + (ax.t(x) - ax.tlo()) / (ax.thi() - ax.tlo()) * pw; };
  auto py = [&](double y) { return top + ph - (ay.t(y) - ay.tlo()) / (ay.thi() - ay.tlo()) * ph; };

  // Heat-map cells (under the grid lines) and the colour bar.
  if (spec.heatmap) {
    const Heatmap& hm = *spec.heatmap;
    const std::size_t nx = hm.x.size();
    auto tcol = [&](double z) { return z < 0 ? z / -zlo : z / zhi; };  // z in units of its side's limit, signed
    cairo_save(cr);
    cairo_rectangle(cr, left, top, pw, ph);
    cairo_clip(cr);
    for (std::size_t j = 0; j < hm.y.size(); ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const double z = hm.z[j * nx + i];
        if (!std::isfinite(z)) continue;
        const auto c = diverging_colour(tcol(z));
        cairo_set_source_rgb(cr, c[0], c[1], c[2]);
        const double X0 = px(hx_edges[i]), X1 = px(hx_edges[i + 1]);
        const double Y0 = py(hy_edges[j + 1]), Y1 = py(hy_edges[j]);
        // Overdraw by half a pixel so neighbouring cells leave no hairline gaps.
        cairo_rectangle(cr, X0 - 0.25, Y0 - 0.25, X1 - X0 + 0.5, Y1 - Y0 + 0.5);
        cairo_fill(cr);
      }
    cairo_restore(cr);
    const double bx = left + pw + fs * 1.2;
    const int steps = 200;
    for (int k = 0; k < steps; ++k) {
      const double z = zlo + (zhi - zlo) * (k + 0.5) / steps;
      const auto c = diverging_colour(tcol(z));
      cairo_set_source_rgb(cr, c[0], c[1], c[2]);
      cairo_rectangle(cr, bx, top + ph * (1.0 - static_cast<double>(k + 1) / steps), bar_w, ph / steps + 0.5);
      cairo_fill(cr);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1.0);
    cairo_rectangle(cr, std::round(bx) + 0.5, std::round(top) + 0.5, std::round(bar_w), std::round(ph));
    cairo_stroke(cr);
    for (std::size_t k = 0; k < zt.size(); ++k) {
      const double Y = std::round(top + ph * (1.0 - (zt[k] - zlo) / (zhi - zlo))) + 0.5;
      cairo_move_to(cr, bx + bar_w, Y);
      cairo_line_to(cr, bx + bar_w + fs * 0.3, Y);
      cairo_stroke(cr);
      show_text_at(cr, zlab[k], bx + bar_w + fs * 0.45, Y, 0.0, 0.5);
    }
    if (!hm.z_label.empty()) {
      cairo_save(cr);
      cairo_set_font_size(cr, fs);
      cairo_translate(cr, W - fs * 0.4, top + ph / 2);
      cairo_rotate(cr, M_PI / 2);
      show_text_at(cr, hm.z_label, 0, 0, 0.5, 0.0);
      cairo_restore(cr);
      cairo_set_font_size(cr, fs * 0.85);
    }
  }

  // Grid and ticks.
  cairo_set_line_width(cr, 1.0);
  for (std::size_t k = 0; k < xt.size(); ++k) {
    const double v = xt[k];
    const double X = std::round(px(v)) + 0.5;
    cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
    cairo_move_to(cr, X, top);
    cairo_line_to(cr, X, top + ph);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, X, top + ph);
    cairo_line_to(cr, X, top + ph + fs * 0.35);
    cairo_stroke(cr);
    show_text_at(cr, xlab[k], X, top + ph + fs * 0.45, 0.5, 0.0);
  }
  for (std::size_t k = 0; k < yt.size(); ++k) {
    const double v = yt[k];
    const double Y = std::round(py(v)) + 0.5;
    cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
    cairo_move_to(cr, left, Y);
    cairo_line_to(cr, left + pw, Y);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, left - fs * 0.35, Y);
    cairo_line_to(cr, left, Y);
    cairo_stroke(cr);
    show_text_at(cr, ylab[k], left - fs * 0.5, Y, 1.0, 0.5);
  }
  // Frame.
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, std::round(left) + 0.5, std::round(top) + 0.5, std::round(pw), std::round(ph));
  cairo_stroke(cr);

  // Axis labels and title.
  cairo_set_font_size(cr, fs);
  if (!spec.x_label.empty()) show_text_at(cr, spec.x_label, left + pw / 2, H - fs * 1.9, 0.5, 0.0);
  if (!spec.y_label.empty()) {
    cairo_save(cr);
    cairo_translate(cr, fs * 0.4, top + ph / 2);
    cairo_rotate(cr, -M_PI / 2);
    show_text_at(cr, spec.y_label, 0, 0, 0.5, 0.0);
    cairo_restore(cr);
  }
  if (!spec.title.empty()) {
    cairo_set_font_size(cr, fs * 1.15);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
    show_text_at(cr, spec.title, left + pw / 2, fs * 0.5, 0.5, 0.0);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  }

  // Series, clipped to the plot area.
  auto colour_of = [&](std::size_t s) {
    return spec.series[s].color.value_or(kPalette[s % kPalette.size()]);
  };
  cairo_save(cr);
  cairo_rectangle(cr, left, top, pw, ph);
  cairo_clip(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (std::size_t s = 0; s < spec.series.size(); ++s) {
    const Series& se = spec.series[s];
    const auto c = colour_of(s);
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
    if (!se.y_err.empty()) {
      cairo_set_line_width(cr, 1.0);
      for (std::size_t i = 0; i < se.x.size(); ++i) {
        if (!std::isfinite(se.x[i]) || !std::isfinite(se.y[i]) || !std::isfinite(se.y_err[i])) continue;
        const double e = std::abs(se.y_err[i]);
        const double X = px(se.x[i]);
        const double y0 = (ay.log && se.y[i] - e <= 0) ? ay.lo : se.y[i] - e;
        const double Y0 = py(y0), Y1 = py(se.y[i] + e), cap = se.marker_size;
        cairo_move_to(cr, X, Y0);
        cairo_line_to(cr, X, Y1);
        cairo_move_to(cr, X - cap, Y0);
        cairo_line_to(cr, X + cap, Y0);
        cairo_move_to(cr, X - cap, Y1);
        cairo_line_to(cr, X + cap, Y1);
      }
      cairo_stroke(cr);
    }
    if (draws_line(se)) {
      cairo_set_line_width(cr, se.line_width);
      if (se.dashed) {
        const double d[] = {6.0, 4.0};
        cairo_set_dash(cr, d, 2, 0);
      }
      bool pen = false;
      for (std::size_t i = 0; i < se.x.size(); ++i) {
        if (!std::isfinite(se.x[i]) || !std::isfinite(se.y[i])) { pen = false; continue; }
        if (pen) cairo_line_to(cr, px(se.x[i]), py(se.y[i]));
        else cairo_move_to(cr, px(se.x[i]), py(se.y[i]));
        pen = true;
      }
      cairo_stroke(cr);
      cairo_set_dash(cr, nullptr, 0, 0);
    }
    if (se.markers) {
      for (std::size_t i = 0; i < se.x.size(); ++i) {
        if (!std::isfinite(se.x[i]) || !std::isfinite(se.y[i])) continue;
        cairo_new_sub_path(cr);
        cairo_arc(cr, px(se.x[i]), py(se.y[i]), se.marker_size, 0, 2 * M_PI);
      }
      cairo_fill(cr);
    }
  }
  cairo_restore(cr);

  // Legend (top right inside the plot area).
  std::vector<std::size_t> shown;
  for (std::size_t s = 0; s < spec.series.size(); ++s)
    if (!spec.series[s].label.empty()) shown.push_back(s);
  if (spec.legend && !shown.empty()) {
    cairo_set_font_size(cr, fs * 0.85);
    double tw = 0;
    for (auto s : shown) tw = std::max(tw, text_width(cr, spec.series[s].label));
    const double row = fs * 1.25, sample = fs * 2.0, pad = fs * 0.5;
    const double bw = pad * 3 + sample + tw, bh = pad * 2 + row * shown.size();
    // Corner of the plot area that hides the fewest data points (top right on ties).
    const std::array<std::array<double, 2>, 4> corners{{{left + pw - bw - pad, top + pad},
                                                         {left + pad, top + pad},
                                                         {left + pw - bw - pad, top + ph - bh - pad},
                                                         {left + pad, top + ph - bh - pad}}};
    std::size_t best = 0, best_n = std::numeric_limits<std::size_t>::max();
    for (std::size_t k = 0; k < corners.size(); ++k) {
      std::size_t n = 0;
      for (const Series& se : spec.series)
        for (std::size_t i = 0; i < se.x.size(); ++i) {
          if (!std::isfinite(se.x[i]) || !std::isfinite(se.y[i])) continue;
          const double X = px(se.x[i]), Y = py(se.y[i]);
          if (X >= corners[k][0] - pad && X <= corners[k][0] + bw + pad && Y >= corners[k][1] - pad &&
              Y <= corners[k][1] + bh + pad)
            ++n;
        }
      if (n < best_n) {
        best_n = n;
        best = k;
      }
    }
    const double bx = corners[best][0], by = corners[best][1];
    cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
    cairo_rectangle(cr, bx, by, bw, bh);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
    cairo_set_line_width(cr, 1.0);
    cairo_stroke(cr);
    for (std::size_t k = 0; k < shown.size(); ++k) {
      const Series& se = spec.series[shown[k]];
      const auto c = colour_of(shown[k]);
      const double yc = by + pad + row * (k + 0.5);
      cairo_set_source_rgb(cr, c[0], c[1], c[2]);
      if (draws_line(se) || !se.markers) {
        cairo_set_line_width(cr, se.line_width);
        if (se.dashed) {
          const double d[] = {6.0, 4.0};
          cairo_set_dash(cr, d, 2, 0);
        }
        cairo_move_to(cr, bx + pad, yc);
        cairo_line_to(cr, bx + pad + sample, yc);
        cairo_stroke(cr);
        cairo_set_dash(cr, nullptr, 0, 0);
      }
      if (se.markers) {
        cairo_arc(cr, bx + pad + sample / 2, yc, se.marker_size, 0, 2 * M_PI);
        cairo_fill(cr);
      }
      cairo_set_source_rgb(cr, 0, 0, 0);
      show_text_at(cr, se.label, bx + pad * 2 + sample, yc, 0.0, 0.5);
    }
  }

  cairo_surface_flush(surf.get());
  // Atomic write: temp PNG in the same folder, then rename.
  static std::atomic<unsigned> counter{0};
  check_replaceable(path);  // (a folder, a device, an empty path: refused naming it)
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::filesystem::path tmp = path;
  tmp += fmt::format(".tmp.{}.{}.png", ::getpid(), counter++);
  const cairo_status_t st = cairo_surface_write_to_png(surf.get(), tmp.c_str());
  if (st != CAIRO_STATUS_SUCCESS) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(where + ": cannot write PNG: " + cairo_status_to_string(st));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {  // no temp file left behind
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(where + ": cannot replace " + path.string() + " by the new picture");
  }
}

std::string column_words(const std::string& column, double scale) {
  struct Unit { const char* suffix; const char* unit; std::vector<std::pair<double, const char*>> scaled; };
  static const std::vector<Unit> units = {
      {"_m_per_s2", "m/s²", {}},
      {"_m_per_s", "m/s", {{1e3, "mm/s"}}},
      {"_m_per_min", "m/min", {}},
      {"_kg_per_m3", "kg/m³", {}},
      {"_Ns_per_m", "N s/m", {}},
      {"_N_per_m", "N/m", {}},
      {"_A_per_m", "A/m", {}},
      {"_um", "µm", {}},
      {"_ms", "ms", {}},
      {"_Hz", "Hz", {}},
      {"_deg", "°", {}},
      {"_ohm", "Ω", {}},
      {"_m", "m", {{1e6, "µm"}, {1e3, "mm"}, {1e9, "nm"}}},
      {"_s", "s", {{1e3, "ms"}, {1e6, "µs"}}},
      {"_N", "N", {{1e9, "nN"}, {1e12, "pN"}, {1e6, "µN"}}},
      {"_V", "V", {}},
      {"_J", "J", {}},
      {"_F", "F", {}},
      {"_T", "T", {{1e3, "mT"}}},
  };
  std::string words = column, unit;
  for (const auto& u : units) {
    const std::string suf = u.suffix;
    if (column.size() > suf.size() && column.compare(column.size() - suf.size(), suf.size(), suf) == 0) {
      words = column.substr(0, column.size() - suf.size());
      unit = u.unit;
      if (scale != 1.0) {
        std::string to;
        for (const auto& [f, name] : u.scaled)
          if (std::fabs(f / scale - 1.0) < 1e-9) to = name;
        unit = to.empty() ? fmt::format("{:g} {}", 1.0 / scale, u.unit) : to;
      }
      break;
    }
  }
  for (char& ch : words)
    if (ch == '_') ch = ' ';
  if (unit.empty() && scale != 1.0) unit = fmt::format("x {:g}", scale);
  return unit.empty() ? words : words + " [" + unit + "]";
}

}  // namespace nipdem::io
