#include "nipdem/experiments/calibrate_magnetisation.hpp"

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
constexpr const char* kWhere = "calibrate magnetisation";
constexpr double kMinVolumeFraction = 1e-3;
// The config values must be ones the config accepts (magnet.*, nip_config.cpp).
constexpr double kMinMs = 1e-3, kMaxMs = 1e7;      // [A/m]
constexpr double kMinBsat = 1e-6, kMaxBsat = 10.0;  // [T]

// Linear-saturated curve along one axis (models/magnetisation.hpp, §4.5): M for flux density B.
double curve(double Ms, double Bs, double B) { return magnet::magnetisation({Ms, Bs, 1.0}, {B, 0.0}).x; }

struct Points {
  std::vector<double> B, M;  // effective flux density mu0 (H - N M) [T], pigment magnetisation [A/m]
};
Points effective(const Record& r, const MagnetisationOptions& o) {
  Points p;
  for (std::size_t i = 0; i < r.rows(); ++i) {
    const double M = r.cols[1][i] / o.volume_fraction;
    p.M.push_back(M);
    p.B.push_back(constants::mu0 * (r.cols[0][i] - o.demag_factor * r.cols[1][i]));  // H_eff = H - N M (sample M)
  }
  return p;
}
}  // namespace

void MagnetisationOptions::validate() const {
  require_range(kWhere, "--demag-factor", demag_factor, 0.0, 1.0);
  // A pigment fraction below 1e-3 is no magnetic toner and scales M = M_sample / eta far past
  // any pigment (1e-300 made the fit blame the record, 1e-10 printed Ms = 4.5e15 A/m).
  require_range(kWhere, "--volume-fraction", volume_fraction, kMinVolumeFraction, 1.0);
}

Record parse_vsm_record(std::string_view text, const std::string& source) {
  return parse_record(text, source, {{"H_A_per_m", -1e9, 1e9}, {"M_A_per_m", -1e8, 1e8}}, 4);
}
Record read_vsm_record(const std::filesystem::path& path) { return parse_vsm_record(io::read_file(path), path.string()); }

