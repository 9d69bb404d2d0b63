#include "nipdem/experiments/calibrate_adhesion.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include <Eigen/Dense>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/analysis/fit.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"
#include "nipdem/version.hpp"

namespace nipdem::calibrate {

namespace {
constexpr const char* kWhere = "calibrate adhesion";
constexpr double kMinParticleMass = 1e-18, kMaxParticleMass = 1e-3;  // [kg]: a 0.1 um particle .. a 1 cm bead
constexpr double kMinRotorRadius = 1e-3, kMaxRotorRadius = 10.0;     // [m]
constexpr double kMaxBootstrapDraws = 5e8;
// The config value must be one the config accepts (adhesion.*_force_N <= 1e-3 N, nip_config.cpp)
// and not a degenerate one.
constexpr double kMinConfigForce = 1e-15, kMaxConfigForce = 1e-3;  // [N]

// Where the piecewise-linear interpolation of fraction(ln F) crosses level q; NaN if it never does.
double crossing(const std::vector<double>& lnF, const std::vector<double>& frac, double q) {
  for (std::size_t i = 1; i < lnF.size(); ++i) {
    const double a = frac[i - 1] - q, b = frac[i] - q;
    if (a >= 0 && b < 0) return lnF[i - 1] + (lnF[i] - lnF[i - 1]) * a / (a - b);
  }
  return std::nan("");
}

// Least-squares fit of the log-normal survival 1 - Phi((ln F - mu)/s) to fractions remaining,
// binomial weights for N0 particles; p = (mu, ln s).
analysis::LmResult fit_survival(const std::vector<double>& F, const std::vector<double>& frac, double n0) {
  const std::size_t n = F.size();
  std::vector<double> lnF, w(n);
  for (double f : F) lnF.push_back(std::log(f));
  for (std::size_t i = 0; i < n; ++i) w[i] = std::sqrt(std::max(frac[i] * (1 - frac[i]), 1.0 / n0) / n0);
  // Start: the 50 % crossing and half the 16-84 % span (defaults when the record misses them).
  double mu0 = crossing(lnF, frac, 0.5);
  if (!std::isfinite(mu0)) mu0 = 0.5 * (lnF.front() + lnF.back());
  const double l16 = crossing(lnF, frac, 0.84), l84 = crossing(lnF, frac, 0.16);
  double s0 = std::isfinite(l16) && std::isfinite(l84) && l84 > l16 ? 0.5 * (l84 - l16) : 1.0;
  const analysis::LmModel model = [&](const Eigen::VectorXd& p, Eigen::VectorXd& res, Eigen::MatrixXd& J) {
    const double mu = p[0], s = std::exp(p[1]);
    for (std::size_t i = 0; i < n; ++i) {
      const double z = (lnF[i] - mu) / s;
      const double pdf = std::exp(-0.5 * z * z) / std::sqrt(2 * constants::pi);
      const auto ii = static_cast<Eigen::Index>(i);
      res[ii] = (0.5 * std::erfc(z / std::sqrt(2.0)) - frac[i]) / w[i];
      J(ii, 0) = pdf / s / w[i];  // d/d mu of 1 - Phi(z)
      J(ii, 1) = pdf * z / w[i];  // d/d ln s
    }
  };
  Eigen::VectorXd p0(2);
  p0 << mu0, std::log(s0);
  return analysis::levenberg_marquardt(model, p0, n, 500);
}

}  // namespace

double LogNormal::median() const { return std::exp(mu_ln); }
double LogNormal::mean() const { return std::exp(mu_ln + 0.5 * sigma_ln * sigma_ln); }
double LogNormal::quantile(double p) const { return std::exp(mu_ln + sigma_ln * normal_quantile(p)); }
double LogNormal::survival(double F) const {
  return 0.5 * std::erfc((std::log(F) - mu_ln) / (sigma_ln * std::sqrt(2.0)));  // 1 - Phi((ln F - mu)/s)
}

const char* to_string(AdhesionMethod m) { return m == AdhesionMethod::centrifugal ? "centrifugal" : "afm"; }

double centrifugal_force(double m, double omega, double r) { return m * omega * omega * r; }  // §4.4: F_c = m w^2 r

void AdhesionOptions::validate() const {
  if (method == AdhesionMethod::centrifugal) {
    // Physical ranges (a toner-to-bead particle, a centrifuge rotor), so that F_c = m omega^2 r
    // stays finite and the messages name these options, not the record (1e308 kg used to blame
    // fraction_remaining, a 1e308 m rotor printed a config value of 4e300 N).
    require_range(kWhere, "--particle-mass-kg", particle_mass_kg, kMinParticleMass, kMaxParticleMass);
    require_range(kWhere, "--rotor-radius-m", rotor_radius_m, kMinRotorRadius, kMaxRotorRadius);
    require_range(kWhere, "--initial-count", initial_count, 10.0, 1e6);
    if (initial_count != std::floor(initial_count))
      throw_input(kWhere, "--initial-count", fmt::format("{:g}", initial_count), "not a whole number of particles", "10 .. 1e6");
    require_range(kWhere, "--bootstrap", bootstrap, 20, 100000);
    // Each resample draws N0 particles: bound the work (~20 s at the limit), not each factor.
    if (static_cast<double>(bootstrap) * initial_count > kMaxBootstrapDraws)
      throw_input(kWhere, "--bootstrap, --initial-count", fmt::format("{} x {:g}", bootstrap, initial_count),
                  fmt::format("{:g} particle draws for the bootstrap", static_cast<double>(bootstrap) * initial_count),
                  fmt::format("--bootstrap x --initial-count <= {:g}", kMaxBootstrapDraws));
  }
  require_range(kWhere, "--measured-diameter-m", measured_diameter_m, 0.0, 1e-2);
  require_range(kWhere, "--d50-m", d50_m, 0.0, 1e-2);
  if ((measured_diameter_m > 0) != (d50_m > 0))
    throw_input(kWhere, measured_diameter_m > 0 ? "--d50-m" : "--measured-diameter-m", "",
                "size scaling needs both the measured particles' diameter and the toner d50", "both or neither");
  if (substrate != "drum" && substrate != "roller")
    throw_input(kWhere, "--substrate", "\"" + substrate + "\"", "unknown substrate", "drum or roller");
  require_range(kWhere, "--level", level, 0.5, 0.9999);
}

Record parse_adhesion_record(std::string_view text, const std::string& source, AdhesionMethod m) {
  if (m == AdhesionMethod::afm) return parse_record(text, source, {{"force_N", 0.0, 1e-3, true}}, 3);
  Record r = parse_record(text, source, {{"omega_rad_per_s", 0.0, 1e7, true}, {"fraction_remaining", 0.0, 1.0}}, 3);
  require_ascending(r, 0, true);
  return r;
}
Record read_adhesion_record(const std::filesystem::path& path, AdhesionMethod m) {
  return parse_adhesion_record(io::read_file(path), path.string(), m);
}

AdhesionResult calibrate_adhesion(const Record& r, const AdhesionOptions& o) {
  o.validate();
  AdhesionResult a;
  const std::size_t n = r.rows();
  if (o.method == AdhesionMethod::afm) {
    std::vector<double> lnF;
    for (double F : r.cols[0]) { a.force_N.push_back(F); lnF.push_back(std::log(F)); }
    const MeanStd ms = mean_std(lnF);  // maximum likelihood of the log-normal (n - 1 for s)
    if (!(ms.std > 0))
      throw_input(r.source, "force_N", fmt::format("{:g}", r.cols[0][0]), "all forces equal: no spread to fit",
                  "at least two different forces");
    a.dist = {ms.mean, ms.std};
    a.mu_ln_std = ms.std / std::sqrt(static_cast<double>(n));
    a.sigma_ln_std = ms.std / std::sqrt(2.0 * static_cast<double>(n - 1));
  } else {
    for (double om : r.cols[0]) a.force_N.push_back(centrifugal_force(o.particle_mass_kg, om, o.rotor_radius_m));
    const analysis::LmResult fit = fit_survival(a.force_N, r.cols[1], o.initial_count);
    if (!fit.p.allFinite() || !fit.covariance.allFinite())
      throw_input(r.source, "fraction_remaining", "", "the log-normal fit failed (no detachment within the record?)",
                  "a record whose fraction falls over the omega range");
    a.dist = {fit.p[0], std::exp(fit.p[1])};
    a.iterations = fit.iterations;
    a.converged = fit.converged;
    double rss = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double d = a.dist.survival(a.force_N[i]) - r.cols[1][i];
      rss += d * d;
    }
    a.rms_residual = std::sqrt(rss / static_cast<double>(n));
    if (a.dist.median() < a.force_N.front() / 100 || a.dist.median() > a.force_N.back() * 100)
      throw_input(r.source, "omega_rad_per_s", fmt::format("[{:g}, {:g}]", r.cols[0].front(), r.cols[0].back()),
                  fmt::format("the fitted median force {:g} N lies far outside the forces of the record ({:g}..{:g} N)",
                              a.dist.median(), a.force_N.front(), a.force_N.back()),
                  "a record that covers the detachment of about half the particles");
    // Parametric bootstrap through the forward model (see the header for why not the covariance).
    std::vector<double> mus, ss;
    const int n0 = static_cast<int>(o.initial_count);
    for (int b = 0; b < o.bootstrap; ++b) {
      const Record rb = synthetic_centrifugal_record(a.dist, o, r.cols[0], n0, Rng::stream(o.seed, b).next_u64());
      const analysis::LmResult fb = fit_survival(a.force_N, rb.cols[1], o.initial_count);
      if (!fb.p.allFinite() || !fb.converged) { ++a.bootstrap_failed; continue; }
      mus.push_back(fb.p[0]);
      ss.push_back(std::exp(fb.p[1]));
    }
    if (mus.size() < 10)
      throw_input(r.source, "fraction_remaining", "", fmt::format("{} of {} bootstrap refits failed", a.bootstrap_failed, o.bootstrap),
                  "a record the log-normal describes");
    a.mu_ln_std = mean_std(mus).std;
    a.sigma_ln_std = mean_std(ss).std;
  }
  const double z = normal_quantile(0.5 + 0.5 * o.level);
  a.median_N = a.dist.median();
  a.median_std_N = a.median_N * a.mu_ln_std;
  a.median_lo_N = std::exp(a.dist.mu_ln - z * a.mu_ln_std);
  a.median_hi_N = std::exp(a.dist.mu_ln + z * a.mu_ln_std);
  a.mean_N = a.dist.mean();
  a.q10_N = a.dist.quantile(0.1);
  a.q90_N = a.dist.quantile(0.9);
  a.scale = o.measured_diameter_m > 0 ? o.d50_m / o.measured_diameter_m : 1.0;  // eq. 2.3.2: F ∝ R
  a.config_key = o.substrate == "drum" ? "adhesion.drum_force_N" : "adhesion.roller_force_N";
  a.config_value_N = a.scale * a.median_N;
  a.config_lo_N = a.scale * a.median_lo_N;
  a.config_hi_N = a.scale * a.median_hi_N;
  const std::string keys = o.method == AdhesionMethod::centrifugal
                               ? (a.scale != 1.0 ? "--particle-mass-kg, --rotor-radius-m, --measured-diameter-m, --d50-m"
                                                 : "--particle-mass-kg, --rotor-radius-m")
                               : "--measured-diameter-m, --d50-m";
  if (!(a.config_value_N >= kMinConfigForce && a.config_value_N <= kMaxConfigForce))
    throw_input(r.source, o.method == AdhesionMethod::afm && a.scale == 1.0 ? std::string("force_N") : keys,
                fmt::format("{:g} N", a.config_value_N),
                fmt::format("the {} this gives is not an adhesion force the config accepts (median {:g} N x size scale "
                            "{:g})",
                            a.config_key, a.median_N, a.scale),
                fmt::format("[{:g}, {:g}] N", kMinConfigForce, kMaxConfigForce));
  for (double v : {a.dist.mu_ln, a.dist.sigma_ln, a.mu_ln_std, a.sigma_ln_std, a.median_std_N, a.median_lo_N,
                   a.median_hi_N, a.mean_N, a.q10_N, a.q90_N, a.config_lo_N, a.config_hi_N, a.rms_residual})
    if (!std::isfinite(v))
      throw_input(r.source, keys, "", "the fitted distribution has no finite mean, quantile or interval",
                  "a record the log-normal describes with a moderate spread");
  return a;
}

