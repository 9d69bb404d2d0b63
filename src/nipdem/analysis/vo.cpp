#include "nipdem/analysis/vo.hpp"

#include <cmath>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"

namespace nipdem::analysis {

VoResult find_vo_level(const std::function<long(double)>& count, const VoSearchOptions& opt) {
  const std::string where = "Vo-level search";
  if (!std::isfinite(opt.step_V) || opt.step_V == 0.0)
    throw_input(where, "step_V", fmt::format("{:g}", opt.step_V), "must be non-zero and finite");
  if (!std::isfinite(opt.v0_V) || !std::isfinite(opt.v_max_V))
    throw_input(where, "v0_V/v_max_V", fmt::format("{:g}/{:g}", opt.v0_V, opt.v_max_V), "must be finite");
  if ((opt.v_max_V - opt.v0_V) * opt.step_V < 0)
    throw_input(where, "v_max_V", fmt::format("{:g}", opt.v_max_V), "lies on the wrong side of v0_V for this step sign");
  const long n_steps = static_cast<long>(std::floor((opt.v_max_V - opt.v0_V) / opt.step_V + 1e-9));
  if (n_steps > 100000) throw_input(where, "step_V", fmt::format("{:g}", opt.step_V), "more than 1e5 steps to v_max_V");
  VoResult r;
  if (opt.coarse_step_V != 0.0) {
    const double m_real = opt.coarse_step_V / opt.step_V;
    const long m = std::lround(m_real);
    if (!std::isfinite(m_real) || m < 2 || std::fabs(m_real - static_cast<double>(m)) > 1e-9 * std::fabs(m_real))
      throw_input(where, "coarse_step_V", fmt::format("{:g}", opt.coarse_step_V),
                  fmt::format("must be an integer multiple >= 2 of step_V ({:g}), with the same sign", opt.step_V));
    auto try_k = [&](long k) {  // fine-grid index k
      const double V = opt.v0_V + static_cast<double>(k) * opt.step_V;
      const long c = count(V);
      r.trace.emplace_back(V, c);
      if (c > 0) { r.found = true; r.vo_V = V; r.count_at_vo = c; }
      return c > 0;
    };
    std::vector<long> coarse;  // 0, m, 2m, ... and the last fine index before v_max
    for (long k = 0; k <= n_steps; k += m) coarse.push_back(k);
    if (coarse.back() != n_steps) coarse.push_back(n_steps);
    for (std::size_t i = 0; i < coarse.size(); ++i) {
      if (!try_k(coarse[i])) continue;
      if (i == 0) break;
      const double vc = r.vo_V;
      const long cc = r.count_at_vo;
      r.found = false;
      for (long k = coarse[i - 1] + 1; k < coarse[i]; ++k)
        if (try_k(k)) break;
      if (!r.found) { r.found = true; r.vo_V = vc; r.count_at_vo = cc; }
      break;
    }
    return r;
  }
  for (long k = 0; k <= n_steps; ++k) {
    const double V = opt.v0_V + static_cast<double>(k) * opt.step_V;  // no accumulated round-off
    const long c = count(V);
    r.trace.emplace_back(V, c);
    if (c > 0) {
      r.found = true;
      r.vo_V = V;
      r.count_at_vo = c;
      break;
    }
  }
  return r;
}

VoStatistics vo_level_over_seeds(const std::function<long(double, std::uint64_t)>& count,
                                 const std::vector<std::uint64_t>& seeds, const VoSearchOptions& opt) {
  VoStatistics s;
  for (auto seed : seeds) {
    const VoResult r = find_vo_level([&](double V) { return count(V, seed); }, opt);
    if (r.found) s.vo_V.push_back(r.vo_V);
    else s.seeds_not_found.push_back(seed);
  }
  const std::size_t n = s.vo_V.size();
  if (n > 0) {
    double m = 0;
    for (double v : s.vo_V) m += v;
    m /= n;
    double ss = 0;
    for (double v : s.vo_V) ss += (v - m) * (v - m);
    s.mean_V = m;
    s.std_V = n > 1 ? std::sqrt(ss / (n - 1)) : 0.0;
    s.stderr_V = s.std_V / std::sqrt(static_cast<double>(n));
  } else {
    s.mean_V = std::nan("");
    s.std_V = std::nan("");
    s.stderr_V = std::nan("");
  }
  return s;
}

}  // namespace nipdem::analysis
