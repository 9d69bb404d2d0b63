// `nipdem field probe|line`: the magnet field (analytic preset or imported map), its gradient and
// the magnet force on a toner particle (thesis §2.4.2 eq. 2.4.34, §4.5 eq. 4.5.1; fig. 2.12 analogue).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <fmt/format.h>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>

#include "nipdem/core/error.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/field_map.hpp"
#include "nipdem/models/magnet_field.hpp"
#include "nipdem/io/plot.hpp"
#include <filesystem>
#include "registry.hpp"

namespace {
using namespace nipdem;

using nip::MagnetMaterial;
using nip::require_finite;

// The magnet, toner and radius options of probe and line (nip/presets.hpp), and --json.
struct Common {
  nip::FieldOptions field;
  bool json = false;
};

void add_common(CLI::App* sub, Common& c) {
  sub->add_option("--preset", c.field.preset, "magnet and toner preset: black or color")->capture_default_str();
  sub->add_option("--map", c.field.map, "field map CSV (x_m,y_m,Bx_T,By_T) instead of the preset magnet");
  sub->add_option("--radius", c.field.radius_m, "toner radius [m] in [1e-7, 1e-3] (default: d50/2 of the preset toner, Table 2.1)");
  sub->add_option("--tip-depth", c.field.tip_depth_m, "override: depth of the knife edge / pole face below the roller surface [m], in [0, 5e-3]");
  sub->add_option("--br", c.field.br_T, "override: remanence of the knife blade / colour pole [T], in [-2.5, 2.5]");
  sub->add_flag("--json", c.json, "print one JSON object on stdout");
}

struct ProbeOpts {
  Common c;
  double x = 0, y = 100e-6;
};
struct ExportOpts {
  std::string preset = "black";
  double x0 = -500e-6, x1 = 500e-6, y0 = 0.0, y1 = 400e-6;
  int nx = 51, ny = 21;
  std::string out;
};
struct LineOpts {
  Common c;
  double y = 100e-6, x0 = -500e-6, x1 = 500e-6;
  int n = 201;
  std::string out;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* field = nipdem::cli::group(app, "field");

  auto* probe = field->add_subcommand("probe", "B, grad B and the magnet force on a toner particle at one point");
  auto po = std::make_shared<ProbeOpts>();
  add_common(probe, po->c);
  probe->add_option("--x", po->x, "x [m] along the process direction, 0 at the magnet edge")->required();
  probe->add_option("--y", po->y, "y [m] above the imaging-roller surface")->required();
  probe->callback([po] {
    // The checks (a point on or inside the magnet, a value that is not finite) and the values
    // are those of Python's nipdem.field_probe (one library function).
    const nlohmann::json j = nip::field_probe(po->c.field, po->x, po->y);
    if (po->c.json) {
      cli::print_json(j.dump());
    } else {
      auto d = [&](const char* k) { return j[k].get<double>(); };
      std::printf("%s\n", j["source"].get<std::string>().c_str());
      std::printf("  point          (%g, %g) m\n", d("x_m"), d("y_m"));
      std::printf("  B              (%.6g, %.6g) T, |B| = %.6g T\n", d("Bx_T"), d("By_T"), d("B_T"));
      std::printf("  grad B         [[%.6g, %.6g], [%.6g, %.6g]] T/m\n", d("dBx_dx_T_per_m"), d("dBx_dy_T_per_m"),
                  d("dBy_dx_T_per_m"), d("dBy_dy_T_per_m"));
      std::printf("  toner R        %g m, moment (%.4g, %.4g) A m^2\n", d("radius_m"), d("mx_Am2"), d("my_Am2"));
      std::printf("  magnet force   (%.6g, %.6g) N, |F| = %.6g N\n", d("Fx_N"), d("Fy_N"), d("force_N"));
    }
  });

