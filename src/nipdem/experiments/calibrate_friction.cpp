#include "nipdem/experiments/calibrate_friction.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"
#include "nipdem/version.hpp"

namespace nipdem::calibrate {

namespace {
constexpr const char* kWhere = "calibrate friction";
constexpr double kMaxMu = 100.0;  // largest friction coefficient reported (rubber ~1-4, toner ~0.2-0.5)

// Median absolute deviation of successive differences -> sd of white noise (sqrt 2 for the difference).
double noise_from_differences(const std::vector<double>& f, std::size_t b, std::size_t e) {
  std::vector<double> d;
  for (std::size_t i = b + 1; i < e; ++i) d.push_back(std::fabs(f[i] - f[i - 1]));
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2] / (0.6744897501960817 * std::sqrt(2.0));
}

struct LineAt {
  double value = 0, std = 0;
};
// Least-squares line through (x, y)[b, e) evaluated at x0, with the standard error of that value.
LineAt line_fit_at(const std::vector<double>& x, const std::vector<double>& y, std::size_t b, std::size_t e, double x0) {
  const double n = static_cast<double>(e - b);
  double mx = 0, my = 0;
  for (std::size_t i = b; i < e; ++i) { mx += x[i]; my += y[i]; }
  mx /= n; my /= n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = b; i < e; ++i) { sxx += (x[i] - mx) * (x[i] - mx); sxy += (x[i] - mx) * (y[i] - my); }
  const double slope = sxx > 0 ? sxy / sxx : 0.0;
  double rss = 0;
  for (std::size_t i = b; i < e; ++i) { const double r = y[i] - my - slope * (x[i] - mx); rss += r * r; }
  const double s2 = n > 2 ? rss / (n - 2) : 0.0;
  LineAt l;
  l.value = my + slope * (x0 - mx);
  l.std = std::sqrt(s2 * (1.0 / n + (sxx > 0 ? (x0 - mx) * (x0 - mx) / sxx : 0.0)));
  return l;
}
}  // namespace

FrictionSetup parse_friction_setup(const std::string& s) {
  if (s == "plate") return FrictionSetup::plate;
  if (s == "capstan") return FrictionSetup::capstan;
  throw_input(kWhere, "--setup", "\"" + s + "\"", "unknown set-up", "plate (fig. 4.7) or capstan (fig. 4.10)");
}
const char* to_string(FrictionSetup s) { return s == FrictionSetup::plate ? "plate" : "capstan"; }

void FrictionOptions::validate() const {
  // Physical ranges of a bench measurement, so that the load force F_n = m g stays a finite,
  // non-degenerate number (1e308 kg gave F_n = inf and mu = 0, 1e308 m/s^2 mu ~ 1e-308).
  if (setup == FrictionSetup::plate) require_range(kWhere, "--sample-mass-kg", sample_mass_kg, 0.0, 1e3);
  require_range(kWhere, "--weight-mass-kg", weight_mass_kg, 1e-6, 1e3);
  const double mass = setup == FrictionSetup::plate ? sample_mass_kg + weight_mass_kg : weight_mass_kg;
  require_range(kWhere, "--mass-std-kg", mass_std_kg, 0.0, 1e3);
  if (mass_std_kg > mass)
    throw_input(kWhere, "--mass-std-kg", fmt::format("{:g}", mass_std_kg),
                fmt::format("larger than the loading mass itself ({:g} kg)", mass), fmt::format("[0, {:g}]", mass));
  require_range(kWhere, "--gravity-m-per-s2", gravity_m_per_s2, 1e-3, 1e3);
  require_positive(kWhere, "--stick-end-m", stick_end_m);
  require_range(kWhere, "--transition-m", transition_m, 0.0, 1e3);
  require_range(kWhere, "--wrap-angle-rad", wrap_angle_rad, 1e-3, 100.0);
  require_range(kWhere, "--min-drop-N", min_drop_N, 0.0, 1e9);
  require_range(kWhere, "--window", window, 1, 1000);
  require_range(kWhere, "--blocks", blocks, 2, 1000);
}