MagnetisationFit calibrate_magnetisation(const Record& r, const MagnetisationOptions& o) {
  o.validate();
  const Points pt = effective(r, o);
  const std::size_t n = r.rows();
  double Bmax = 0;
  for (double b : pt.B) Bmax = std::max(Bmax, std::fabs(b));
  if (!(Bmax > 0)) throw_input(r.source, "H_A_per_m", "0", "all fields are zero", "a record sweeping the field");
  // Start: Ms from the rows at the top 20 % of |B|, the slope from a line through the origin of
  // the rows below half of that.
  std::vector<double> top;
  for (std::size_t i = 0; i < n; ++i)
    if (std::fabs(pt.B[i]) >= 0.8 * Bmax) top.push_back(std::fabs(pt.M[i]));
  std::nth_element(top.begin(), top.begin() + top.size() / 2, top.end());
  const double Ms0 = top[top.size() / 2];
  if (!(Ms0 > 0)) throw_input(r.source, "M_A_per_m", "", "no magnetisation at the largest fields", "a magnetisable sample");
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (std::fabs(pt.M[i]) < 0.5 * Ms0) { sxy += pt.B[i] * pt.M[i]; sxx += pt.B[i] * pt.B[i]; }
  const double Bs0 = sxx > 0 && sxy > 0 ? Ms0 / (sxy / sxx) : 0.5 * Bmax;
  const analysis::LmModel model = [&](const Eigen::VectorXd& p, Eigen::VectorXd& res, Eigen::MatrixXd& J) {
    const double Ms = std::exp(p[0]), Bs = std::exp(p[1]);
    for (std::size_t i = 0; i < n; ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      const double m = curve(Ms, Bs, pt.B[i]);
      res[ii] = m - pt.M[i];
      J(ii, 0) = m;                                          // d M / d ln Ms
      J(ii, 1) = std::fabs(pt.B[i]) < Bs ? -m : 0.0;         // d M / d ln B_sat (linear part only)
    }
  };
  Eigen::VectorXd p0(2);
  p0 << std::log(Ms0), std::log(std::min(Bs0, Bmax));
  const analysis::LmResult fit = analysis::levenberg_marquardt(model, p0, n, 500);
  MagnetisationFit f;
  f.Ms_A_per_m = std::exp(fit.p[0]);
  f.B_sat_T = std::exp(fit.p[1]);
  for (double b : pt.B) (std::fabs(b) < f.B_sat_T ? f.n_linear : f.n_saturated)++;
  // A plateau shorter than a quarter of the knee field cannot tell a knee from the record's end.
  if (f.n_saturated < 2 || Bmax < 1.25 * f.B_sat_T)
    throw_input(r.source, "H_A_per_m", fmt::format("max |mu0 H_eff| = {:g} T", Bmax),
                fmt::format("the record does not reach saturation (fitted B_sat = {:g} T)", f.B_sat_T),
                fmt::format(">= 2 rows above saturation and fields up to >= 1.25 B_sat = {:g} T", 1.25 * f.B_sat_T));
  if (f.n_linear < 2)
    throw_input(r.source, "H_A_per_m", "", fmt::format("fewer than 2 rows below saturation (fitted B_sat = {:g} T)", f.B_sat_T),
                ">= 2 rows on the linear part");
  if (!fit.covariance.allFinite())
    throw_input(r.source, "M_A_per_m", "", "the fit covariance is singular", "a record with spread on both parts");
  f.Ms_std_A_per_m = f.Ms_A_per_m * std::sqrt(fit.covariance(0, 0));
  f.B_sat_std_T = f.B_sat_T * std::sqrt(fit.covariance(1, 1));
  f.corr = fit.covariance(0, 1) / std::sqrt(fit.covariance(0, 0) * fit.covariance(1, 1));
  f.chi_linear = constants::mu0 * f.Ms_A_per_m / f.B_sat_T;
  f.rms_residual_A_per_m = std::sqrt(fit.rss / static_cast<double>(n));
  f.iterations = fit.iterations;
  f.converged = fit.converged;
  if (!(f.Ms_A_per_m >= kMinMs && f.Ms_A_per_m <= kMaxMs))
    throw_input(r.source, o.volume_fraction < 1.0 ? "M_A_per_m, --volume-fraction" : "M_A_per_m",
                fmt::format("Ms = {:g} A/m", f.Ms_A_per_m),
                fmt::format("not a saturation magnetisation the config accepts (the record's M / volume fraction {:g})",
                            o.volume_fraction),
                fmt::format("[{:g}, {:g}] A/m", kMinMs, kMaxMs));
  if (!(f.B_sat_T >= kMinBsat && f.B_sat_T <= kMaxBsat))
    throw_input(r.source, o.demag_factor > 0 ? "H_A_per_m, --demag-factor" : "H_A_per_m", fmt::format("B_sat = {:g} T", f.B_sat_T),
                "not a saturation flux the config accepts", fmt::format("[{:g}, {:g}] T", kMinBsat, kMaxBsat));
  for (double v : {f.Ms_std_A_per_m, f.B_sat_std_T, f.corr, f.chi_linear, f.rms_residual_A_per_m})
    if (!std::isfinite(v))
      throw_input(r.source, "M_A_per_m", "", "the fit gives no finite uncertainty", "a record with spread on both parts");
  return f;
}

