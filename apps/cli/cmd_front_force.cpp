// `nipdem experiment front-force`: net y-force on a front particle (electric towards the drum,
// magnetic towards the roller) vs x and distance l from the drum, thesis §2.5.4, figs. 2.23-2.25.
// See src/nipdem/experiments/front_force.hpp.
#include <fmt/format.h>
#include <memory>

#include "nipdem/experiments/front_force.hpp"
#include "registry.hpp"

namespace {

struct Opts {
  nipdem::experiments::ExperimentOptions e;
  nipdem::experiments::FrontForceOptions f;
  std::string l_list, out;
  bool json = false;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* g = nipdem::cli::group(app, "experiment");
  auto* sub = g->add_subcommand("front-force", "Net y-force on a d95/2 front particle vs x and drum distance l (§2.5.4, figs. 2.24-2.25)");
  auto c = std::make_shared<Opts>();
  sub->add_option("--preset", c->e.preset, "black or color")->capture_default_str();
  sub->add_option("--config", c->e.config, "a config file instead of a preset");
  sub->add_option("--set", c->e.sets, "override a config key (repeatable; not geometry.gap_m: use --gap)");
  sub->add_option("--gap", c->f.gap_m, "gap w_h [m] (default: 240 um, the largest of the fig. 5.3 range)")->capture_default_str();
  sub->add_option("--voltage", c->f.voltage_V, "print voltage [V] (0: the config's [print], else 40 V, §2.5.1)")->capture_default_str();
  sub->add_option("--l", c->l_list, "distances from the drum [m], comma-separated (default 2e-6,...,12e-6)");
  sub->add_option("--x-min", c->f.x_min_m, "[m]")->capture_default_str();
  sub->add_option("--x-max", c->f.x_max_m, "[m]")->capture_default_str();
  sub->add_option("--dx", c->f.dx_m, "x step [m]")->capture_default_str();
  sub->add_option("--front-x-min", c->f.front_x_min_m, "front region start [m] (§2.5.4: -300 um)")->capture_default_str();
  sub->add_option("--front-x-max", c->f.front_x_max_m, "front region end [m] (§2.5.4: 0)")->capture_default_str();
  sub->add_option("--out", c->out, "output folder (default runs/front_force)");
  sub->add_flag("--json", c->json, "print one JSON object on stdout");
  sub->callback([c] {
    if (!c->l_list.empty()) c->f.l_m = nipdem::cli::parse_number_list(c->l_list, "experiment front-force", "--l");
    c->e.out = c->out.empty() ? "runs/front_force" : c->out;
    const auto j = nipdem::experiments::front_force(c->e, c->f);
    auto um = [&](const char* k) { return j[k].is_null() ? std::string("none (net force to the drum at 100 um)") : fmt::format("{:.3g} um", 1e6 * j[k].get<double>()); };
    nipdem::cli::finish_report(j, c->e.out, "front_force", c->json,
                               fmt::format("front force (§2.5.4): R = {:.3g} um, V = {:g} V, gap {:g} um\n"
                                           "  net force to the roller everywhere in the front region beyond l = {} (exact), {} (eq. 2.5.31 as printed); d50 = {:.3g} um\n",
                                           1e6 * j["radius_m"].get<double>(), j["voltage_V"].get<double>(),
                                           1e6 * c->f.gap_m, um("l_cross_max_exact_m"), um("l_cross_max_printed_m"),
                                           1e6 * j["d50_m"].get<double>()));
  });
});

}  // namespace
