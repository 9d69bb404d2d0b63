#include "nipdem/experiments/vo_level.hpp"

#include <cmath>

#include "nipdem/core/error.hpp"
#include "nipdem/analysis/analysis.hpp"

namespace nipdem::experiments {

using nlohmann::json;

namespace {
analysis::VoSearchOptions search_options(const VoOptions& v) {
  return {.v0_V = v.v0_V, .step_V = v.step_V, .v_max_V = v.v_max_V, .coarse_step_V = v.coarse_step_V};
}

void check(const VoOptions& v) {
  require_range("experiment vo-level", "--step", v.step_V, 1e-3, 100.0);
  if (v.seeds < 1 || v.seeds > 100000) throw_input("experiment vo-level", "--seeds", std::to_string(v.seeds), "out of range", "[1, 100000]");
  check_print_options("experiment vo-level", v.print);
  // the search options are checked once here (exit 2), not in every seed's task
  analysis::find_vo_level([](double) { return 1L; }, search_options(v));
}

// One seed: the part before the line once, then one line per voltage of the search.
json run_seed_scan(const ExperimentOptions& o, const VoOptions& v, const nip::NipConfig& base, std::uint64_t seed) {
  const auto prefix = print_prefix(o, base, v.print, seed);
  const auto res = analysis::find_vo_level(
      [&](double V) { return print_line(o, base, v.print, V, seed, 0.0, prefix ? &*prefix : nullptr).printed; }, search_options(v));
  json trace = json::array();
  for (auto& [V, n] : res.trace) trace.push_back({V, n});
  return json{{"found", res.found}, {"vo_V", res.vo_V}, {"trace_V_printed", trace}};
}
}  // namespace

json vo_level(const ExperimentOptions& o, const VoOptions& v) {
  check(v);
  // reject a bad configuration or line before any run starts (exit 2, not failed points)
  reject_fixed_sets(o, "vo-level", print_fixed_keys(v.print, true));
  const nip::NipConfig base = base_config(o);
  print_config(base, v.print, 1.0, std::nullopt);
  const auto sum = ensemble::run([&](std::size_t, std::uint64_t seed) { return run_seed_scan(o, v, base, seed); },
                                 ensemble_options(o, static_cast<std::size_t>(v.seeds), "vo_level"));
  if (!sum.is_root) return {};
  std::vector<double> vo;
  json per = json::array();
  for (const auto& r : sum.records) {
    if (!r.ok) continue;
    per.push_back(r.result);
    if (r.result["found"].get<bool>()) vo.push_back(r.result["vo_V"].get<double>());
  }
  double mean = 0, sd = 0;
  for (double x : vo) mean += x;
  if (!vo.empty()) mean /= vo.size();
  for (double x : vo) sd += (x - mean) * (x - mean);
  if (vo.size() > 1) sd = std::sqrt(sd / (vo.size() - 1));
  return {{"experiment", "vo-level"}, {"step_V", v.step_V}, {"coarse_step_V", v.coarse_step_V}, {"vo_mean_V", vo.empty() ? json(nullptr) : json(mean)}, {"vo_std_V", sd},
          {"seeds_found", vo.size()}, {"seeds_total", v.seeds}, {"per_seed", per}, {"failed", failures(sum)},
          {"n_failed", sum.n_failed}, {"meta", meta(o, &sum)}};
}

}  // namespace nipdem::experiments