Record synthetic_vsm_record(const magnet::MagnetisationParams& p, const MagnetisationOptions& o, double H_max, int n,
                            double noise, std::uint64_t seed) {
  Rng rng(seed);
  Record r;
  r.source = "synthetic";
  r.names = {"H_A_per_m", "M_A_per_m"};
  r.cols.resize(2);
  const double chi = constants::mu0 * p.Ms_A_per_m / p.B_sat_T;      // intrinsic slope
  // The demagnetising field is -N times the SAMPLE magnetisation eta M_pigment.
  const double Neff = o.demag_factor * o.volume_fraction;
  const double H_knee = p.B_sat_T / constants::mu0 + Neff * p.Ms_A_per_m;  // applied field at saturation
  auto sample = [&](double H) {
    // Internal field H - N eta M, with M on the linear part or saturated.
    const double M_lin = chi * H / (1.0 + Neff * chi);
    const double M_in = std::fabs(H) < H_knee ? M_lin : std::copysign(p.Ms_A_per_m, H);
    const double M = curve(p.Ms_A_per_m, p.B_sat_T, constants::mu0 * (H - Neff * M_in));
    return o.volume_fraction * M + noise * rng.normal();
  };
  // Down branch H_max -> -H_max, then up branch back (2 n rows).
  for (int branch = 0; branch < 2; ++branch)
    for (int k = 0; k < n; ++k) {
      const double u = static_cast<double>(k) / (n - 1);
      const double H = branch == 0 ? H_max * (1 - 2 * u) : H_max * (-1 + 2 * u);
      r.cols[0].push_back(H);
      r.cols[1].push_back(sample(H));
      r.lines.push_back(r.lines.size() + 2);
    }
  return r;
}

nlohmann::json magnetisation_report(const Record& r, const MagnetisationOptions& o, const MagnetisationFit& f,
                                    const std::filesystem::path& out) {
  std::filesystem::create_directories(out);
  const Points pt = effective(r, o);
  std::vector<std::vector<double>> rows;
  io::Series data;
  data.label = "VSM record";
  data.line = false;
  data.markers = true;
  data.marker_size = 2.5;
  io::Series fit;
  fit.label = fmt::format("linear-saturated: Ms = {:.3g} A/m, B_sat = {:.3g} T", f.Ms_A_per_m, f.B_sat_T);
  double Bmax = 0;
  for (std::size_t i = 0; i < r.rows(); ++i) {
    const double m = curve(f.Ms_A_per_m, f.B_sat_T, pt.B[i]);
    rows.push_back({r.cols[0][i], r.cols[1][i], pt.B[i], pt.M[i], m});
    data.x.push_back(pt.B[i]);
    data.y.push_back(pt.M[i]);
    Bmax = std::max(Bmax, std::fabs(pt.B[i]));
  }
  io::write_csv(out / "magnetisation.csv", {"H_A_per_m", "M_A_per_m", "B_eff_T", "M_pigment_A_per_m", "M_fit_A_per_m"}, rows);
  for (double b : {-Bmax, -f.B_sat_T, f.B_sat_T, Bmax}) {
    fit.x.push_back(b);
    fit.y.push_back(curve(f.Ms_A_per_m, f.B_sat_T, b));
  }
  io::PlotSpec plot;
  plot.title = fmt::format("Magnetisation curve (§4.5, fig. 4.20), demagnetising factor N = {:g}", o.demag_factor);
  plot.x_label = o.demag_factor > 0 ? "internal field mu0 (H - N M) [T]" : "external field mu0 H [T]";
  plot.y_label = "pigment magnetisation M [A/m]";
  plot.series = {data, fit};
  io::write_plot_png(out / "magnetisation.png", plot);
  return {{"calibration", "magnetisation"},
          {"data", r.source},
          {"saturation_magnetisation_A_per_m", f.Ms_A_per_m},
          {"saturation_magnetisation_std_A_per_m", f.Ms_std_A_per_m},
          {"saturation_flux_T", f.B_sat_T},
          {"saturation_flux_std_T", f.B_sat_std_T},
          {"correlation", f.corr},
          {"chi_linear", f.chi_linear},
          {"rms_residual_A_per_m", f.rms_residual_A_per_m},
          {"n_linear", f.n_linear},
          {"n_saturated", f.n_saturated},
          {"iterations", f.iterations},
          {"converged", f.converged},
          {"config",
           {{"magnet.saturation_magnetisation_A_per_m", f.Ms_A_per_m}, {"magnet.saturation_flux_T", f.B_sat_T}}},
          {"inputs", {{"demag_factor", o.demag_factor}, {"volume_fraction", o.volume_fraction}}},
          {"csv", (out / "magnetisation.csv").string()},
          {"plot", (out / "magnetisation.png").string()},
          {"meta", {{"git_hash", kGitHash}}}};
}

}  // namespace nipdem::calibrate