Record synthetic_centrifugal_record(const LogNormal& d, const AdhesionOptions& o, const std::vector<double>& omegas,
                                    int n0, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<double> F(static_cast<std::size_t>(n0));
  for (auto& f : F) f = std::exp(rng.normal(d.mu_ln, d.sigma_ln));
  Record r;
  r.source = "synthetic";
  r.names = {"omega_rad_per_s", "fraction_remaining"};
  r.cols.resize(2);
  for (std::size_t i = 0; i < omegas.size(); ++i) {
    const double Fc = centrifugal_force(o.particle_mass_kg, omegas[i], o.rotor_radius_m);
    const auto left = std::count_if(F.begin(), F.end(), [&](double f) { return f > Fc; });
    r.cols[0].push_back(omegas[i]);
    r.cols[1].push_back(static_cast<double>(left) / n0);
    r.lines.push_back(i + 2);
  }
  return r;
}

Record synthetic_afm_record(const LogNormal& d, int n, std::uint64_t seed) {
  Rng rng(seed);
  Record r;
  r.source = "synthetic";
  r.names = {"force_N"};
  r.cols.resize(1);
  for (int i = 0; i < n; ++i) {
    r.cols[0].push_back(std::exp(rng.normal(d.mu_ln, d.sigma_ln)));
    r.lines.push_back(static_cast<std::size_t>(i) + 2);
  }
  return r;
}

