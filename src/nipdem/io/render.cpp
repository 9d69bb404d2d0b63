#include "nipdem/io/render.hpp"

#include <algorithm>
#include <cairo.h>
#include <cerrno>
#include <cmath>
#include <limits>
#include <fmt/format.h>
#include <set>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"

namespace nipdem::io {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {
// Viridis (perceptually uniform, readable in grey and by colour-blind readers): its colours at
// v = 0, 0.1, ..., 1, linearly interpolated in between.
constexpr double kViridis[11][3] = {{68, 1, 84},    {72, 40, 120},  {62, 73, 137},  {49, 104, 142},
                                    {38, 130, 142}, {31, 158, 137}, {53, 183, 121}, {110, 206, 88},
                                    {181, 222, 43}, {221, 227, 24}, {253, 231, 37}};
double nice_number(double v) {
  // 1, 2, 2.5 or 5 x 10^k, the smallest not below v
  const double mag = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= v * (1 - 1e-9)) return m * mag;
  return 10 * mag;
}
}  // namespace

std::array<double, 3> viridis(double v) {
  v = std::isfinite(v) ? std::clamp(v, 0.0, 1.0) : 0.0;
  const double s = v * 10.0;
  const int i = std::min(9, static_cast<int>(s));
  const double t = s - i;
  std::array<double, 3> c;
  for (int k = 0; k < 3; ++k) c[k] = (kViridis[i][k] + t * (kViridis[i + 1][k] - kViridis[i][k])) / 255.0;
  return c;
}

double percentile(std::vector<double> v, double q) {
  std::erase_if(v, [](double x) { return !std::isfinite(x); });
  if (v.empty()) return 0.0;
  const std::size_t k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1) + 0.5);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