double load_force(const FrictionOptions& o) {
  // eq. 4.3.1 (plate): F_n = F_z,s + F_z,w; capstan: the hanging weight F_z.
  return o.setup == FrictionSetup::plate ? (o.sample_mass_kg + o.weight_mass_kg) * o.gravity_m_per_s2
                                         : o.weight_mass_kg * o.gravity_m_per_s2;
}

double friction_coefficient(const FrictionOptions& o, double F, double load) {
  if (o.setup == FrictionSetup::plate) return F / load;    // eq. 4.3.2: F_t = mu F_n
  return std::log(F / load) / o.wrap_angle_rad;            // eq. 4.3.3: F_t / F_z = exp(mu pi/2)
}

double friction_force(const FrictionOptions& o, double mu, double load) {
  if (o.setup == FrictionSetup::plate) return mu * load;             // eq. 4.3.2
  return load * std::exp(mu * o.wrap_angle_rad);                     // eq. 4.3.3
}

Record parse_friction_record(std::string_view text, const std::string& source) {
  Record r = parse_record(text, source, {{"x_m"}, {"force_N", 0.0, 1e300, true}}, 8);
  require_ascending(r, 0, true);
  return r;
}
Record read_friction_record(const std::filesystem::path& path) {
  return parse_friction_record(io::read_file(path), path.string());
}

