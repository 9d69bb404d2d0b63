#include "nipdem/experiments/calibrate_rc.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <sstream>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/analysis/fit.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::probe {
namespace {

using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;
constexpr double kInf = std::numeric_limits<double>::infinity();
// Search box in log-parameters: R, Rd in [1, 1e30] ohm; C in [1e-30, 1] F.
const double kLo[3] = {0.0, 0.0, std::log(1e-30)};
const double kHi[3] = {std::log(1e30), std::log(1e30), 0.0};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream is(line);
  while (std::getline(is, cur, ',')) out.push_back(trim(cur));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

struct Ctx {
  const std::vector<RcDataPoint>* data;
  RcFitOptions opt;
  double sA = 0.01, sP = 1.0;  // residual scales (relative amplitude, degrees)
};

Vec residual(const Ctx& c, const double x[3]) {
  const auto& d = *c.data;
  const std::size_t n = d.size();
  Vec r(2 * n);
  ProbeCircuitParams p{std::exp(x[0]), std::exp(x[1]), std::exp(x[2]), c.opt.Rm_ohm};
  for (std::size_t i = 0; i < n; ++i) {
    const ProbeResponse s = response(p, c.opt.voltage_V, d[i].frequency_Hz);
    r[i] = (std::log(c.opt.particles * s.amplitude_V) - std::log(d[i].amplitude_V)) / c.sA;
    r[n + i] = (s.phase_deg() - d[i].phase_deg) / c.sP;
  }
  return r;
}

// Central-difference Jacobian of the residuals in the free components of x (others: 0).
Mat jacobian(const Ctx& c, const double x[3], const bool free[3]) {
  const std::size_t m = 2 * c.data->size();
  Mat J = Mat::Zero(static_cast<Eigen::Index>(m), 3);
  for (int k = 0; k < 3; ++k) {
    if (!free[k]) continue;
    double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
    const double h = 1e-6;
    xp[k] += h;
    xm[k] -= h;
    J.col(k) = (residual(c, xp) - residual(c, xm)) / (2.0 * h);
  }
  return J;
}

struct LmOut {
  double chi2 = 0;
  int iterations = 0;
  bool converged = false;
};

// Levenberg–Marquardt (analysis::levenberg_marquardt) on the free components of x (in place),
// kept inside the search box, at most a factor e^2 per step; central-difference Jacobian.
LmOut levenberg_marquardt(const Ctx& c, double x[3], const bool free[3], int max_it) {
  analysis::LmModel model = [&](const Vec& p, Vec& r, Mat& J) {
    const double xp[3] = {p[0], p[1], p[2]};
    r = residual(c, xp);
    J = jacobian(c, xp, free);
  };
  analysis::LmOptions o;
  o.max_iterations = max_it;
  o.stop = analysis::LmOptions::Stop::absolute;
  o.tol_drop = 1e-12;
  o.tol_step = 1e-10;
  o.free = {free[0], free[1], free[2]};
  o.lower = Vec::Map(kLo, 3);
  o.upper = Vec::Map(kHi, 3);
  o.max_step = 2.0;  // trust region: at most a factor e^2 per step
  o.damping_floor = 1e-9;
  o.strict_decrease = true;
  o.lambda_cap = kInf;
  o.max_tries = 30;
  const analysis::LmResult fit = analysis::levenberg_marquardt(model, Vec::Map(x, 3), 2 * c.data->size(), o);
  for (int k = 0; k < 3; ++k) x[k] = fit.p[k];
  return {fit.rss, fit.iterations, fit.converged};
}

// Initial R, C assuming Rd -> inf: Vm/V = Rm i w C / (1 + i w C (R + Rm)).
void initial_guess(const Ctx& c, double& R, double& C) {
  std::vector<double> Rs, Cs;
  for (const auto& d : *c.data) {
    const double w = 2.0 * constants::pi * d.frequency_Hz;
    const double phi = d.phase_deg * constants::pi / 180.0;
    if (!(phi > 1e-3)) continue;
    const double tau = 1.0 / (w * std::tan(phi));
    const double Cg = d.amplitude_V / c.opt.particles * std::sqrt(1.0 + w * w * tau * tau) /
                      (std::fabs(c.opt.voltage_V) * c.opt.Rm_ohm * w);
    const double Rg = tau / Cg - c.opt.Rm_ohm;
    if (Cg > 0 && Rg > 0) { Rs.push_back(Rg); Cs.push_back(Cg); }
  }
  if (Rs.empty()) {  // no usable phase: assume w tau ~ 1 at the median frequency
    const double f = (*c.data)[c.data->size() / 2].frequency_Hz, w = 2 * constants::pi * f;
    const double A = (*c.data)[c.data->size() / 2].amplitude_V / c.opt.particles;
    C = A * std::sqrt(2.0) / (std::fabs(c.opt.voltage_V) * c.opt.Rm_ohm * w);
    R = 1.0 / (w * C);
    return;
  }
  std::nth_element(Rs.begin(), Rs.begin() + Rs.size() / 2, Rs.end());
  std::nth_element(Cs.begin(), Cs.begin() + Cs.size() / 2, Cs.end());
  R = std::clamp(Rs[Rs.size() / 2], 1.0, 1e30);
  C = std::clamp(Cs[Cs.size() / 2], 1e-30, 1.0);
}

// Best fit over several starting values of Rd.
LmOut multistart(const Ctx& c, double x[3], int max_it) {
  double R0, C0;
  initial_guess(c, R0, C0);
  const bool all[3] = {true, true, true};
  LmOut best;
  best.chi2 = kInf;
  double xb[3] = {0, 0, 0};
  for (double k : {-2.0, 0.0, 2.0, 5.0, 9.0, 14.0}) {
    double xs[3] = {std::log(R0), std::clamp(std::log(R0) + k * std::log(10.0), kLo[1], kHi[1]), std::log(C0)};
    const LmOut o = levenberg_marquardt(c, xs, all, max_it);
    if (o.chi2 < best.chi2) {
      best = o;
      std::copy(xs, xs + 3, xb);
    }
  }
  std::copy(xb, xb + 3, x);
  return best;
}

// chi^2 with ln Rd fixed at t, R and C refitted (warm start from x).
double profile_chi2(const Ctx& c, const double x[3], double t, int max_it) {
  double xs[3] = {x[0], t, x[2]};
  const bool free[3] = {true, false, true};
  return levenberg_marquardt(c, xs, free, max_it).chi2;
}

// Where the profile crosses `threshold` between t_in (inside) and t_out (outside the interval).
double profile_crossing(const Ctx& c, const double x[3], double t_in, double t_out, double threshold, int max_it) {
  if (profile_chi2(c, x, t_out, max_it) <= threshold) return t_out;
  for (int i = 0; i < 40; ++i) {
    const double tm = 0.5 * (t_in + t_out);
    if (profile_chi2(c, x, tm, max_it) <= threshold) t_in = tm; else t_out = tm;
    if (std::fabs(t_out - t_in) < 1e-4) break;
  }
  return 0.5 * (t_in + t_out);
}

}  // namespace