  auto* exp = field->add_subcommand("export", "Sample a preset magnet on a regular grid as a field-map CSV");
  auto eo = std::make_shared<ExportOpts>();
  exp->add_option("--preset", eo->preset, "magnet preset: black or color")->capture_default_str();
  exp->add_option("--x0", eo->x0, "first x [m]")->capture_default_str();
  exp->add_option("--x1", eo->x1, "last x [m]")->capture_default_str();
  // Ranges checked on the text, as for `field line --n` below.
  exp->add_option("--nx", eo->nx, "nodes along x, in [5, 1e5]")->capture_default_str()->check(CLI::Range(5, 100000).description(""));
  exp->add_option("--y0", eo->y0, "first y [m]")->capture_default_str();
  exp->add_option("--y1", eo->y1, "last y [m]")->capture_default_str();
  exp->add_option("--ny", eo->ny, "nodes along y, in [5, 1e5]")->capture_default_str()->check(CLI::Range(5, 100000).description(""));
  exp->add_option("--out", eo->out, "output CSV file (written atomically)")->required();
  exp->callback([eo] {
    require_range("field export", "--nx", eo->nx, 5, 1e5);
    require_range("field export", "--ny", eo->ny, 5, 1e5);
    if (eo->preset != "black" && eo->preset != "color") throw_input("field export", "--preset", eo->preset, "unknown preset", "black, color");
    require_range("field export", "--x0", eo->x0, -1.0, 1.0);
    require_range("field export", "--x1", eo->x1, -1.0, 1.0);
    require_range("field export", "--y0", eo->y0, -1.0, 1.0);
    require_range("field export", "--y1", eo->y1, -1.0, 1.0);
    if (static_cast<double>(eo->nx) * eo->ny > 1e7)
      throw_input("field export", "--nx, --ny", fmt::format("{} x {}", eo->nx, eo->ny), "too many nodes for a map nipdem reads", "nx * ny <= 1e7");
    if (!(eo->x1 > eo->x0)) throw_input("field export", "--x1", fmt::format("{:g}", eo->x1), "must exceed x0", "> x0");
    if (!(eo->y1 > eo->y0)) throw_input("field export", "--y1", fmt::format("{:g}", eo->y1), "must exceed y0", "> y0");
    const auto f = nip::preset_magnet(eo->preset);
    io::write_file_atomic(eo->out, io::field_to_csv(f, eo->x0, eo->x1, eo->nx, eo->y0, eo->y1, eo->ny,
                                                    f.describe() + ", magnet frame (see docs/magnetic.md)"));
    std::fprintf(stderr, "wrote %s (%d x %d nodes)\n", eo->out.c_str(), eo->nx, eo->ny);
  });

