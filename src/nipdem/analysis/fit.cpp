#include "nipdem/analysis/fit.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numeric>

#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"

namespace nipdem::analysis {

namespace {

const std::string kWhere = "sigmoid fit";

double logistic(double u) {
  if (u >= 0) return 1.0 / (1.0 + std::exp(-u));
  const double e = std::exp(u);
  return e / (1.0 + e);
}

void check_xy(const std::vector<double>& x, const std::vector<double>& c, std::size_t min_points) {
  if (x.size() != c.size())
    throw_input(kWhere, "curve", fmt::format("{} x, {} values", x.size(), c.size()), "x and coverage lengths differ");
  if (x.size() < min_points)
    throw_input(kWhere, "curve", fmt::format("{} points", x.size()), "too few points",
                fmt::format(">= {}", min_points));
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]) || !std::isfinite(c[i]))
      throw_input(kWhere, fmt::format("point {}", i), fmt::format("({:g}, {:g})", x[i], c[i]), "not finite");
}

// Sorted copy (by x) and a moving-average smoothed copy used only for initial values.
struct Prepared {
  std::vector<double> x, c, smooth;
};
Prepared prepare(const std::vector<double>& x, const std::vector<double>& c) {
  std::vector<std::size_t> idx(x.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::stable_sort(idx.begin(), idx.end(), [&](auto a, auto b) { return x[a] < x[b]; });
  Prepared p;
  for (auto i : idx) {
    p.x.push_back(x[i]);
    p.c.push_back(c[i]);
  }
  const std::size_t n = p.x.size();
  const std::size_t k = std::max<std::size_t>(1, n / 50);
  p.smooth.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i >= k ? i - k : 0, b = std::min(n - 1, i + k);
    double s = 0;
    for (std::size_t j = a; j <= b; ++j) s += p.c[j];
    p.smooth[i] = s / static_cast<double>(b - a + 1);
  }
  return p;
}

// First crossing of `level` in [i0, i1) going up (rising) or down; linear interpolation.
double crossing(const Prepared& p, std::size_t i0, std::size_t i1, double level, bool rising) {
  for (std::size_t i = i0 + 1; i < i1; ++i) {
    const double a = p.smooth[i - 1], b = p.smooth[i];
    const bool hit = rising ? (a < level && b >= level) : (a > level && b <= level);
    if (hit) {
      const double f = (b == a) ? 0.5 : (level - a) / (b - a);
      return p.x[i - 1] + f * (p.x[i] - p.x[i - 1]);
    }
  }
  return std::nan("");
}

// sqrt(1 / max(p(1-p), 1/N)) for a model probability p (relative to floor..ceiling).
double binomial_sqrt_weight(double p, int n_real) {
  const double v = std::max(p * (1.0 - p), 1.0 / n_real);
  return 1.0 / std::sqrt(v);
}

// Parameter layout shared by both models: core parameters first, then ceiling, then floor,
// each either fitted or fixed at the options' value.
struct Layout {
  int n_core = 2;
  int i_ceil = -1, i_floor = -1;
  double fixed_ceiling = 1.0, fixed_floor = 0.0;
  int size() const { return n_core + (i_ceil >= 0) + (i_floor >= 0); }
  double ceiling(const Eigen::VectorXd& p) const { return i_ceil >= 0 ? p[i_ceil] : fixed_ceiling; }
  double floor(const Eigen::VectorXd& p) const { return i_floor >= 0 ? p[i_floor] : fixed_floor; }
  // The start vector: `core`, then the start ceiling A0 and floor F0 where they are fitted.
  Eigen::VectorXd start(const Eigen::VectorXd& core, double A0, double F0) const {
    Eigen::VectorXd p0(size());
    p0 << core, Eigen::VectorXd::Zero(size() - n_core);
    if (i_ceil >= 0) p0[i_ceil] = A0;
    if (i_floor >= 0) p0[i_floor] = F0;
    return p0;
  }
};
Layout make_layout(int n_core, const SigmoidOptions& o) {
  Layout l;
  l.n_core = n_core;
  l.fixed_ceiling = o.ceiling;
  l.fixed_floor = o.floor;
  int k = n_core;
  if (o.fit_ceiling) l.i_ceil = k++;
  if (o.fit_floor) l.i_floor = k++;
  return l;
}