ColourScale colour_scale(const std::string& color_by, double max_si) {
  ColourScale c;
  if (color_by == "force") {
    c.label = "|force| per disc [nN]";
    c.factor = 1e9;
  } else {
    c.label = "speed [mm/s]";
    c.factor = 1e3;
  }
  c.max = max_si;
  return c;
}

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
  // layout: title line on top, y axis (µm) on the left, x axis (µm) and the colour bar below
  const int W = opt.width_px;
  const int margin_top = 40, margin_left = 70, margin_right = 20, margin_bottom = 110;
  const double scale = (W - margin_left - margin_right) / (x1 - x0);  // px per metre
  const int H = static_cast<int>((yhi - ylo) * scale) + margin_top + margin_bottom;
  const double plot_bottom = H - margin_bottom;
  cairo_surface_t* surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  cairo_t* cr = cairo_create(surf);
  auto X = [&](double x) { return margin_left + (x - x0) * scale; };
  auto Y = [&](double y) { return margin_top + (yhi - y) * scale; };
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_save(cr);
  cairo_rectangle(cr, X(x0), Y(yhi), X(x1) - X(x0), Y(ylo) - Y(yhi));
  cairo_clip(cr);
  // drum (filled above its surface)
  cairo_set_source_rgb(cr, 0.80, 0.82, 0.88);
  cairo_move_to(cr, X(x0), Y(yhi));
  for (int px = 0; px <= W; px += 4) cairo_line_to(cr, X(x0) + px, Y(drum_y(x0 + px / scale)));
  cairo_line_to(cr, X(x1) + 4, Y(yhi));
  cairo_close_path(cr);
  cairo_fill(cr);
  // roller with its roughness (filled below the surface)
  const auto& prof = geo["roller"]["profile_s_depth_m"];
  const int nper = geo["roller"]["n_periods"];
  const double phase = geo["roller"]["phase_m"];
  const double angle = f.wall_angle.empty() ? 0.0 : f.wall_angle[0];
  cairo_set_source_rgb(cr, 0.72, 0.66, 0.58);
  if (prof.empty() || nper == 0) {
    cairo_move_to(cr, X(x0), plot_bottom);
    for (int px = 0; px <= W; px += 4) cairo_line_to(cr, X(x0) + px, Y(roll_y(x0 + px / scale)));
    cairo_line_to(cr, X(x1) + 4, plot_bottom);
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
        if (first) { cairo_move_to(cr, px, plot_bottom); cairo_line_to(cr, px, py); first = false; }
        else cairo_line_to(cr, px, py);
      }
    }
    double cx, cy;
    cairo_get_current_point(cr, &cx, &cy);
    cairo_line_to(cr, cx, plot_bottom);
  }
  cairo_close_path(cr);
  cairo_fill(cr);
  // discs, viridis over [0, cmax]; faster/stronger ones take the top colour
  const std::vector<double>& val = opt.color_by == "force" ? f.force : f.speed;
  for (std::size_t i = 0; i < f.x.size(); ++i) {
    const auto c = viridis(cmax > 0 && i < val.size() ? val[i] / cmax : 0.0);
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
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
  cairo_line_to(cr, X(0), Y(yhi));
  cairo_stroke(cr);
  cairo_set_dash(cr, nullptr, 0, 0);
  cairo_restore(cr);
  // frame and axes in µm (x from the magnet edge, y from the roller lands at the nip)
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, X(x0), Y(yhi), X(x1) - X(x0), Y(ylo) - Y(yhi));
  cairo_stroke(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 13);
  auto text = [&](const std::string& t, double x, double y, double align_x) {
    cairo_text_extents_t e;
    cairo_text_extents(cr, t.c_str(), &e);
    cairo_move_to(cr, x - align_x * e.x_advance, y);
    cairo_show_text(cr, t.c_str());
  };
  const double xstep = nice_number((x1 - x0) * 1e6 / 8.0), ystep = nice_number((yhi - ylo) * 1e6 / 5.0);
  for (double v = std::ceil(x0 * 1e6 / xstep) * xstep; v <= x1 * 1e6 + 1e-9; v += xstep) {
    const double px = X(v * 1e-6);
    cairo_move_to(cr, px, Y(ylo));
    cairo_line_to(cr, px, Y(ylo) + 5);
    cairo_stroke(cr);
    text(fmt::format("{:g}", std::abs(v) < 1e-9 ? 0.0 : v), px, Y(ylo) + 19, 0.5);
  }
  for (double v = std::ceil(ylo * 1e6 / ystep) * ystep; v <= yhi * 1e6 + 1e-9; v += ystep) {
    const double py = Y(v * 1e-6);
    cairo_move_to(cr, X(x0) - 5, py);
    cairo_line_to(cr, X(x0), py);
    cairo_stroke(cr);
    text(fmt::format("{:g}", std::abs(v) < 1e-9 ? 0.0 : v), X(x0) - 8, py + 4, 1.0);
  }
  text("x [µm] (0 = magnet edge)", X(0.5 * (x0 + x1)), Y(ylo) + 38, 0.5);
  cairo_save(cr);
  cairo_translate(cr, 20, Y(0.5 * (ylo + yhi)));
  cairo_rotate(cr, -M_PI / 2);
  text("y [µm] (0 = roller lands)", 0, 0, 0.5);
  cairo_restore(cr);
  // title: time, particles
  const ColourScale cs = colour_scale(opt.color_by, cmax);
  cairo_set_font_size(cr, 16);
  text(fmt::format("t = {:.4f} ms   particles: {}", f.time * 1e3, std::set<int>(f.body.begin(), f.body.end()).size()), margin_left, 26, 0.0);
  cairo_set_font_size(cr, 13);
  text("DI-drum, surface moves to -x", X(x0) + 8, Y(yhi) + 18, 0.0);
  text("imaging roller, surface moves to +x", X(x1) - 8, Y(ylo) - 8, 1.0);
  // colour bar with its quantity and unit
  const double bw = std::min(320.0, 0.4 * W), bx = X(x1) - bw, by = H - 50;
  for (int i = 0; i < static_cast<int>(bw); ++i) {
    const auto c = viridis(i / (bw - 1));
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
    cairo_rectangle(cr, bx + i, by, 1.2, 14);
    cairo_fill(cr);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  text("0", bx, by + 30, 0.5);
  const double top = cmax * cs.factor;
  text(top >= 100 ? fmt::format(">= {:.0f}", top) : fmt::format(">= {:.3g}", top), bx + bw, by + 30, 1.0);
  text(cs.label, bx - 10, by + 12, 1.0);
  // scale bar: 100 µm
  const double bar = 100e-6 * scale;
  cairo_set_line_width(cr, 3);
  cairo_move_to(cr, X(x0), by + 7);
  cairo_line_to(cr, X(x0) + bar, by + 7);
  cairo_stroke(cr);
  text("100 µm", X(x0) + 0.5 * bar, by + 30, 0.5);
  cairo_destroy(cr);
  check_replaceable(png);
  fs::create_directories(png.parent_path());
  fs::path tmp = png;
  tmp += ".tmp." + std::to_string(::getpid());
  const cairo_status_t st = cairo_surface_write_to_png(surf, tmp.c_str());
  cairo_surface_destroy(surf);
  std::error_code ec;
  if (st != CAIRO_STATUS_SUCCESS) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write " + png.string() + ": " + cairo_status_to_string(st));
  }
  fs::rename(tmp, png, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot replace " + png.string() + " by the new picture");
  }
}