FrictionResult calibrate_friction(const Record& r, const FrictionOptions& o) {
  o.validate();
  const auto& x = r.cols[0];
  const auto& F = r.cols[1];
  const std::size_t n = r.rows();
  FrictionResult res;
  res.load_force_N = load_force(o);
  res.load_force_std_N = o.mass_std_kg * o.gravity_m_per_s2;
  const std::size_t i_stick = static_cast<std::size_t>(std::lower_bound(x.begin(), x.end(), o.stick_end_m) - x.begin());
  const std::size_t i_slide =
      static_cast<std::size_t>(std::lower_bound(x.begin(), x.end(), o.stick_end_m + o.transition_m) - x.begin());
  res.n_stick = i_stick;
  res.n_slide = n - i_slide;
  const std::size_t min_slide = static_cast<std::size_t>(4 * o.blocks);
  if (res.n_slide < min_slide)
    throw_input(r.source, o.transition_m > 0 ? "--stick-end-m + --transition-m" : "--stick-end-m",
                fmt::format("{:g}", o.stick_end_m + o.transition_m),
                fmt::format("only {} samples beyond stick end + transition ({:g} m); the last x is {:g} m", res.n_slide,
                            o.stick_end_m + o.transition_m, x.back()),
                fmt::format(">= {} sliding samples (4 x --blocks)", min_slide));
  if (res.n_stick < static_cast<std::size_t>(2 * o.window + 3))
    throw_input(r.source, "--stick-end-m", fmt::format("{:g}", o.stick_end_m),
                fmt::format("only {} samples before the stick end; the first x is {:g} m", res.n_stick, x.front()),
                fmt::format(">= {} stick samples (2 x --window + 3)", 2 * o.window + 3));

  // Dynamic force: plateau mean, batch-means standard error.
  double sum = 0;
  for (std::size_t i = i_slide; i < n; ++i) sum += F[i];
  res.dynamic_force_N = sum / static_cast<double>(res.n_slide);
  std::vector<double> block_means;
  for (int b = 0; b < o.blocks; ++b) {
    const std::size_t lo = i_slide + res.n_slide * static_cast<std::size_t>(b) / static_cast<std::size_t>(o.blocks);
    const std::size_t hi = i_slide + res.n_slide * static_cast<std::size_t>(b + 1) / static_cast<std::size_t>(o.blocks);
    double s = 0;
    for (std::size_t i = lo; i < hi; ++i) s += F[i];
    block_means.push_back(s / static_cast<double>(hi - lo));
  }
  res.dynamic_force_std_N = mean_std(block_means).std / std::sqrt(static_cast<double>(o.blocks));
  res.noise_N = noise_from_differences(F, i_slide, n);
  res.min_drop_N = o.min_drop_N > 0 ? o.min_drop_N : 6.0 * res.noise_N;

  // Static force: stick-slip peaks before the stick end.
  const std::size_t w = static_cast<std::size_t>(o.window);
  std::size_t ramp_start = 0;
  for (std::size_t i = 0; i < i_stick; ++i) {
    // The drop must happen inside the stick part: the speed change at stick_end is no slip.
    const std::size_t lo = i >= w ? i - w : 0, hi = std::min(i + w, i_stick - 1);
    bool is_max = true;
    double after_min = F[i];
    for (std::size_t k = lo; k <= hi; ++k) {
      if (F[k] > F[i]) is_max = false;
      if (k > i) after_min = std::min(after_min, F[k]);
    }
    if (!is_max || F[i] - after_min <= res.min_drop_N) continue;
    const std::size_t len = i + 1 - ramp_start;
    const std::size_t b = len >= 6 ? i + 1 - len / 2 : ramp_start;
    if (i + 1 - b < 3) { ramp_start = i + 1; continue; }  // too short a ramp to fit a line
    // The stick breaks between sample i and i + 1: evaluate the ramp at the midpoint.
    const LineAt l = line_fit_at(x, F, b, i + 1, 0.5 * (x[i] + x[i + 1]));
    res.peaks.push_back({x[i], l.value, l.std});
    // The next ramp starts at the bottom of this slip.
    std::size_t k_min = i + 1;
    for (std::size_t k = i + 1; k <= hi; ++k)
      if (F[k] < F[k_min]) k_min = k;
    ramp_start = k_min;
    i = k_min;  // skip the slip itself
  }
  if (res.peaks.empty())
    throw_input(r.source, "--min-drop-N", fmt::format("{:g}", res.min_drop_N),
                fmt::format("no stick-slip peak (a maximum followed within {} samples by a drop above the threshold) "
                            "before x = {:g} m",
                            o.window, o.stick_end_m),
                "a threshold below the stick-slip drops (default 6 x the noise estimate)");
  std::vector<double> pf;
  for (const auto& p : res.peaks) pf.push_back(p.force_N);
  const MeanStd ms = mean_std(pf);
  res.static_force_N = ms.mean;
  res.static_force_std_N = pf.size() >= 2 ? ms.std / std::sqrt(static_cast<double>(pf.size())) : res.peaks[0].force_std_N;

  const double L = res.load_force_N, sL = res.load_force_std_N;
  if (o.setup == FrictionSetup::capstan && !(res.dynamic_force_N > L))
    throw_input(r.source, "force_N", fmt::format("{:g}", res.dynamic_force_N),
                fmt::format("plateau force not above the hanging weight F_z = {:g} N: no capstan friction (eq. 4.3.3)", L),
                fmt::format("> {:g} N", L));
  if (o.setup == FrictionSetup::capstan && !(res.static_force_N > L))
    throw_input(r.source, "force_N", fmt::format("{:g}", res.static_force_N),
                fmt::format("static (stick peak) force not above the hanging weight F_z = {:g} N: no capstan friction "
                            "(eq. 4.3.3); check --weight-mass-kg",
                            L),
                fmt::format("> {:g} N", L));
  res.mu_s = friction_coefficient(o, res.static_force_N, L);
  res.mu_d = friction_coefficient(o, res.dynamic_force_N, L);
  // Linear error propagation: d mu / mu = dF/F (+) dL/L (plate); d mu = (dF/F (+) dL/L) / theta (capstan).
  auto spread = [&](double Fv, double sF) {
    const double rel = std::hypot(sF / Fv, sL / L);
    return o.setup == FrictionSetup::plate ? friction_coefficient(o, Fv, L) * rel : rel / o.wrap_angle_rad;
  };
  res.mu_s_std = spread(res.static_force_N, res.static_force_std_N);
  res.mu_d_std = spread(res.dynamic_force_N, res.dynamic_force_std_N);
  // A coefficient outside (0, kMaxMu] (or not finite) means the load options do not belong to
  // the record: refused rather than reported (the record's forces go up to 1e300 N).
  const char* load_keys = o.setup == FrictionSetup::plate
                              ? "--sample-mass-kg, --weight-mass-kg, --gravity-m-per-s2"
                              : "--weight-mass-kg, --gravity-m-per-s2, --wrap-angle-rad";
  for (const auto& [name, mu] : {std::pair{"mu_s", res.mu_s}, std::pair{"mu_d", res.mu_d}})
    if (!(mu > 0 && mu <= kMaxMu))
      throw_input(r.source, load_keys, "",
                  fmt::format("{} = {:g} from the record's forces and the load force {:g} N: the load does not fit "
                              "the record",
                              name, mu, L),
                  fmt::format("options giving 0 < mu <= {:g}", kMaxMu));
  for (double v : {res.mu_s_std, res.mu_d_std, res.static_force_std_N, res.dynamic_force_std_N, res.load_force_std_N,
                   res.noise_N})
    if (!std::isfinite(v))
      throw_input(r.source, "force_N", "", "the record's forces give no finite uncertainty",
                  "forces of a bench measurement");
  return res;
}