// The fit both sigmoid models share. `model(p, sw, r, J)` gives the residuals and Jacobian
// scaled by sw[i], the square roots of the least-squares weights. With
// opt.binomial_realizations > 0 the fit is repeated three times with the binomial variance of
// the fitted profile `profile(p, x)` (in [0, 1]) as weights; the rss reported is unweighted.
template <class Model, class Profile>
LmResult fit_reweighted(const Model& model, const Profile& profile, const Prepared& P, const Eigen::VectorXd& p0,
                        const SigmoidOptions& opt) {
  const std::size_t n = P.x.size();
  std::vector<double> sw(n, 1.0);
  auto weighted = [&](const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd& J) { model(p, sw, r, J); };
  LmResult R = levenberg_marquardt(weighted, p0, n, opt.max_iterations);
  for (int pass = 0; pass < (opt.binomial_realizations > 0 ? 3 : 0); ++pass) {
    for (std::size_t i = 0; i < n; ++i) sw[i] = binomial_sqrt_weight(profile(R.p, P.x[i]), opt.binomial_realizations);
    R = levenberg_marquardt(weighted, R.p, n, opt.max_iterations);
  }
  for (std::size_t i = 0; i < n; ++i) sw[i] = 1.0;  // report the unweighted rms residual
  Eigen::VectorXd r(n);
  Eigen::MatrixXd J(n, R.p.size());
  weighted(R.p, r, J);
  R.rss = r.squaredNorm();
  return R;
}

EdgeFit make_edge(double x0, double w, double floor, double ceiling, double var_w, double var_x0) {
  EdgeFit e;
  e.x0 = x0;
  e.w = w;
  e.floor = floor;
  e.ceiling = ceiling;
  e.width_10_90 = kLogistic1090 * std::abs(w);
  e.width_stderr = kLogistic1090 * std::sqrt(std::max(0.0, var_w));
  e.x0_stderr = std::sqrt(std::max(0.0, var_x0));
  const double ln9 = std::log(9.0);
  e.x10 = x0 - w * ln9;
  e.x90 = x0 + w * ln9;
  return e;
}

}  // namespace

