#include "nipdem/io/render.hpp"

#include <algorithm>
#include <cairo.h>
#include <cmath>
#include <fmt/format.h>
#include <set>
#include <unistd.h>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::io {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {
// Perceptually ordered colour map (dark blue -> cyan -> yellow -> red), v in [0, 1].
void colormap(double v, double& r, double& g, double& b) {
  v = std::clamp(v, 0.0, 1.0);
  const double stops[5][3] = {{0.10, 0.10, 0.45}, {0.10, 0.55, 0.85}, {0.35, 0.80, 0.45}, {0.98, 0.85, 0.20}, {0.85, 0.15, 0.10}};
  const double s = v * 4.0;
  const int i = std::min(3, static_cast<int>(s));
  const double t = s - i;
  r = stops[i][0] + t * (stops[i + 1][0] - stops[i][0]);
  g = stops[i][1] + t * (stops[i + 1][1] - stops[i][1]);
  b = stops[i][2] + t * (stops[i + 1][2] - stops[i][2]);
}
}  // namespace

void render_frame(const Frame& f, const json& geo, const RenderOptions& opt, const fs::path& png, double cmax) {
  const double x0 = geo["window_x_m"][0], x1 = geo["window_x_m"][1];
  const double gap = geo["gap_m"];
  const double rdrum = geo["drum"]["radius_m"], rroll = geo["roller"]["radius_m"];
  const double cdx = geo["drum"]["centre_m"][0], cdy = geo["drum"]["centre_m"][1];
  const double crx = geo["roller"]["centre_m"][0], cry = geo["roller"]["centre_m"][1];
  // vertical extent: from below the roughness to above the drum surface at the window edges
  double depth = 0;
  for (auto& p : geo["roller"]["profile_s_depth_m"]) depth = std::max(depth, p[1].get<double>());
  auto drum_y = [&](double x) { return cdy - std::sqrt(rdrum * rdrum - (x - cdx) * (x - cdx)); };
  auto roll_y = [&](double x) { return cry + std::sqrt(rroll * rroll - (x - crx) * (x - crx)); };
  const double ylo = std::min(roll_y(x0), roll_y(x1)) - depth - 0.1 * gap;
  const double yhi = std::max(drum_y(x0), drum_y(x1)) + 0.1 * gap;
  const int W = opt.width_px;
  const int margin_top = 40, margin_bottom = 60;
  const double scale = W / (x1 - x0);  // px per metre
  const int H = static_cast<int>((yhi - ylo) * scale) + margin_top + margin_bottom;
  cairo_surface_t* surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  cairo_t* cr = cairo_create(surf);
  auto X = [&](double x) { return (x - x0) * scale; };
  auto Y = [&](double y) { return margin_top + (yhi - y) * scale; };
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  // drum (filled above its surface)
  cairo_set_source_rgb(cr, 0.80, 0.82, 0.88);
  cairo_move_to(cr, 0, 0);
  for (int px = 0; px <= W; px += 4) cairo_line_to(cr, px, Y(drum_y(x0 + px / scale)));
  cairo_line_to(cr, W, 0);
  cairo_close_path(cr);
  cairo_fill(cr);
  // roller with its roughness (filled below the surface)
  const auto& prof = geo["roller"]["profile_s_depth_m"];
  const int nper = geo["roller"]["n_periods"];
  const double phase = geo["roller"]["phase_m"];
  const double angle = f.wall_angle.empty() ? 0.0 : f.wall_angle[0];
  cairo_set_source_rgb(cr, 0.72, 0.66, 0.58);
  if (prof.empty() || nper == 0) {
    cairo_move_to(cr, 0, H);
    for (int px = 0; px <= W; px += 4) cairo_line_to(cr, px, Y(roll_y(x0 + px / scale)));
    cairo_line_to(cr, W, H);
  } else {
    const double P = prof.back()[0];
    // arc-length range covering the window
    auto s_of_x = [&](double x) {
      const double phi = std::atan2(roll_y(x) - cry, x - crx) - angle;
      return phi * rroll - phase;
    };
    double sa = s_of_x(x1), sb = s_of_x(x0);
    if (sa > sb) std::swap(sa, sb);
    const int ka = static_cast<int>(std::floor(sa / P)) - 1, kb = static_cast<int>(std::floor(sb / P)) + 1;
    bool first = true;
    for (int k = kb; k >= ka; --k) {
      for (int j = static_cast<int>(prof.size()) - 1; j >= 0; --j) {
        const double s = k * P + prof[j][0].get<double>() + phase;
        const double phi = s / rroll + angle;
        const double rr = rroll - prof[j][1].get<double>();
        const double px = X(crx + rr * std::cos(phi)), py = Y(cry + rr * std::sin(phi));
        if (first) { cairo_move_to(cr, px, H); cairo_line_to(cr, px, py); first = false; }
        else cairo_line_to(cr, px, py);
      }
    }
    double cx, cy;
    cairo_get_current_point(cr, &cx, &cy);
    cairo_line_to(cr, cx, H);
  }
  cairo_close_path(cr);
  cairo_fill(cr);
  // discs
  const std::vector<double>& val = opt.color_by == "force" ? f.force : f.speed;
  for (std::size_t i = 0; i < f.x.size(); ++i) {
    double r, g, b;
    colormap(cmax > 0 ? val[i] / cmax : 0.0, r, g, b);
    cairo_set_source_rgb(cr, r, g, b);
    cairo_arc(cr, X(f.x[i]), Y(f.y[i]), std::max(0.8, f.r[i] * scale), 0, 2 * M_PI);
    cairo_fill_preserve(cr);
    cairo_set_source_rgba(cr, 0, 0, 0, 0.35);
    cairo_set_line_width(cr, 0.6);
    cairo_stroke(cr);
  }
  // magnet edge marker at x = 0
  cairo_set_source_rgba(cr, 0.6, 0, 0, 0.6);
  cairo_set_line_width(cr, 1.0);
  const double dashes[] = {4.0, 4.0};
  cairo_set_dash(cr, dashes, 2, 0);
  cairo_move_to(cr, X(0), Y(ylo));
  cairo_line_to(cr, X(0), margin_top);
  cairo_stroke(cr);
  cairo_set_dash(cr, nullptr, 0, 0);
  // text: time, labels
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 16);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_move_to(cr, 10, 26);
  cairo_show_text(cr, fmt::format("t = {:.4f} ms   particles: {}   colour: {} (max {:.3g} {})", f.time * 1e3,
                                  std::set<int>(f.body.begin(), f.body.end()).size(), opt.color_by, cmax,
                                  opt.color_by == "force" ? "N" : "m/s").c_str());
  cairo_set_font_size(cr, 13);
  cairo_move_to(cr, X(0) + 4, Y(ylo) - 4);
  cairo_show_text(cr, "x = 0 (magnet edge)");
  cairo_move_to(cr, 10, Y(drum_y(x0)) - 6 > margin_top + 14 ? Y(drum_y(x0)) - 6 : margin_top + 14);
  cairo_show_text(cr, "DI-drum  <- moves");
  cairo_move_to(cr, W - 200, H - margin_bottom - 6);
  cairo_show_text(cr, "imaging roller  moves ->");
  // scale bar: 100 um
  const double bar = 100e-6 * scale;
  cairo_set_line_width(cr, 3);
  cairo_move_to(cr, 20, H - 25);
  cairo_line_to(cr, 20 + bar, H - 25);
  cairo_stroke(cr);
  cairo_move_to(cr, 20, H - 8);
  cairo_show_text(cr, "100 um");
  // colour bar
  for (int i = 0; i < 200; ++i) {
    double r, g, b;
    colormap(i / 199.0, r, g, b);
    cairo_set_source_rgb(cr, r, g, b);
    cairo_rectangle(cr, W - 260 + i, H - 35, 1, 14);
    cairo_fill(cr);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_move_to(cr, W - 260, H - 8);
  cairo_show_text(cr, "0");
  cairo_move_to(cr, W - 90, H - 8);
  cairo_show_text(cr, fmt::format("{:.3g}", cmax).c_str());
  cairo_destroy(cr);
  fs::create_directories(png.parent_path());
  fs::path tmp = png;
  tmp += ".tmp." + std::to_string(::getpid());
  const cairo_status_t st = cairo_surface_write_to_png(surf, tmp.c_str());
  cairo_surface_destroy(surf);
  if (st != CAIRO_STATUS_SUCCESS) throw std::runtime_error("cannot write " + png.string() + ": " + cairo_status_to_string(st));
  fs::rename(tmp, png);
}