Record synthetic_friction_record(const FrictionSynth& s, const FrictionOptions& o, std::uint64_t seed) {
  Rng rng(seed);
  const double L = load_force(o);
  const double Fd = friction_force(o, s.mu_d, L);
  const double Fs = friction_force(o, s.mu_s, L);
  Record r;
  r.source = "synthetic";
  r.names = {"x_m", "force_N"};
  r.cols.resize(2);
  const double phi = std::exp(-s.dx_m / s.corr_m);  // OU step correlation
  double u_ou = rng.normal();
  double peak = Fs * (1 + s.peak_jitter * rng.normal());
  double ramp_x0 = 0.0, f_stick_end = 0.0;
  const std::size_t n = static_cast<std::size_t>(std::floor(s.x_end_m / s.dx_m)) + 1;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i) * s.dx_m;
    double f;
    if (x < o.stick_end_m) {
      double u = (x - ramp_x0) / s.ramp_m;
      if (u >= 1.0) {  // slip: the next stick starts from the slip level
        ramp_x0 += s.ramp_m;
        peak = Fs * (1 + s.peak_jitter * rng.normal());
        u = (x - ramp_x0) / s.ramp_m;
      }
      f = peak * (s.slip_rel + (1 - s.slip_rel) * u);
      f_stick_end = f;
    } else {  // settles from the last stick force to the plateau within the transition length
      const double settle = std::exp(-(x - o.stick_end_m) / (0.2 * std::max(o.transition_m, s.dx_m)));
      u_ou = phi * u_ou + std::sqrt(1 - phi * phi) * rng.normal();
      f = Fd + (f_stick_end - Fd) * settle + Fd * s.wave_rel * u_ou;
    }
    r.cols[0].push_back(x);
    r.cols[1].push_back(f + s.noise_N * rng.normal());
    r.lines.push_back(i + 2);
  }
  return r;
}