LmResult levenberg_marquardt(const LmModel& model, Eigen::VectorXd p0, std::size_t n, const LmOptions& opt) {
  const Eigen::Index m = p0.size();
  const bool bounded = opt.lower.size() == m && opt.upper.size() == m;
  auto is_free = [&](Eigen::Index k) { return opt.free.empty() || opt.free[static_cast<std::size_t>(k)]; };
  LmResult res;
  Eigen::VectorXd r(n), r_new(n);
  Eigen::MatrixXd J(n, m), J_new(n, m);
  Eigen::VectorXd p = std::move(p0);
  model(p, r, J);
  double rss = r.squaredNorm();
  double lambda = 1e-3;
  bool converged = false;
  int it = 0;
  for (; it < opt.max_iterations && !converged; ++it) {
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    Eigen::VectorXd g = J.transpose() * r;
    const double floor = opt.damping_floor > 0.0 ? opt.damping_floor * std::max(JtJ.diagonal().maxCoeff(), 1e-300) : 1e-300;
    const Eigen::VectorXd d = JtJ.diagonal().cwiseMax(floor);
    for (Eigen::Index k = 0; k < m; ++k)
      if (!is_free(k)) g[k] = 0.0;
    for (int tries = 1;; ++tries) {
      Eigen::MatrixXd A = JtJ;
      for (Eigen::Index k = 0; k < m; ++k) {
        if (is_free(k)) {
          A(k, k) += lambda * d[k];
        } else {  // a fixed parameter: its row and column decouple, its step is 0
          A.row(k).setZero();
          A.col(k).setZero();
          A(k, k) = 1.0;
        }
      }
      Eigen::VectorXd step = A.ldlt().solve(-g);
      if (!step.allFinite()) {
        lambda *= 10;
      } else {
        const double big = step.cwiseAbs().maxCoeff();
        if (big > opt.max_step) step *= opt.max_step / big;
        Eigen::VectorXd p_new = p + step;
        if (bounded) p_new = p_new.cwiseMax(opt.lower).cwiseMin(opt.upper);
        model(p_new, r_new, J_new);
        const double rss_new = r_new.allFinite() ? r_new.squaredNorm() : std::numeric_limits<double>::infinity();
        if (opt.strict_decrease ? rss_new < rss : rss_new <= rss) {
          const double drop = rss - rss_new;
          if (opt.stop == LmOptions::Stop::relative) {
            const double step_norm = std::sqrt((step.array().square() * d.array()).sum());
            const double fit_norm = std::sqrt(std::max(rss_new, 1e-300));
            converged = drop <= opt.tol_drop * rss || rss_new == 0.0 || step_norm <= opt.tol_step * fit_norm;
          } else {
            const double change = (p_new - p).cwiseAbs().maxCoeff();
            converged = drop <= opt.tol_drop * rss_new + 1e-300 || change < opt.tol_step;
          }
          p = p_new;
          r.swap(r_new);
          J.swap(J_new);
          rss = rss_new;
          lambda = std::max(lambda / 3.0, 1e-12);
          break;
        }
        lambda *= 4.0;
      }
      if (lambda > opt.lambda_cap || (opt.max_tries > 0 && tries >= opt.max_tries)) {  // no downhill step left
        converged = true;
        break;
      }
    }
  }
  res.p = p;
  res.rss = rss;
  res.iterations = it;
  res.converged = converged;
  const double dof = static_cast<double>(n) - static_cast<double>(m);
  const Eigen::MatrixXd JtJ = J.transpose() * J;
  res.covariance = JtJ.completeOrthogonalDecomposition().pseudoInverse() * (dof > 0 ? rss / dof : 0.0);
  return res;
}

LmResult levenberg_marquardt(const LmModel& model, Eigen::VectorXd p0, std::size_t n, int max_iterations, double rel_tol) {
  LmOptions o;
  o.max_iterations = max_iterations;
  o.tol_drop = rel_tol;
  return levenberg_marquardt(model, std::move(p0), n, o);
}

