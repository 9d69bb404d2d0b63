// `nipdem run CONFIG.toml [--out DIR] [--set KEY=VALUE]... [--resume] [--force] [--json]`
#include <nlohmann/json.hpp>

#include "nipdem/nip/run_driver.hpp"
#include "registry.hpp"

namespace {
struct Opts {
  std::string config, out = "runs/out";
  std::vector<std::string> sets;
  bool resume = false, force = false, json = false, quiet = false;
};
nipdem::cli::Register reg([](CLI::App& app) {
  auto o = std::make_shared<Opts>();
  auto* sub = app.add_subcommand("run", "Run the nip simulation a TOML config describes");
  sub->add_option("config", o->config, "configuration file (TOML; see `nipdem presets show black`)")->required();
  sub->add_option("--out", o->out, "output folder (summary.json, particles.pvd, checkpoint.bin, ...)")->capture_default_str();
  sub->add_option("--set", o->sets, "override a config key, e.g. --set run.end_time_s=1e-3 (repeatable)");
  sub->add_flag("--resume", o->resume, "continue from OUT/checkpoint.bin (same config and --set options)");
  sub->add_flag("--force", o->force, "write into an output folder that already holds results");
  sub->add_flag("--json", o->json, "print summary.json on stdout");
  sub->add_flag("--quiet", o->quiet, "no progress on stderr");
  sub->callback([o] {
    const auto cfg = nipdem::nip::load_nip_config(o->config, o->sets);
    nipdem::nip::RunOptions ro{o->resume, o->force, !o->quiet};
    const auto summary = nipdem::nip::run_nip(cfg, o->out, ro);
    if (o->json) nipdem::cli::print_json(summary.dump());
    else std::fprintf(stderr, "nipdem run: %s  (developed %lld, returned %lld, lost %lld, %.1f s wall)\n", o->out.c_str(),
                      summary["developed"].get<long long>(), summary["returned"].get<long long>(), summary["lost"].get<long long>(),
                      summary["wall_time_s"].get<double>());
  });
});
}  // namespace
