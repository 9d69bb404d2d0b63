#include "nipdem/experiments/experiment.hpp"

#include <algorithm>

#include <cstdio>
#include <sstream>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/toml_reader.hpp"
#include "nipdem/version.hpp"

namespace nipdem::experiments {

using nlohmann::json;

nip::NipConfig base_config(const ExperimentOptions& o) {
  if (!o.config.empty()) return nip::read_nip_config(io::read_file(o.config), o.config, o.sets);
  return nip::read_nip_config(nip::preset_text(o.preset), "preset:" + o.preset, o.sets);
}

namespace {
// "key=value" as the messages show it (numbers as %.10g, strings quoted as in TOML).
std::string shown(const FixedKey& f) {
  struct V {
    std::string operator()(std::monostate) const { return "*"; }
    std::string operator()(double v) const { return fmt::format("{:.10g}", v); }
    std::string operator()(bool v) const { return v ? "true" : "false"; }
    std::string operator()(const std::string& v) const { return "\"" + v + "\""; }
  };
  return f.key + "=" + (f.shown.empty() ? std::visit(V{}, f.value) : f.shown);
}
bool varies(const FixedKey& f) { return std::holds_alternative<std::monostate>(f.value); }
}  // namespace

void reject_fixed_sets(const ExperimentOptions& o, const std::string& experiment, const std::vector<FixedKey>& fixed, bool note_config) {
  auto key_of = [](const std::string& a) { return a.substr(0, a.find('=')); };
  for (const auto& f : fixed) {
    for (const auto& u : o.sets) {
      if (key_of(u) != f.key) continue;
      throw_input("experiment " + experiment, "--set " + f.key, u.substr(std::min(u.size(), f.key.size() + 1)),
                  "this experiment sets the key itself (" + (varies(f) ? f.key + ", a new value for every run" : shown(f)) +
                      ") and would replace the value",
                  !f.use_instead.empty() ? "use " + f.use_instead + " instead" : "leave it out");
    }
  }
  // A key the user could set with an option is replaced in the configuration file too: say so
  // (once per experiment), not silently. Keys that define the experiment (the reduction's
  // 4 mm gap, no inflow, no VTK) are replaced without a note.
  if (!note_config) return;
  try {
    const std::string text = o.config.empty() ? nip::preset_text(o.preset) : io::read_file(o.config);
    const toml::table root = io::parse_toml(text, o.config.empty() ? "preset:" + o.preset : o.config);
    for (const auto& f : fixed) {
      if (varies(f) || f.use_instead.empty()) continue;  // varies per run, or defines the experiment
      const toml::node_view<const toml::node> have = root.at_path(f.key);
      if (!have) continue;
      const auto a = have.value<double>();
      bool same = false;
      if (const double* v = std::get_if<double>(&f.value)) same = a && *a == *v;
      else if (const std::string* v = std::get_if<std::string>(&f.value)) same = have.value<std::string>() == *v;
      else if (const bool* v = std::get_if<bool>(&f.value)) same = have.value<bool>() == *v;
      if (same) continue;
      std::ostringstream sa;
      sa << have;
      std::fprintf(stderr, "nipdem: note: experiment %s sets %s (%s); the configuration's %s = %s is not used\n", experiment.c_str(),
                   shown(f).c_str(), f.use_instead.c_str(), f.key.c_str(), a ? fmt::format("{:g}", *a).c_str() : sa.str().c_str());
    }
  } catch (const InputError&) {
    // an unreadable configuration is reported by base_config with its own message
  }
}

ensemble::Options ensemble_options(const ExperimentOptions& o, std::size_t count, const std::string& sub) {
  ensemble::Options e;
  e.count = count;
  e.seed = o.seed;
  e.jobs = o.jobs;
  e.mpi = o.mpi;
  e.resume = o.resume;
  e.dir = o.out / sub;
  if (o.progress)
    e.progress = [sub](std::size_t done, std::size_t total) { std::fprintf(stderr, "%s: %zu/%zu done\n", sub.c_str(), done, total); };
  return e;
}

io::Progress run_progress(const ExperimentOptions& o, const std::string& label, double t_start, double t_end) {
  return io::Progress(label, t_start, t_end, 0, {.enabled = o.progress, .bar = false, .every_s = 60.0});
}

json failures(const ensemble::Summary& s) {
  json f = json::array();
  for (const auto& r : s.records) if (!r.ok) f.push_back({{"index", r.index}, {"seed", r.seed}, {"error", r.error}});
  return f;
}

json meta(const ExperimentOptions& o, const ensemble::Summary* sum) {
  json m{{"git_hash", kGitHash}, {"preset", o.config.empty() ? o.preset : ""}, {"config", o.config}, {"set", o.sets},
         {"seed", o.seed}, {"jobs", o.jobs}, {"mpi", o.mpi}};
  if (sum) {  // [{git_hash, realizations}] in order of first appearance
    json builds = json::array();
    for (const auto& r : sum->records) {
      const std::string h = r.git_hash.empty() ? "unrecorded" : r.git_hash;
      auto it = std::find_if(builds.begin(), builds.end(), [&](const json& b) { return b["git_hash"] == h; });
      if (it == builds.end()) builds.push_back({{"git_hash", h}, {"realizations", 1}});
      else (*it)["realizations"] = (*it)["realizations"].get<int>() + 1;
    }
    m["realization_builds"] = builds;
  }
  return m;
}

}  // namespace nipdem::experiments