EdgeFit fit_edge(const std::vector<double>& x_in, const std::vector<double>& c_in, const SigmoidOptions& opt) {
  check_xy(x_in, c_in, 5);
  const Prepared P = prepare(x_in, c_in);
  const std::size_t n = P.x.size();
  const bool rising = P.smooth.back() >= P.smooth.front();
  const double F0 = opt.fit_floor ? *std::min_element(P.smooth.begin(), P.smooth.end()) : opt.floor;
  const double A0 = opt.fit_ceiling ? *std::max_element(P.smooth.begin(), P.smooth.end()) : opt.ceiling;
  const double x10 = crossing(P, 0, n, F0 + 0.1 * (A0 - F0), rising);
  const double x50 = crossing(P, 0, n, F0 + 0.5 * (A0 - F0), rising);
  const double x90 = crossing(P, 0, n, F0 + 0.9 * (A0 - F0), rising);
  const double span = P.x.back() - P.x.front();
  double x0 = std::isfinite(x50) ? x50 : 0.5 * (P.x.front() + P.x.back());
  double w = (std::isfinite(x10) && std::isfinite(x90) && x90 != x10) ? (x90 - x10) / kLogistic1090 : 0.0;
  if (!(std::abs(w) > 1e-6 * span)) w = span / 20.0;
  w = rising ? std::abs(w) : -std::abs(w);

  const Layout L = make_layout(2, opt);
  auto model = [&](const Eigen::VectorXd& p, const std::vector<double>& sw, Eigen::VectorXd& r, Eigen::MatrixXd& J) {
    const double A = L.ceiling(p), F = L.floor(p);
    for (std::size_t i = 0; i < n; ++i) {
      const double u = (P.x[i] - p[0]) / p[1];
      const double s = logistic(u), ds = s * (1 - s);
      r[i] = sw[i] * (F + (A - F) * s - P.c[i]);
      J(i, 0) = -sw[i] * (A - F) * ds / p[1];
      J(i, 1) = -sw[i] * (A - F) * ds * u / p[1];
      if (L.i_ceil >= 0) J(i, L.i_ceil) = sw[i] * s;
      if (L.i_floor >= 0) J(i, L.i_floor) = sw[i] * (1 - s);
    }
  };
  auto profile = [](const Eigen::VectorXd& p, double x) { return logistic((x - p[0]) / p[1]); };
  const LmResult R = fit_reweighted(model, profile, P, L.start(Eigen::Vector2d(x0, w), A0, F0), opt);
  EdgeFit e = make_edge(R.p[0], R.p[1], L.floor(R.p), L.ceiling(R.p), R.covariance(1, 1), R.covariance(0, 0));
  e.rms_residual = std::sqrt(R.rss / n);
  e.iterations = R.iterations;
  e.converged = R.converged && std::isfinite(e.w) && e.w != 0.0;
  e.n_points = n;
  return e;
}

double evaluate(const EdgeFit& f, double x) { return f.floor + (f.ceiling - f.floor) * logistic((x - f.x0) / f.w); }