void RcFitOptions::validate() const {
  if (!std::isfinite(voltage_V) || voltage_V == 0.0)
    throw_input("calibrate rc", "voltage_V", fmt::format("{:g}", voltage_V), "must be finite and non-zero");
  require_positive("calibrate rc", "Rm_ohm", Rm_ohm);
  require_positive("calibrate rc", "particles", particles);
  require_range("calibrate rc", "amplitude_rel_std", amplitude_rel_std, 0.0, 10.0);
  require_range("calibrate rc", "phase_std_deg", phase_std_deg, 0.0, 90.0);
  require_range("calibrate rc", "max_iterations", max_iterations, 1, 1e6);
}

std::vector<RcDataPoint> parse_rc_csv(const std::string& text, const std::string& source) {
  std::istringstream is(text);
  std::string line;
  int lineno = 0;
  int ci[3] = {-1, -1, -1};
  const char* names[3] = {"frequency_Hz", "amplitude_V", "phase_deg"};
  bool have_header = false;
  std::size_t ncols = 0;
  std::vector<RcDataPoint> out;
  while (std::getline(is, line)) {
    ++lineno;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    const auto f = split(t);
    if (!have_header) {
      for (std::size_t k = 0; k < f.size(); ++k)
        for (int j = 0; j < 3; ++j)
          if (f[k] == names[j]) ci[j] = static_cast<int>(k);
      for (int j = 0; j < 3; ++j)
        if (ci[j] < 0)
          throw_input(source, names[j], "", fmt::format("header (line {}) lacks column", lineno),
                      "header with frequency_Hz,amplitude_V,phase_deg");
      ncols = f.size();
      have_header = true;
      continue;
    }
    if (f.size() < ncols)
      throw_input(source, fmt::format("line {}", lineno), t, fmt::format("has {} fields, header has {}", f.size(), ncols));
    double v[3];
    for (int j = 0; j < 3; ++j) {
      const std::string& s = f[static_cast<std::size_t>(ci[j])];
      try {
        std::size_t used = 0;
        v[j] = std::stod(s, &used);
        if (used != s.size() || !std::isfinite(v[j])) throw std::invalid_argument("x");
      } catch (const std::exception&) {
        throw_input(source, fmt::format("line {} column {}", lineno, names[j]), s, "not a finite number");
      }
    }
    if (!(v[0] > 0 && v[0] <= kMaxFrequency_Hz))
      throw_input(source, fmt::format("line {} column frequency_Hz", lineno), f[ci[0]], "out of range",
                  fmt::format("(0, {:g}] Hz", kMaxFrequency_Hz));
    if (!(v[1] > 0)) throw_input(source, fmt::format("line {} column amplitude_V", lineno), f[ci[1]], "must be positive", "(0, inf)");
    if (!(std::fabs(v[2]) < 90.0))
      throw_input(source, fmt::format("line {} column phase_deg", lineno), f[ci[2]], "out of range", "(-90, 90)");
    out.push_back({v[0], v[1], v[2]});
  }
  if (!have_header) throw_input(source, "", "", "empty file: no header", "header frequency_Hz,amplitude_V,phase_deg");
  if (out.size() < 3)
    throw_input(source, "rows", std::to_string(out.size()), "too few data rows to fit 3 parameters", ">= 3");
  return out;
}