nlohmann::json adhesion_report(const Record& r, const AdhesionOptions& o, const AdhesionResult& a,
                               const std::filesystem::path& out) {
  std::filesystem::create_directories(out);
  io::PlotSpec plot;
  plot.log_x = true;
  plot.x_label = "force F [N]";
  io::Series data;
  data.label = "measured";
  data.line = false;
  data.markers = true;
  io::Series fit;
  fit.label = fmt::format("log-normal: median {:.3g} N, s = {:.2f}", a.median_N, a.dist.sigma_ln);
  std::vector<std::vector<double>> rows;
  std::vector<double> Fs = a.force_N;
  std::vector<double> surv;
  if (o.method == AdhesionMethod::centrifugal) {
    for (std::size_t i = 0; i < r.rows(); ++i) {
      rows.push_back({r.cols[0][i], a.force_N[i], r.cols[1][i], a.dist.survival(a.force_N[i])});
      data.x.push_back(a.force_N[i]);
      data.y.push_back(r.cols[1][i]);
    }
    io::write_csv(out / "adhesion.csv", {"omega_rad_per_s", "force_N", "fraction_remaining", "fraction_fit"}, rows);
    plot.title = "Adhesion, centrifugal detachment (§4.4, fig. 4.18)";
    plot.y_label = "fraction remaining";
  } else {
    std::sort(Fs.begin(), Fs.end());
    const double n = static_cast<double>(Fs.size());
    for (std::size_t i = 0; i < Fs.size(); ++i) {
      const double emp = 1.0 - (static_cast<double>(i) + 0.5) / n;  // empirical P(F_adh > F), mid-rank
      rows.push_back({Fs[i], emp, a.dist.survival(Fs[i])});
      data.x.push_back(Fs[i]);
      data.y.push_back(emp);
    }
    io::write_csv(out / "adhesion.csv", {"force_N", "fraction_above_empirical", "fraction_above_fit"}, rows);
    plot.title = "Adhesion, AFM pull-off forces (§4.4, fig. 4.16)";
    plot.y_label = "fraction with F_adh > F";
  }
  const double lo = std::min(Fs.front(), a.q10_N) / 2, hi = std::max(Fs.back(), a.q90_N) * 2;
  for (int k = 0; k <= 200; ++k) {
    const double F = lo * std::pow(hi / lo, k / 200.0);
    fit.x.push_back(F);
    fit.y.push_back(a.dist.survival(F));
  }
  io::Series med;
  med.label = fmt::format("median, {:.0f} % interval", 100 * o.level);
  med.x = {a.median_lo_N, a.median_N, a.median_hi_N};
  med.y = {0.5, 0.5, 0.5};
  med.line = true;
  med.markers = true;
  plot.series = {data, fit, med};
  plot.y_min = 0.0;
  plot.y_max = 1.0;
  io::write_plot_png(out / "adhesion.png", plot);

  nlohmann::json j{{"calibration", "adhesion"},
                   {"method", to_string(o.method)},
                   {"data", r.source},
                   {"distribution", "log-normal"},
                   {"median_N", a.median_N},
                   {"median_std_N", a.median_std_N},
                   {"median_interval_N", {a.median_lo_N, a.median_hi_N}},
                   {"mu_ln", a.dist.mu_ln},
                   {"mu_ln_std", a.mu_ln_std},
                   {"sigma_ln", a.dist.sigma_ln},
                   {"sigma_ln_std", a.sigma_ln_std},
                   {"mean_N", a.mean_N},
                   {"quantile_10_N", a.q10_N},
                   {"quantile_90_N", a.q90_N},
                   {"level", o.level},
                   {"size_scale", a.scale},
                   {"config", {{a.config_key, a.config_value_N}}},
                   {"config_interval_N", {a.config_lo_N, a.config_hi_N}},
                   {"n_points", r.rows()},
                   {"csv", (out / "adhesion.csv").string()},
                   {"plot", (out / "adhesion.png").string()},
                   {"meta", {{"git_hash", kGitHash}}}};
  if (o.method == AdhesionMethod::centrifugal) {
    j["rms_residual"] = a.rms_residual;
    j["iterations"] = a.iterations;
    j["converged"] = a.converged;
    j["uncertainty"] = "parametric bootstrap";
    j["bootstrap_failed"] = a.bootstrap_failed;
    j["inputs"] = {{"particle_mass_kg", o.particle_mass_kg},
                   {"rotor_radius_m", o.rotor_radius_m},
                   {"initial_count", o.initial_count},
                   {"bootstrap", o.bootstrap},
                   {"seed", o.seed},
                   {"measured_diameter_m", o.measured_diameter_m},
                   {"d50_m", o.d50_m},
                   {"substrate", o.substrate}};
  } else {
    j["uncertainty"] = "maximum likelihood, se(mu) = s/sqrt(n), se(s) = s/sqrt(2(n-1))";
    j["inputs"] = {{"measured_diameter_m", o.measured_diameter_m}, {"d50_m", o.d50_m}, {"substrate", o.substrate}};
  }
  return j;
}

}  // namespace nipdem::calibrate
