// `nipdem params collision --preset NAME [--config FILE] [--set K=V]... --json`
#include <nlohmann/json.hpp>

#include "nipdem/core/error.hpp"
#include "nipdem/nip/nip_config.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "registry.hpp"

namespace {
struct Opts {
  std::string preset, config;
  std::vector<std::string> sets;
  bool json = false;
};
nipdem::cli::Register reg([](CLI::App& app) {
  auto* g = nipdem::cli::group(app, "params");
  auto o = std::make_shared<Opts>();
  auto* sub = g->add_subcommand("collision", "Spring-dashpot parameters per collision type (Table 4.2, eqs. 2.2.7, 4.2.25)");
  sub->add_option("--preset", o->preset, "black or color");
  sub->add_option("--config", o->config, "a config file instead of a preset");
  sub->add_option("--set", o->sets, "override a config key (repeatable)");
  sub->add_flag("--json", o->json, "print one JSON object");
  sub->callback([o] {
    using namespace nipdem::nip;
    if (o->preset.empty() == o->config.empty()) throw nipdem::InputError("params collision: give exactly one of --preset NAME or --config FILE");
    const NipConfig cfg = o->config.empty() ? parse_nip_config(preset_text(o->preset), "preset:" + o->preset, o->sets)
                                            : load_nip_config(o->config, o->sets);
    const auto ts = choose_time_step(cfg);
    if (o->json) { nipdem::cli::print_json(collision_json(cfg).dump()); return; }
    std::printf("%-14s %10s %12s %10s %6s %12s %14s %14s\n", "type", "k [N/m]", "gamma [Ns/m]", "ks [N/m]", "e", "t_n [s]",
                "dt_max NM [s]", "dt_max VV [s]");
    for (const auto& r : collision_report(cfg))
      std::printf("%-14s %10.4g %12.4g %10.4g %6.3g %12.4g %14.4g %14.4g\n", r.name.c_str(), r.k, r.gamma, r.ks, r.restitution,
                  r.contact_time, r.dt_max_newmark, r.dt_max_verlet);
    std::printf("time step used: %.4g s (bound %.4g s for the configured integrator, set by %s of the smallest particle)\n", ts.dt,
                ts.bound, ts.limiting.c_str());
  });
});
}  // namespace
