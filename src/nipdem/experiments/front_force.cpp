#include "nipdem/experiments/front_force.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"
#include "nipdem/models/electric_force.hpp"
#include "nipdem/models/magnet_field.hpp"
#include "nipdem/version.hpp"

namespace nipdem::experiments {

namespace {
constexpr const char* kWhere = "experiment front-force";
// The print voltage of §2.5.1 ("alternatively 0 or 40 Volt") when the configuration has no [print].
constexpr double kThesisPrintVoltage_V = 40.0;
// Largest print voltage [V]: far above any DI print voltage (tens of V), and small enough that the
// forces stay finite (1e308 V gave null results, exit 0).
constexpr double kMaxVoltage_V = 1e4;

// Grey dashed horizontal line at y over [x0, x1] (x in m, plotted in µm).
io::Series reference_line(const std::string& label, double x0, double x1, double y) {
  io::Series s;
  s.label = label;
  s.x = {1e6 * x0, 1e6 * x1};
  s.y = {y, y};
  s.dashed = true;
  s.color = std::array<double, 3>{0.3, 0.3, 0.3};
  return s;
}
}  // namespace

void FrontForceOptions::validate() const {
  require_range(kWhere, "--gap", gap_m, 20e-6, 5e-3);
  if (!(voltage_V >= 0 && voltage_V <= kMaxVoltage_V))
    throw_input(kWhere, "--voltage", fmt::format("{:g}", voltage_V), "out of range",
                fmt::format("[0, {:g}] V (0: the configuration's)", kMaxVoltage_V));
  if (l_m.empty()) throw_input(kWhere, "--l", "", "need at least one distance");
  for (double l : l_m) require_range(kWhere, "--l", l, 1e-8, 1e-4);
  if (!(x_max_m > x_min_m)) throw_input(kWhere, "--x-max", fmt::format("{:g}", x_max_m), "must exceed --x-min", fmt::format("> {:g}", x_min_m));
  require_range(kWhere, "--x-min", x_min_m, -5e-3, 5e-3);
  require_range(kWhere, "--x-max", x_max_m, -5e-3, 5e-3);
  require_range(kWhere, "--dx", dx_m, 1e-7, x_max_m - x_min_m);
  if ((x_max_m - x_min_m) / dx_m > 1e5) throw_input(kWhere, "--dx", fmt::format("{:g}", dx_m), "more than 1e5 points per row", ">= (x_max - x_min) / 1e5");
  if (!(front_x_max_m >= front_x_min_m))
    throw_input(kWhere, "--front-x-max", fmt::format("{:g}", front_x_max_m), "below --front-x-min", fmt::format(">= {:g}", front_x_min_m));
  // The front region's results (crossing distance, share to the drum) come from the x grid: a
  // region outside it, or in part outside it, would be reported from fewer points or none at all
  // (all zeros before), so it must lie within [--x-min, --x-max] and hold a grid point.
  for (const auto& [key, v] : {std::pair{"--front-x-min", front_x_min_m}, std::pair{"--front-x-max", front_x_max_m}})
    if (!(v >= x_min_m && v <= x_max_m))
      throw_input(kWhere, key, fmt::format("{:g}", v), "the front region must lie within the x range",
                  fmt::format("[{:g}, {:g}] (--x-min, --x-max)", x_min_m, x_max_m));
  const double first = std::ceil((front_x_min_m - x_min_m) / dx_m - 1e-3);  // first grid index in the region
  const double last = std::floor((x_max_m - x_min_m) / dx_m + 1e-9);           // last grid index (front_force's nx - 1)
  if (!(first <= last && x_min_m + first * dx_m <= front_x_max_m + 1e-3 * dx_m))
    throw_input(kWhere, "--front-x-min, --front-x-max", fmt::format("[{:g}, {:g}]", front_x_min_m, front_x_max_m),
                fmt::format("front region holds no point of the x grid (--x-min {:g} step --dx {:g})", x_min_m, dx_m),
                "a region holding at least one grid point (widen it or make --dx smaller)");
}

FrontForcePoint FrontForceModel::at(double x, double l) const {
  const Vec2 c = cfg.electric.drum_centre;
  const double Rd = cfg.drum_radius;
  const double reach = Rd + l + radius_m;  // drum centre to particle centre
  const double dx = x - c.x;
  FrontForcePoint p;
  p.x_m = x;
  p.l_m = l;
  p.y_m = c.y - std::sqrt(reach * reach - dx * dx);
  const double ny = (c.y - p.y_m) / reach;  // y-component of the unit vector to the drum centre
  const double d = cfg.electric.dielectric_layer
                       ? electric::effective_gap(l, cfg.electric.layer_thickness, cfg.electric.layer_permittivity)  // eq. 2.5.43
                       : l;
  p.electric_exact_N = electric::force_exact(radius_m, voltage_V, d) * ny;
  p.electric_printed_N = std::fabs(electric::force_series_as_printed(radius_m, voltage_V, d)) * ny;  // eq. 2.5.31 as printed
  if (field) {
    const magnet::Sample s = field->at({x, p.y_m});
    p.magnetic_N = magnet::induced_dipole_force(cfg.magnet.toner, radius_m, s).y;  // eq. 2.4.34 with eq. 4.5.1
  }
  return p;
}

double FrontForceModel::crossing(double x, bool printed, double lo, double hi) const {
  auto net = [&](double l) { const auto p = at(x, l); return printed ? p.net_printed_N() : p.net_exact_N(); };
  if (net(lo) <= 0) return lo;
  if (net(hi) > 0) return std::nan("");
  for (int i = 0; i < 60 && hi - lo > 1e-12; ++i) {
    const double m = 0.5 * (lo + hi);
    (net(m) > 0 ? lo : hi) = m;
  }
  return 0.5 * (lo + hi);
}

FrontForceModel make_front_force_model(const ExperimentOptions& e, const FrontForceOptions& f) {
  f.validate();
  reject_fixed_sets(e, "front-force", {{"geometry.gap_m", std::monostate{}, "--gap"}}, false);
  FrontForceModel m;
  m.cfg = base_config(e);
  m.cfg.gap = f.gap_m;
  validate(m.cfg);
  m.field = nip::make_magnet_field(m.cfg.magnet);
  m.radius_m = 0.5 * m.cfg.size.d_small;  // R = d95/2 (§2.5.4; Table 2.1 "d95")
  double v = f.voltage_V;
  if (v == 0.0) {
    v = kThesisPrintVoltage_V;
    const auto& segs = m.cfg.electric.pattern.segments();
    if (!segs.empty()) {
      v = 0.0;
      for (const auto& s : segs) v = std::max(v, std::fabs(s.voltage_V - m.cfg.electric.pattern.off_voltage()));
    }
  }
  if (!(v <= kMaxVoltage_V))  // the configuration's print voltage, where --voltage was 0
    throw_input(kWhere, "[print] voltage of the configuration (used as --voltage is 0)", fmt::format("{:g}", v), "out of range",
                fmt::format("[0, {:g}] V", kMaxVoltage_V));
  m.voltage_V = v;
  return m;
}

nlohmann::json front_force(const ExperimentOptions& e, const FrontForceOptions& f) {
  const auto t0 = std::chrono::steady_clock::now();
  const FrontForceModel m = make_front_force_model(e, f);
  const std::filesystem::path& out = e.out;
  std::filesystem::create_directories(out);
  const int nx = static_cast<int>(std::floor((f.x_max_m - f.x_min_m) / f.dx_m + 1e-9)) + 1;
  // Front region membership of a grid x (a tolerance of dx/1000 absorbs the grid's round-off).
  auto in_front = [&](double x) { return x >= f.front_x_min_m - 1e-3 * f.dx_m && x <= f.front_x_max_m + 1e-3 * f.dx_m; };
  std::vector<std::vector<double>> rows;
  io::PlotSpec pe, pp;
  const std::string name = e.config.empty() ? e.preset : std::filesystem::path(e.config).stem().string();
  const std::string setting = fmt::format("{}, R = {:.3g} µm, {:g} V, w_h = {:g} µm", name, 1e6 * m.radius_m, m.voltage_V, 1e6 * f.gap_m);
  pe.title = "Net y-force, front particle: " + setting;
  pp.title = "Same, eq. 2.5.31 as printed: " + setting;
  for (auto* p : {&pe, &pp}) {
    p->x_label = "x [µm] (magnet edge at 0, supply roller at +x)";
    p->y_label = "net y-force [nN] (+: to the DI-drum, -: to the roller)";
  }
  nlohmann::json per_l = nlohmann::json::array();
  for (double l : f.l_m) {
    io::Series se;
    se.label = fmt::format("l = {:g} µm", 1e6 * l);
    io::Series sp = se;
    double fe_min = 1e300, fe_max = -1e300;
    double to_drum_front = 0;  // share of the front region with net force to the drum
    int n_front = 0;
    for (int i = 0; i < nx; ++i) {
      const double x = f.x_min_m + i * f.dx_m;
      const FrontForcePoint p = m.at(x, l);
      rows.push_back({p.x_m, p.l_m, p.y_m, p.electric_exact_N, p.electric_printed_N, p.magnetic_N, p.net_exact_N(),
                      p.net_printed_N()});
      se.x.push_back(1e6 * x);
      se.y.push_back(1e9 * p.net_exact_N());
      sp.x.push_back(1e6 * x);
      sp.y.push_back(1e9 * p.net_printed_N());
      fe_min = std::min(fe_min, p.net_exact_N());
      fe_max = std::max(fe_max, p.net_exact_N());
      if (in_front(x)) {
        ++n_front;
        if (p.net_exact_N() > 0) ++to_drum_front;
      }
    }
    pe.series.push_back(se);
    pp.series.push_back(sp);
    per_l.push_back({{"l_m", l},
                     {"net_exact_min_N", fe_min},
                     {"net_exact_max_N", fe_max},
                     {"front_fraction_to_drum_exact", n_front ? to_drum_front / n_front : 0.0}});
  }
  for (auto* p : {&pe, &pp}) {
    io::Series zero = reference_line("", f.x_min_m, f.x_max_m, 0.0);
    p->series.push_back(zero);
  }
  io::write_csv(out / "front_force.csv",
                {"x_m", "l_m", "y_m", "electric_exact_y_N", "electric_printed_y_N", "magnetic_y_N", "net_exact_y_N",
                 "net_printed_y_N"},
                rows);
  io::write_plot_png(out / "front_force.png", pe);
  io::write_plot_png(out / "front_force_printed.png", pp);

  // Crossing distance l*(x) and its maximum over the front region.
  std::vector<std::vector<double>> crow;
  io::Series ce, cp;
  ce.label = "exact electric force";
  cp.label = "eq. 2.5.31 as printed";
  cp.dashed = true;
  double lmax_e = 0, lmax_p = 0, x_at_e = 0, x_at_p = 0;
  bool open_e = false, open_p = false;
  for (int i = 0; i < nx; ++i) {
    const double x = f.x_min_m + i * f.dx_m;
    const double le = m.crossing(x, false), lp = m.crossing(x, true);
    crow.push_back({x, le, lp});
    ce.x.push_back(1e6 * x);
    ce.y.push_back(1e6 * le);
    cp.x.push_back(1e6 * x);
    cp.y.push_back(1e6 * lp);
    if (!in_front(x)) continue;
    if (std::isnan(le)) open_e = true; else if (le > lmax_e) { lmax_e = le; x_at_e = x; }
    if (std::isnan(lp)) open_p = true; else if (lp > lmax_p) { lmax_p = lp; x_at_p = x; }
  }
  io::write_csv(out / "front_force_crossing.csv", {"x_m", "l_cross_exact_m", "l_cross_printed_m"}, crow);
  const double d50 = m.cfg.size.d50;
  io::PlotSpec pc;
  pc.title = "Distance from the drum beyond which the net force points to the roller";
  pc.x_label = pe.x_label;
  pc.y_label = "crossing distance l* [µm]";
  const io::Series sd = reference_line(fmt::format("d50 = {:g} µm", 1e6 * d50), f.x_min_m, f.x_max_m, 1e6 * d50);
  pc.series = {ce, cp, sd};
  pc.y_min = 0.0;
  io::write_plot_png(out / "front_force_crossing.png", pc);

  // Map over (x, l) on a finer l grid reaching past the largest crossing, with the crossings on top.
  double l_top = *std::max_element(f.l_m.begin(), f.l_m.end());
  for (const auto& c : crow)
    for (int k : {1, 2})
      if (std::isfinite(c[k])) l_top = std::max(l_top, 1.15 * c[k]);
  const int nl = 80;
  io::Heatmap hm;
  hm.z_label = "net y-force [nN] (+: to the drum)";
  double mag_max = 0;  // largest magnet pull on the map [N]
  std::vector<std::vector<double>> mrow;
  for (int i = 0; i < nx; ++i) hm.x.push_back(1e6 * (f.x_min_m + i * f.dx_m));
  for (int j = 0; j < nl; ++j) {
    const double l = 0.5e-6 + (l_top - 0.5e-6) * j / (nl - 1);
    hm.y.push_back(1e6 * l);
    for (int i = 0; i < nx; ++i) {
      const FrontForcePoint p = m.at(f.x_min_m + i * f.dx_m, l);
      hm.z.push_back(1e9 * p.net_exact_N());
      mag_max = std::max(mag_max, std::fabs(p.magnetic_N));
      mrow.push_back({p.x_m, p.l_m, p.net_exact_N(), p.net_printed_N()});
    }
  }
  io::write_csv(out / "front_force_map.csv", {"x_m", "l_m", "net_exact_y_N", "net_printed_y_N"}, mrow);
  // Colour scale: blue down to the most negative net force, red up to 3x its size, so the sign
  // change is visible; the strong electric force close to the drum takes the end colour (its
  // values are in the CSV).
  double z_neg = 0;
  for (double z : hm.z) z_neg = std::min(z_neg, z);
  if (z_neg == 0) z_neg = -1e9 * mag_max;
  hm.z_min = z_neg;
  hm.z_max = -3 * z_neg;
  io::PlotSpec pm;
  pm.title = "Net y-force map (exact electric force): " + setting;
  pm.x_label = pe.x_label;
  pm.y_label = "distance from the DI-drum l [µm]";
  pm.heatmap = hm;
  io::Series ke = ce, kp = cp, kd = sd;
  kd.color = std::array<double, 3>{0.17, 0.63, 0.17};
  ke.label = "net force = 0 (exact)";
  ke.color = std::array<double, 3>{0, 0, 0};
  kp.label = "net force = 0 (as printed)";
  kp.color = std::array<double, 3>{0.2, 0.2, 0.2};
  pm.series = {ke, kp, kd};
  pm.y_min = 0.0;
  pm.y_max = 1e6 * l_top;
  io::write_plot_png(out / "front_force_map.png", pm);

  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  auto opt_num = [](bool open, double v) { return open ? nlohmann::json(nullptr) : nlohmann::json(v); };
  return {{"experiment", "front-force"},
          {"preset", e.config.empty() ? e.preset : ""},
          {"config", e.config},
          {"set", e.sets},
          {"gap_m", f.gap_m},
          {"voltage_V", m.voltage_V},
          {"radius_m", m.radius_m},
          {"d50_m", d50},
          {"magnet_field", m.field ? m.field->describe() : "none"},
          {"dielectric_layer", m.cfg.electric.dielectric_layer},
          {"layer_thickness_m", m.cfg.electric.layer_thickness},
          {"layer_permittivity", m.cfg.electric.layer_permittivity},
          {"front_region_m", {f.front_x_min_m, f.front_x_max_m}},
          {"l_cross_max_exact_m", opt_num(open_e, lmax_e)},
          {"l_cross_max_exact_at_x_m", opt_num(open_e, x_at_e)},
          {"l_cross_max_printed_m", opt_num(open_p, lmax_p)},
          {"l_cross_max_printed_at_x_m", opt_num(open_p, x_at_p)},
          {"roller_wins_beyond_d50_exact", !open_e && lmax_e <= d50},
          {"roller_wins_beyond_d50_printed", !open_p && lmax_p <= d50},
          {"rows", per_l},
          {"csv", (out / "front_force.csv").string()},
          {"crossing_csv", (out / "front_force_crossing.csv").string()},
          {"map_csv", (out / "front_force_map.csv").string()},
          {"plot_map", (out / "front_force_map.png").string()},
          {"plot", (out / "front_force.png").string()},
          {"plot_printed", (out / "front_force_printed.png").string()},
          {"plot_crossing", (out / "front_force_crossing.png").string()},
          {"wall_time_s", wall},
          {"meta", {{"git_hash", kGitHash}}}};
}

}  // namespace nipdem::experiments