std::vector<RcDataPoint> read_rc_csv(const std::filesystem::path& path) {
  return parse_rc_csv(io::read_file(path), path.string());
}

RcFitResult fit_rc(const std::vector<RcDataPoint>& data, const RcFitOptions& opt) {
  opt.validate();
  if (data.size() < 3) throw_input("calibrate rc", "data", std::to_string(data.size()) + " rows", "too few", ">= 3");
  for (const auto& d : data) {
    require_positive("calibrate rc", "frequency_Hz", d.frequency_Hz);
    require_range("calibrate rc", "frequency_Hz", d.frequency_Hz, 0.0, kMaxFrequency_Hz);
    require_positive("calibrate rc", "amplitude_V", d.amplitude_V);
    require_range("calibrate rc", "phase_deg", d.phase_deg, -90.0, 90.0);
  }
  Ctx c{&data, opt};
  const bool known = opt.amplitude_rel_std > 0 && opt.phase_std_deg > 0;
  if (opt.amplitude_rel_std > 0) c.sA = opt.amplitude_rel_std;
  if (opt.phase_std_deg > 0) c.sP = opt.phase_std_deg;
  double x[3];
  LmOut o = multistart(c, x, opt.max_iterations);
  const std::size_t n = data.size();
  int total_it = o.iterations;
  if (!known) {
    // Re-estimate the noise levels from the residuals (each block gets half of the 3 fitted dof).
    for (int pass = 0; pass < 2; ++pass) {
      const Vec r = residual(c, x);
      const double dofb = std::max(static_cast<double>(n) - 1.5, 1.0);
      if (opt.amplitude_rel_std <= 0) c.sA = std::max(std::sqrt(r.head(n).squaredNorm() / dofb) * c.sA, 1e-12);
      if (opt.phase_std_deg <= 0) c.sP = std::max(std::sqrt(r.tail(n).squaredNorm() / dofb) * c.sP, 1e-10);
      const bool all[3] = {true, true, true};
      o = levenberg_marquardt(c, x, all, opt.max_iterations);
      total_it += o.iterations;
    }
  }
  RcFitResult res;
  res.R_ohm = std::exp(x[0]);
  res.Rd_ohm = std::exp(x[1]);
  res.C_F = std::exp(x[2]);
  res.chi2 = o.chi2;
  res.dof = static_cast<int>(2 * n) - 3;
  res.iterations = total_it;
  res.converged = o.converged;
  res.amplitude_rel_std = c.sA;
  res.phase_std_deg = c.sP;
  res.tau_s = (res.R_ohm + opt.Rm_ohm) * res.C_F;

  // Profile-likelihood 95 % interval of Rd.
  const double thr = o.chi2 + 3.84;
  const double lo_t = profile_crossing(c, x, x[1], kLo[1], thr, opt.max_iterations);
  const double hi_t = profile_crossing(c, x, x[1], kHi[1], thr, opt.max_iterations);
  res.Rd_ohm_lower_95 = std::exp(lo_t);
  res.Rd_identifiable = hi_t < kHi[1] - 1e-6 && lo_t > kLo[1] + 1e-6;
  res.Rd_ohm_upper_95 = hi_t < kHi[1] - 1e-6 ? std::exp(hi_t) : kInf;

  // Covariance of the log-parameters.
  const bool all[3] = {true, true, true};
  const bool noRd[3] = {true, false, true};
  const Mat J = jacobian(c, x, res.Rd_identifiable ? all : noRd);
  Mat A = J.transpose() * J;
  if (!res.Rd_identifiable) A(1, 1) = 1.0;  // column is zero: decouple Rd
  const Mat cov = A.inverse();
  res.R_log_std = std::sqrt(cov(0, 0));
  res.C_log_std = std::sqrt(cov(2, 2));
  res.Rd_log_std = res.Rd_identifiable ? std::sqrt(cov(1, 1)) : kInf;
  res.corr_R_C = cov(0, 2) / (res.R_log_std * res.C_log_std);
  res.R_ohm_std = res.R_ohm * res.R_log_std;
  res.C_F_std = res.C_F * res.C_log_std;
  res.Rd_ohm_std = res.Rd_identifiable ? res.Rd_ohm * res.Rd_log_std : kInf;

  // A fit stuck at the search box or without finite chi2 / uncertainties is no fit.
  const double tol = 1e-6;  // in ln units
  if (x[0] <= kLo[0] + tol || x[0] >= kHi[0] - tol)
    res.limit_hit = fmt::format("R_ohm = {:g} is at the end of the search range [1, 1e30] ohm", res.R_ohm);
  else if (x[2] <= kLo[2] + tol || x[2] >= kHi[2] - tol)
    res.limit_hit = fmt::format("C_F = {:g} is at the end of the search range [1e-30, 1] F", res.C_F);
  if (!res.limit_hit.empty() || !std::isfinite(res.chi2) || !std::isfinite(res.R_log_std) || !std::isfinite(res.C_log_std))
    res.converged = false;
  return res;
}