int render_run(const fs::path& dir, const RenderOptions& opt) {
  if (!fs::exists(dir / "summary.json") && !fs::exists(dir / "frames.json"))
    throw InputError(dir.string() + ": not a nipdem run folder (no summary.json / frames.json)");
  if (opt.color_by != "speed" && opt.color_by != "force")
    throw_input("render", "--color-by", opt.color_by, "unknown colouring", "speed, force");
  json geometry;
  if (fs::exists(dir / "summary.json")) geometry = json::parse(read_file(dir / "summary.json"))["geometry"];
  else throw InputError(dir.string() + ": summary.json missing (run not finished); render needs its geometry");
  const json frames = json::parse(read_file(dir / "frames.json"));
  if (frames.empty()) throw InputError(dir.string() + ": no particle snapshots (was output.vtk = false?)");
  double cmax = opt.color_max;
  if (cmax <= 0) {
    // a robust scale: 98th percentile over the last frame
    Frame last = read_vtp(dir / frames.back()[1].get<std::string>());
    std::vector<double> v = opt.color_by == "force" ? last.force : last.speed;
    if (!v.empty()) {
      std::sort(v.begin(), v.end());
      cmax = v[static_cast<std::size_t>(0.98 * (v.size() - 1))];
    }
    if (cmax <= 0) cmax = 1.0;
  }
  int n = 0;
  for (const auto& f : frames) {
    Frame fr = read_vtp(dir / f[1].get<std::string>());
    render_frame(fr, geometry, opt, dir / "frames" / fmt::format("frame_{:06d}.png", n), cmax);
    ++n;
  }
  return n;
}

}  // namespace nipdem::io