  auto* line = field->add_subcommand("line", "CSV of |B|, grad B and the magnet force along a line y = const");
  auto lo = std::make_shared<LineOpts>();
  add_common(line, lo->c);
  line->add_option("--y", lo->y, "height above the roller surface [m]")->capture_default_str();
  line->add_option("--x0", lo->x0, "first x [m]")->capture_default_str();
  line->add_option("--x1", lo->x1, "last x [m]")->capture_default_str();
  // The range is checked on the text (a value beyond int was "Could not convert", without the
  // range); no description, so that the type stays INT for main.cpp's plain-integer check.
  line->add_option("--n", lo->n, "number of points, in [2, 1e6]")->capture_default_str()->check(CLI::Range(2, 1000000).description(""));
  line->add_option("--out", lo->out, "output CSV file (written atomically); its picture goes next to it, the name with .png (so not itself a .png)")->required();
  line->callback([lo] {
    require_range("field line", "--n", lo->n, 2, 1e6);
    require_range("field line", "--y", lo->y, -1.0, 1.0);
    require_range("field line", "--x0", lo->x0, -1.0, 1.0);
    require_range("field line", "--x1", lo->x1, -1.0, 1.0);
    if (!(lo->x1 > lo->x0)) throw_input("field line", "--x1", fmt::format("{:g}", lo->x1), "must exceed x0", "> x0");
    // The picture goes to OUT with the extension .png: an OUT ending in .png would be both (and
    // .PNG too on a file system that ignores case).
    std::filesystem::path png = lo->out;
    std::string ext = png.extension().string();
    for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    png.replace_extension(".png");
    if (ext == ".png")
      throw_input("field line", "--out", lo->out, "the CSV and its picture (the same name with .png) would be the same file",
                  "a CSV name not ending in .png, e.g. " + std::filesystem::path(lo->out).replace_extension(".csv").string());
    nip::check_field_options(lo->c.field, "field line");
    const nip::FieldSetup s = nip::make_field_setup(lo->c.field);
    const std::string keys = "--y, --x0, --x1, --n";
    const MagnetMaterial material(*s.field);
    std::vector<std::vector<double>> rows;
    std::vector<double> crossings;
    double prev_fx = 0, prev_x = 0, fmax = 0;
    io::Series sb, sfx, sfy;
    sb.label = "|B| [T] x 100";
    sfx.label = "F_x [nN]";
    sfy.label = "F_y [nN]";
    for (int i = 0; i < lo->n; ++i) {
      const double x = lo->x0 + (lo->x1 - lo->x0) * i / (lo->n - 1);
      material.require_outside({x, lo->y}, "field line", keys, "a line");
      const auto smp = s.field->at({x, lo->y});
      const Vec2 m = magnet::induced_moment(s.toner, s.radius_m, smp.B);
      const Vec2 F = magnet::dipole_force(m, smp);
      rows.push_back({x, lo->y, smp.B.x, smp.B.y, norm(smp.B), smp.dB.xx, smp.dB.xy, smp.dB.yx, smp.dB.yy, m.x, m.y, F.x, F.y, norm(F)});
      require_finite(rows.back(), {x, lo->y}, "field line", keys, "a line off the magnet's corners and edges");
      if (i > 0 && (prev_fx > 0) != (F.x > 0))  // linear interpolation of the sign change of F_x
        crossings.push_back(prev_x + (x - prev_x) * prev_fx / (prev_fx - F.x));
      prev_fx = F.x;
      prev_x = x;
      fmax = std::max(fmax, norm(F));
      for (auto* sr : {&sb, &sfx, &sfy}) sr->x.push_back(x * 1e6);
      sb.y.push_back(100.0 * norm(smp.B));
      sfx.y.push_back(F.x * 1e9);
      sfy.y.push_back(F.y * 1e9);
    }
    const std::vector<std::string> columns = {"x_m", "y_m", "Bx_T", "By_T", "B_T", "dBx_dx_T_per_m", "dBx_dy_T_per_m", "dBy_dx_T_per_m",
                                              "dBy_dy_T_per_m", "mx_Am2", "my_Am2", "Fx_N", "Fy_N", "F_N"};
    io::write_file_atomic(lo->out, fmt::format("# {}; toner preset {}, R = {:g} m; force F = (m.grad)B, m = m(B) of eq. 4.5.1\n",
                                               s.field->describe(), lo->c.field.preset, s.radius_m) +
                                       io::format_csv(columns, rows, std::vector<std::string>(columns.size(), "{:.9g}")));
    // The picture of the same data (thesis fig. 2.12 analogue), next to the CSV.
    io::PlotSpec plot;
    plot.title = fmt::format("Magnet field and force on a toner of R = {:.3g} um at y = {:.3g} um", s.radius_m * 1e6, lo->y * 1e6);
    plot.x_label = "x [um] (magnet edge = 0)";
    plot.y_label = "force [nN], |B| [T/100]";
    plot.series = {sb, sfx, sfy};
    io::write_plot_png(png, plot);
    if (lo->c.json) {
      cli::print_json(nlohmann::json{{"out", lo->out},
                                     {"n", lo->n},
                                     {"y_m", lo->y},
                                     {"fx_sign_changes_m", crossings},
                                     {"max_force_N", fmax}}
                          .dump());
    } else {
      std::printf("wrote %s (%d points); F_x changes sign at", lo->out.c_str(), lo->n);
      for (double c : crossings) std::printf(" %.4g m", c);
      std::printf("\n");
    }
  });
});
}  // namespace