void check_amplitude(const std::string& where, double V) {
  const std::string allowed = "[1e-06, 1e+06] V";
  if (V < 0.0)
    throw_input(where, "--voltage", fmt::format("{:g}", V),
                "is the amplitude of the applied V sin(wt) and must be positive (a negative amplitude is the "
                "same signal shifted by 180 deg; give its magnitude)",
                allowed);
  if (!(V >= 1e-6 && V <= 1e6)) throw_input(where, "--voltage", fmt::format("{:g}", V), "out of range", allowed);
}

std::vector<ProbeResponse> rc_response_table(const ProbeCircuitParams& p, double voltage_V, const std::string& freq) {
  // A value <= 0 is refused by validate (its message names the circuit's key); then physical
  // ranges (the thesis' circuit: R ~ 1e6, Rd >= 1e24 ohm, C ~ 1e-12 F, Rm = 1e4 ohm, 40 V,
  // 500-2000 Hz) with wide margins, so that no amplitude or phase overflows into null.
  p.validate();
  require_range("rc response", "--R", p.R_ohm, 1e-3, 1e30);
  require_range("rc response", "--Rd", p.Rd_ohm, 1e-3, 1e40);
  require_range("rc response", "--C", p.C_F, 1e-24, 1.0);
  require_range("rc response", "--Rm", p.Rm_ohm, 1e-3, 1e30);
  check_amplitude("rc response", voltage_V);
  const auto fs = parse_frequency_range(freq);
  if (fs.back() > kMaxFrequency_Hz)
    throw_input("rc response", "--freq", freq, fmt::format("frequencies above {:g} Hz", kMaxFrequency_Hz),
                fmt::format("F1:F2:STEP with 0 < F1 <= F2 <= {:g} Hz", kMaxFrequency_Hz));
  std::vector<ProbeResponse> rows;
  rows.reserve(fs.size());
  for (double f : fs) {
    rows.push_back(response(p, voltage_V, f));
    const ProbeResponse& r = rows.back();
    if (!std::isfinite(r.amplitude_V) || !std::isfinite(r.phase_deg()))  // not reached within the ranges above
      throw_input("rc response", "--R, --Rd, --C, --Rm, --voltage, --freq", fmt::format("at {:g} Hz", f),
                  "the response is not computable for these inputs");
  }
  return rows;
}

}  // namespace nipdem::probe