LineEdgesFit fit_line_edges(const std::vector<double>& x_in, const std::vector<double>& c_in, const SigmoidOptions& opt,
                            FrontSide front) {
  check_xy(x_in, c_in, 7);
  const Prepared P = prepare(x_in, c_in);
  const std::size_t n = P.x.size();
  const std::size_t ip = static_cast<std::size_t>(std::max_element(P.smooth.begin(), P.smooth.end()) - P.smooth.begin());
  const double F0 = opt.fit_floor ? *std::min_element(P.smooth.begin(), P.smooth.end()) : opt.floor;
  const double A0 = opt.fit_ceiling ? P.smooth[ip] : opt.ceiling;
  const double span = P.x.back() - P.x.front();
  auto level = [&](double q) { return F0 + q * (A0 - F0); };
  // Rise: crossings left of the peak; fall: right of the peak.
  double xr = crossing(P, 0, ip + 1, level(0.5), true);
  double xr10 = crossing(P, 0, ip + 1, level(0.1), true), xr90 = crossing(P, 0, ip + 1, level(0.9), true);
  double xf = crossing(P, ip, n, level(0.5), false);
  double xf10 = crossing(P, ip, n, level(0.1), false), xf90 = crossing(P, ip, n, level(0.9), false);
  if (!std::isfinite(xr)) xr = P.x.front() + 0.25 * span;
  if (!std::isfinite(xf)) xf = P.x.front() + 0.75 * span;
  double wr = (std::isfinite(xr10) && std::isfinite(xr90)) ? (xr90 - xr10) / kLogistic1090 : 0.0;
  double wf = (std::isfinite(xf10) && std::isfinite(xf90)) ? (xf10 - xf90) / kLogistic1090 : 0.0;
  const double wdef = std::max(std::abs(xf - xr) / 10.0, span / 100.0);
  if (!(wr > 1e-6 * span)) wr = wdef;
  if (!(wf > 1e-6 * span)) wf = wdef;

  const Layout L = make_layout(4, opt);
  auto model = [&](const Eigen::VectorXd& p, const std::vector<double>& sw, Eigen::VectorXd& r, Eigen::MatrixXd& J) {
    const double A = L.ceiling(p), F = L.floor(p);
    for (std::size_t i = 0; i < n; ++i) {
      const double u = (P.x[i] - p[0]) / p[1];
      const double v = -(P.x[i] - p[2]) / p[3];
      const double su = logistic(u), sv = logistic(v);
      const double dsu = su * (1 - su), dsv = sv * (1 - sv);
      const double k = sw[i] * (A - F);
      r[i] = sw[i] * (F + (A - F) * su * sv - P.c[i]);
      J(i, 0) = -k * dsu * sv / p[1];
      J(i, 1) = -k * dsu * sv * u / p[1];
      J(i, 2) = k * su * dsv / p[3];
      J(i, 3) = -k * su * dsv * v / p[3];
      if (L.i_ceil >= 0) J(i, L.i_ceil) = sw[i] * su * sv;
      if (L.i_floor >= 0) J(i, L.i_floor) = sw[i] * (1 - su * sv);
    }
  };
  auto profile = [](const Eigen::VectorXd& p, double x) { return logistic((x - p[0]) / p[1]) * logistic(-(x - p[2]) / p[3]); };
  const LmResult R = fit_reweighted(model, profile, P, L.start(Eigen::Vector4d(xr, wr, xf, wf), A0, F0), opt);
  LineEdgesFit f;
  f.floor = L.floor(R.p);
  f.ceiling = L.ceiling(R.p);
  f.rise = make_edge(R.p[0], R.p[1], f.floor, f.ceiling, R.covariance(1, 1), R.covariance(0, 0));
  f.fall = make_edge(R.p[2], -R.p[3], f.floor, f.ceiling, R.covariance(3, 3), R.covariance(2, 2));
  f.rms_residual = std::sqrt(R.rss / n);
  f.iterations = R.iterations;
  f.converged = R.converged && R.p[1] > 0 && R.p[3] > 0 && R.p[0] < R.p[2] && R.p.allFinite();
  for (EdgeFit* e : {&f.rise, &f.fall}) {
    e->rms_residual = f.rms_residual;
    e->iterations = f.iterations;
    e->converged = f.converged;
    e->n_points = n;
  }
  f.front = front == FrontSide::low_x ? f.rise : f.fall;
  f.back = front == FrontSide::low_x ? f.fall : f.rise;
  return f;
}

double evaluate(const LineEdgesFit& f, double x) {
  return f.floor + (f.ceiling - f.floor) * logistic((x - f.rise.x0) / f.rise.w) * logistic((x - f.fall.x0) / f.fall.w);
}

RangeEndCoverage range_end_coverage(const std::vector<double>& avg, int edge_bins, double threshold) {
  const int n = static_cast<int>(avg.size());
  if (n < 2) throw_input("coverage range ends", "points", std::to_string(n), "need >= 2");
  double peak = 0;
  for (double c : avg) peak = std::max(peak, c);
  if (!(peak > 0)) throw_input("coverage range ends", "peak coverage", std::to_string(peak), "need > 0 (nothing printed)");
  const int m = std::max(1, std::min(n / 4, edge_bins));
  double lo = 0, hi = 0;
  for (int k = 0; k < m; ++k) lo += avg[k] / m, hi += avg[n - 1 - k] / m;
  RangeEndCoverage r;
  r.at_start = lo / peak;
  r.at_end = hi / peak;
  r.start_cut = r.at_start > threshold;
  r.end_cut = r.at_end > threshold;
  if (r.start_cut)
    r.warnings.push_back(fmt::format("coverage at the range start is {:.0f} % of the peak: the edge there is cut by the analysis range; use a larger --margin", 100 * r.at_start));
  if (r.end_cut)
    r.warnings.push_back(fmt::format("coverage at the range end is {:.0f} % of the peak: printing goes on past line end + margin; use a larger --margin", 100 * r.at_end));
  return r;
}

