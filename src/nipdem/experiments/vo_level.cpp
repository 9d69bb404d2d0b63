#include "nipdem/experiments/vo_level.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>

#include "nipdem/core/crc32c.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/analysis/analysis.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::experiments {

using nlohmann::json;

namespace {
analysis::VoSearchOptions search_options(const VoOptions& v) {
  return {.v0_V = v.v0_V, .step_V = v.step_V, .v_max_V = v.v_max_V, .coarse_step_V = v.coarse_step_V};
}

// Largest |voltage| of the search [V]: far above any Vo-level (tens of V, §5.2). Without a bound
// --v0 -1e308 made the step count overflow and the search ran no line at all (exit 0, found false).
constexpr double kMaxVoltage_V = 1e4;
// The search's own limit on the steps of one seed (analysis::find_vo_level), checked here first so
// that the message names the options.
constexpr double kMaxSteps = 1e5;

void check(const VoOptions& v) {
  const std::string where = "experiment vo-level";
  require_range(where, "--step", v.step_V, 1e-3, 100.0);
  require_range(where, "--v0", v.v0_V, -kMaxVoltage_V, kMaxVoltage_V);
  require_range(where, "--vmax", v.v_max_V, v.v0_V, kMaxVoltage_V);  // the step is > 0: upwards from --v0
  require_range(where, "--coarse-step", v.coarse_step_V, 0.0, 2 * kMaxVoltage_V);
  const double steps = std::floor((v.v_max_V - v.v0_V) / v.step_V + 1e-9);  // as find_vo_level counts them
  if (steps > kMaxSteps)
    throw_input(where, "--step", fmt::format("{:g}", v.step_V),
                fmt::format("{:g} steps per seed from --v0 {:g} to --vmax {:g}", steps, v.v0_V, v.v_max_V),
                fmt::format(">= (vmax - v0) / {:g}", kMaxSteps));
  if (v.seeds < 1 || v.seeds > 100000) throw_input(where, "--seeds", std::to_string(v.seeds), "out of range", "[1, 100000]");
  check_print_options(where, v.print);
  // the search options are checked once here (exit 2), not in every seed's task
  analysis::find_vo_level([](double) { return 1L; }, search_options(v));
}

// The lines a seed's scan has finished, kept in OUT/vo_level/lines/<index>.json after each one, so
// that an interrupted scan goes on where it stopped: the bisection asks for the same voltages in
// the same order, and a voltage found there is not run again. The file names its seed and a
// CRC-32C of the resolved configuration and the line's options; a file that does not match, or
// cannot be read, is set aside with a warning and its lines are run again (never reused).
class LineMemo {
 public:
  LineMemo(const ExperimentOptions& o, const nip::NipConfig& base, const PrintOptions& p, std::size_t index,
           std::uint64_t seed)
      : seed_(seed),
        key_(crc32c(base.resolved_toml + fmt::format("\nline {:.17g} {:.17g} {:.17g}", p.line_start_m, p.line_length_m,
                                                     p.extra_time_s))) {
    if (o.out.empty()) return;  // results in memory only
    file_ = o.out / "vo_level" / "lines" / (std::to_string(index) + ".json");
    if (!o.resume || !std::filesystem::exists(file_)) return;
    try {
      const json j = json::parse(io::read_file(file_));
      if (j.at("seed").get<std::uint64_t>() != seed_ || j.at("config_crc32c").get<std::uint32_t>() != key_) {
        std::fprintf(stderr, "nipdem: warning: %s was made for another seed or configuration; running its lines again\n",
                     file_.c_str());
        return;
      }
      for (const auto& l : j.at("lines_V_printed")) lines_.push_back({l.at(0).get<double>(), l.at(1).get<long>()});
    } catch (const std::exception& e) {
      lines_.clear();
      std::fprintf(stderr, "nipdem: warning: %s unreadable (%s); running its lines again\n", file_.c_str(), e.what());
    }
  }
  const long* find(double V) const {
    for (const auto& l : lines_)
      if (l.first == V) return &l.second;
    return nullptr;
  }
  void add(double V, long printed) {
    lines_.push_back({V, printed});
    if (file_.empty()) return;
    json arr = json::array();
    for (const auto& [v, n] : lines_) arr.push_back({v, n});
    std::filesystem::create_directories(file_.parent_path());
    io::write_file_atomic(file_, json{{"seed", seed_}, {"config_crc32c", key_}, {"lines_V_printed", arr}}.dump(1) + "\n");
  }
  std::size_t size() const { return lines_.size(); }

 private:
  std::uint64_t seed_;
  std::uint32_t key_;
  std::filesystem::path file_;
  std::vector<std::pair<double, long>> lines_;
};

// One seed: the part before the line once (only if a line is still to run), then one line per
// voltage of the search, each kept as it finishes (LineMemo).
json run_seed_scan(const ExperimentOptions& o, const VoOptions& v, const nip::NipConfig& base, std::size_t index,
                   std::uint64_t seed) {
  LineMemo memo(o, base, v.print, index, seed);
  const std::size_t resumed = memo.size();
  std::optional<std::optional<std::string>> prefix;  // computed on first need
  const auto res = analysis::find_vo_level(
      [&](double V) {
        if (const long* n = memo.find(V)) return *n;
        if (!prefix) prefix = print_prefix(o, base, v.print, seed);
        const long n = print_line(o, base, v.print, V, seed, 0.0, *prefix ? &**prefix : nullptr).printed;
        memo.add(V, n);
        return n;
      },
      search_options(v));
  json trace = json::array();
  for (auto& [V, n] : res.trace) trace.push_back({V, n});
  return json{{"found", res.found}, {"vo_V", res.vo_V}, {"trace_V_printed", trace}, {"lines_resumed", resumed}};
}
}  // namespace

json vo_level(const ExperimentOptions& o, const VoOptions& v) {
  check(v);
  // reject a bad configuration or line before any run starts (exit 2, not failed points)
  reject_fixed_sets(o, "vo-level", print_fixed_keys(v.print, true));
  const nip::NipConfig base = base_config(o);
  print_config(base, v.print, 1.0, std::nullopt);
  const auto sum = ensemble::run([&](std::size_t i, std::uint64_t seed) { return run_seed_scan(o, v, base, i, seed); },
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