int render_run(const fs::path& dir, const RenderOptions& opt) {
  if (!fs::exists(dir / "summary.json") && !fs::exists(dir / "frames.json"))
    throw InputError(dir.string() + ": not a nipdem run folder (no summary.json / frames.json)");
  if (opt.color_by != "speed" && opt.color_by != "force")
    throw_input("render", "--color-by", opt.color_by, "unknown colouring", "speed, force");
  if (!(opt.color_max >= 0.0 && std::isfinite(opt.color_max)))
    throw_input("render", "--color-max", fmt::format("{:g}", opt.color_max), "must be a finite value >= 0",
                "[0, inf) (0: automatic scale)");
  // Both files are a run's own outputs; anything else in their place is refused naming the file
  // (valid JSON of another shape too: it would otherwise fail deep in the drawing, exit 1).
  auto parse = [](const fs::path& p) {
    try {
      return json::parse(read_file(p));
    } catch (const json::exception& e) {
      throw InputError(p.string() + ": not JSON (" + std::string(e.what()).substr(0, 120) + ")");
    }
  };
  if (!fs::exists(dir / "summary.json"))
    throw InputError(dir.string() + ": summary.json missing (run not finished); render needs its geometry");
  const fs::path summary_file = dir / "summary.json", frames_file = dir / "frames.json";
  const json summary = parse(summary_file);
  if (!summary.is_object() || !summary.contains("geometry") || !summary["geometry"].is_object())
    throw InputError(summary_file.string() + ": not the summary of a nipdem run (no \"geometry\" object)");
  const json geometry = summary["geometry"];
  const json frames = fs::exists(frames_file) ? parse(frames_file) : json::array();
  if (!frames.is_array()) throw InputError(frames_file.string() + ": not a frame list of a nipdem run (not an array)");
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const json& f = frames[k];
    if (!f.is_array() || f.size() != 2 || !f[0].is_number() || !f[1].is_string())
      throw InputError(fmt::format("{}: entry {} is not a frame [time_s, \"file.vtp\"]", frames_file.string(), k));
  }
  if (frames.empty()) throw InputError(dir.string() + ": no particle snapshots (was output.vtk = false?)");
  double cmax = opt.color_max;
  if (cmax <= 0) {
    // A scale robust to a few fast strays (one particle knocked off in a collision would set a
    // maximum and leave every other disc dark) and to a few violent frames (the start, when the
    // magnet pulls the whole drum layer across the gap): the median over the frames of each
    // frame's 98th percentile. Faster discs take the top colour ("≥" on the colour bar).
    std::vector<double> per_frame;
    for (const auto& f : frames) {
      Frame fr = read_vtp(dir / f[1].get<std::string>());
      per_frame.push_back(percentile(opt.color_by == "force" ? fr.force : fr.speed, 0.98));
    }
    cmax = percentile(std::move(per_frame), 0.5);
    if (!(cmax > 0)) cmax = 1.0;
  }
  int n = 0;
  for (const auto& f : frames) {
    Frame fr = read_vtp(dir / f[1].get<std::string>());
    try {
      render_frame(fr, geometry, opt, dir / "frames" / fmt::format("frame_{:06d}.png", n), cmax);
    } catch (const json::exception& e) {  // a key missing or of another type in the geometry
      throw InputError(summary_file.string() + ": its \"geometry\" is not a nipdem run's (" + std::string(e.what()).substr(0, 120) + ")");
    }
    ++n;
  }
  if (fs::exists(dir / "coverage.csv")) write_coverage_png(dir / "coverage.csv", dir / "coverage.png");
  return n;
}