std::vector<double> average_curve(const std::vector<std::vector<double>>& real) {
  if (real.empty()) throw_input("coverage average", "realizations", "0", "no realizations to average");
  const std::size_t n = real[0].size();
  std::vector<double> avg(n, 0.0);
  for (std::size_t k = 0; k < real.size(); ++k) {
    if (real[k].size() != n)
      throw_input("coverage average", fmt::format("realization {}", k), fmt::format("{} points", real[k].size()),
                  "curves must share one grid", fmt::format("{} points", n));
    for (std::size_t i = 0; i < n; ++i) avg[i] += real[k][i];
  }
  for (double& a : avg) a /= static_cast<double>(real.size());
  return avg;
}

Interval percentile_interval(std::vector<double> s, double level) {
  if (s.empty()) return {std::nan(""), std::nan("")};
  std::sort(s.begin(), s.end());
  auto q = [&](double f) {
    const double pos = f * static_cast<double>(s.size() - 1);
    const std::size_t i = static_cast<std::size_t>(std::floor(pos));
    const std::size_t j = std::min(i + 1, s.size() - 1);
    return s[i] + (pos - static_cast<double>(i)) * (s[j] - s[i]);
  };
  return {q(0.5 * (1 - level)), q(0.5 * (1 + level))};
}

BootstrapSamples bootstrap_curves(const std::vector<std::vector<double>>& real,
                                  const std::function<std::vector<double>(const std::vector<double>&)>& statistic,
                                  int n_boot, std::uint64_t seed) {
  if (real.empty()) throw_input("bootstrap", "realizations", "0", "no realizations");
  if (n_boot < 1) throw_input("bootstrap", "n_boot", std::to_string(n_boot), "must be at least 1");
  BootstrapSamples out;
  Rng rng(seed);
  const std::size_t N = real.size();
  std::vector<std::vector<double>> pick(N);
  for (int b = 0; b < n_boot; ++b) {
    for (std::size_t k = 0; k < N; ++k) {
      const std::size_t j = std::min(N - 1, static_cast<std::size_t>(rng.uniform() * static_cast<double>(N)));
      pick[k] = real[j];
    }
    try {
      auto st = statistic(average_curve(pick));
      if (st.empty()) ++out.n_failed;
      else out.stats.push_back(std::move(st));
    } catch (const std::exception&) {
      ++out.n_failed;
    }
  }
  return out;
}

LineEdgesBootstrap bootstrap_line_edges(const std::vector<double>& x, const std::vector<std::vector<double>>& real,
                                        int n_boot, std::uint64_t seed, double level, const SigmoidOptions& opt,
                                        FrontSide front) {
  require_range("bootstrap", "level", level, 0.0, 1.0);
  LineEdgesBootstrap out;
  out.level = level;
  out.n_boot = n_boot;
  out.average = average_curve(real);
  out.fit = fit_line_edges(x, out.average, opt, front);
  auto stat = [&](const std::vector<double>& avg) -> std::vector<double> {
    const LineEdgesFit f = fit_line_edges(x, avg, opt, front);
    if (!f.converged) return {};
    return {f.front.width_10_90, f.back.width_10_90};
  };
  const BootstrapSamples bs = bootstrap_curves(real, stat, n_boot, seed);
  out.n_failed = bs.n_failed;
  std::vector<double> fw, bw;
  for (const auto& s : bs.stats) {
    fw.push_back(s[0]);
    bw.push_back(s[1]);
  }
  auto sd = [](const std::vector<double>& v) {
    if (v.size() < 2) return std::nan("");
    const double m = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
    double s = 0;
    for (double a : v) s += (a - m) * (a - m);
    return std::sqrt(s / (v.size() - 1));
  };
  out.front_width_ci = percentile_interval(fw, level);
  out.back_width_ci = percentile_interval(bw, level);
  out.front_width_std = sd(fw);
  out.back_width_std = sd(bw);
  return out;
}

}  // namespace nipdem::analysis