nlohmann::json friction_report(const Record& r, const FrictionOptions& o, const FrictionResult& f,
                               const std::filesystem::path& out) {
  const auto& x = r.cols[0];
  const auto& F = r.cols[1];
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < r.rows(); ++i) {
    const double part = x[i] < o.stick_end_m ? 0.0 : (x[i] < o.stick_end_m + o.transition_m ? 1.0 : 2.0);
    rows.push_back({x[i], F[i], part});
  }
  std::filesystem::create_directories(out);
  io::write_csv(out / "friction.csv", {"x_m", "force_N", "part_stick0_transition1_slide2"}, rows);
  std::vector<std::vector<double>> prow;
  for (const auto& p : f.peaks) prow.push_back({p.x_m, p.force_N, p.force_std_N});
  io::write_csv(out / "friction_peaks.csv", {"x_m", "static_force_N", "static_force_std_N"}, prow);

  io::PlotSpec plot;
  plot.title = fmt::format("Friction, {} set-up (§4.3.1): mu_s = {:.3f} ± {:.3f}, mu_d = {:.3f} ± {:.3f}",
                           to_string(o.setup), f.mu_s, f.mu_s_std, f.mu_d, f.mu_d_std);
  plot.x_label = "pulled distance x [mm]";
  plot.y_label = "tangential force F_t [N]";
  io::Series rec;
  rec.label = "record";
  rec.line_width = 1.0;
  for (std::size_t i = 0; i < r.rows(); ++i) { rec.x.push_back(1e3 * x[i]); rec.y.push_back(F[i]); }
  io::Series pk;
  pk.label = "stick peaks (line fit)";
  pk.line = false;
  pk.markers = true;
  for (const auto& p : f.peaks) { pk.x.push_back(1e3 * p.x_m); pk.y.push_back(p.force_N); pk.y_err.push_back(p.force_std_N); }
  const double xa = 1e3 * x.front(), xb = 1e3 * x.back();
  io::Series fs;
  fs.label = "static force F_s";
  fs.x = {xa, 1e3 * o.stick_end_m};
  fs.y = {f.static_force_N, f.static_force_N};
  fs.dashed = true;
  io::Series fd;
  fd.label = "dynamic force F_d";
  fd.x = {1e3 * (o.stick_end_m + o.transition_m), xb};
  fd.y = {f.dynamic_force_N, f.dynamic_force_N};
  fd.dashed = true;
  plot.series = {rec, pk, fs, fd};
  io::write_plot_png(out / "friction.png", plot);

  nlohmann::json peaks = nlohmann::json::array();
  for (const auto& p : f.peaks) peaks.push_back({{"x_m", p.x_m}, {"force_N", p.force_N}, {"force_std_N", p.force_std_N}});
  return {{"calibration", "friction"},
          {"setup", to_string(o.setup)},
          {"data", r.source},
          {"mu_s", f.mu_s},
          {"mu_s_std", f.mu_s_std},
          {"mu_d", f.mu_d},
          {"mu_d_std", f.mu_d_std},
          {"static_force_N", f.static_force_N},
          {"static_force_std_N", f.static_force_std_N},
          {"dynamic_force_N", f.dynamic_force_N},
          {"dynamic_force_std_N", f.dynamic_force_std_N},
          {o.setup == FrictionSetup::plate ? "normal_force_N" : "hanging_force_N", f.load_force_N},
          {o.setup == FrictionSetup::plate ? "normal_force_std_N" : "hanging_force_std_N", f.load_force_std_N},
          {"noise_N", f.noise_N},
          {"min_drop_N", f.min_drop_N},
          {"n_stick_samples", f.n_stick},
          {"n_slide_samples", f.n_slide},
          {"peaks", peaks},
          {"inputs",
           {{"sample_mass_kg", o.sample_mass_kg},
            {"weight_mass_kg", o.weight_mass_kg},
            {"mass_std_kg", o.mass_std_kg},
            {"gravity_m_per_s2", o.gravity_m_per_s2},
            {"stick_end_m", o.stick_end_m},
            {"transition_m", o.transition_m},
            {"wrap_angle_rad", o.wrap_angle_rad},
            {"window", o.window},
            {"blocks", o.blocks}}},
          {"csv", (out / "friction.csv").string()},
          {"peaks_csv", (out / "friction_peaks.csv").string()},
          {"plot", (out / "friction.png").string()},
          {"meta", {{"git_hash", kGitHash}}}};
}

}  // namespace nipdem::calibrate