void write_coverage_png(const fs::path& csv, const fs::path& png) {
  const CsvTable t = read_csv(csv);
  const auto s0 = t.column("s_begin_m"), s1 = t.column("s_end_m"), cov = t.column("coverage"), volt = t.column("track_voltage_V");
  PlotSpec p;
  p.title = "Coverage of the drum track (" + csv.parent_path().filename().string() + ")";
  p.x_label = "drum surface position s [µm]";
  p.y_label = "covered (1) or not (0)";
  p.y_min = -0.1;
  p.y_max = 1.35;
  p.width = 900;
  p.height = 420;
  // The intended line: where the track is at another voltage than at its lowest (off) level.
  double voff = std::numeric_limits<double>::infinity();
  for (double v : volt) voff = std::min(voff, std::fabs(v));
  Series intended;
  intended.label = "intended line (track voltage on)";
  intended.dashed = true;
  intended.color = std::array<double, 3>{0.85, 0.33, 0.10};
  bool inside = false;
  for (std::size_t i = 0; i < s0.size(); ++i) {
    const bool on = std::fabs(volt[i]) > voff + 1e-9;
    if (on != inside) {
      const double s = 1e6 * s0[i];
      intended.x.insert(intended.x.end(), {s, s});
      intended.y.insert(intended.y.end(), on ? std::initializer_list<double>{0.0, 1.0} : std::initializer_list<double>{1.0, 0.0});
      inside = on;
    }
  }
  if (inside && !s1.empty()) {
    intended.x.insert(intended.x.end(), {1e6 * s1.back(), 1e6 * s1.back()});
    intended.y.insert(intended.y.end(), {1.0, 0.0});
  }
  Series bins;
  bins.label = "toner printed in the d50/4 bin (1) or not (0)";
  bins.line = false;  // 0/1 per bin: joining them would draw edges the bins do not resolve
  bins.markers = true;
  bins.marker_size = 2.5;
  for (std::size_t i = 0; i < s0.size(); ++i) {
    bins.x.push_back(0.5e6 * (s0[i] + s1[i]));
    bins.y.push_back(cov[i]);
  }
  p.series.push_back(bins);
  if (!intended.x.empty()) p.series.push_back(intended);
  write_plot_png(png, p);
}

fs::path write_movie(const fs::path& run_dir, int fps) {
  // ffmpeg is started without a shell (posix_spawnp with an argument vector), so a folder name
  // with spaces, quotes or $ reaches it unchanged.
  const fs::path frames = run_dir / "frames", movie = frames / "movie.mp4";
  check_replaceable(movie);
  fs::path tmp = movie;
  tmp += ".tmp." + std::to_string(::getpid()) + ".mp4";
  const std::string pattern = (frames / "frame_%06d.png").string(), out = tmp.string(), rate = std::to_string(fps);
  std::vector<std::string> args = {"ffmpeg", "-y", "-loglevel", "error", "-framerate", rate, "-i", pattern,
                                   "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", out};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid;
  const int rc = posix_spawnp(&pid, "ffmpeg", nullptr, nullptr, argv.data(), environ);
  if (rc != 0)
    throw std::runtime_error("--movie needs ffmpeg on PATH (scripts/install-deps installs it; apt-get install ffmpeg); the PNG frames were written");
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error("ffmpeg failed to assemble " + movie.string());
  }
  std::error_code ec;
  fs::rename(tmp, movie, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot replace " + movie.string() + " by the new movie");
  }
  return movie;
}

}  // namespace nipdem::io
