// `nipdem experiment front-position|reduction|vo-level|edge-sharpness` (CLI.md), and
// `nipdem calibrate cohesion` (r fitted to a reduction speed over reduction experiments) and
// `nipdem calibrate cohesion-joint` (one r for several units from their cohesion reports).
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/calibrate_cohesion.hpp"
#include "nipdem/experiments/ensemble.hpp"
#include "nipdem/experiments/edge_sharpness.hpp"
#include "nipdem/experiments/front_position.hpp"
#include "nipdem/experiments/reduction.hpp"
#include "nipdem/experiments/vo_level.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "registry.hpp"

namespace {
using namespace nipdem::experiments;
using namespace nipdem::nip;

struct Common {
  ExperimentOptions o;
  std::string out = "";
  bool json = false, quiet = false;
};

std::vector<double> parse_list(const std::string& text, const std::string& key) {
  return nipdem::cli::parse_number_list(text, "experiment", key);
}

void add_common(CLI::App* sub, const std::shared_ptr<Common>& c, const std::string& name, bool mpi = true) {
  sub->add_option("--preset", c->o.preset, "black or color")->capture_default_str();
  sub->add_option("--config", c->o.config, "a config file instead of a preset");
  sub->add_option("--set", c->o.sets, "override a config key for every run (repeatable)");
  sub->add_option("--seed", c->o.seed, "base seed (same seed, same result)")->capture_default_str();
  sub->add_option("--jobs", c->o.jobs, "threads running points/realizations in parallel")->capture_default_str()->check(CLI::Range(1, 256));
  if (mpi) sub->add_flag("--mpi", c->o.mpi, "spread points over MPI ranks (under mpirun); results gathered on rank 0");
  sub->add_option("--out", c->out, "output folder (default runs/" + name + ")");
  sub->add_flag("--json", c->json, "print one JSON object on stdout");
  sub->add_flag("--quiet", c->quiet, "no progress on stderr");
}

void finish(const std::shared_ptr<Common>& c, const std::string& name, const std::function<nlohmann::json()>& run) {
  if (c->out.empty()) c->out = "runs/" + name;
  c->o.out = c->out;
  c->o.progress = !c->quiet;
  std::unique_ptr<nipdem::ensemble::MpiSession> mpi;
  if (c->o.mpi) mpi = std::make_unique<nipdem::ensemble::MpiSession>();
  const nlohmann::json j = run();
  if (mpi && mpi->rank() != 0) return;
  nipdem::io::write_file_atomic(c->o.out / (name + ".json"), j.dump(2));
  if (c->json) nipdem::cli::print_json(j.dump());
  else std::fprintf(stderr, "%s: results in %s\n", name.c_str(), c->o.out.c_str());
  if (j.contains("bracketed") && !j["bracketed"].get<bool>())
    throw std::runtime_error("the target was not bracketed (" + j.value("hint", std::string()) + "); see " + (c->o.out / (name + ".json")).string());
  if (j.value("n_failed", 0) > 0) throw std::runtime_error(std::to_string(j["n_failed"].get<int>()) + " point(s) failed; see \"failed\" in " + (c->o.out / (name + ".json")).string());
}

nipdem::cli::Register reg([](CLI::App& app) {
  auto* g = nipdem::cli::group(app, "experiment");
  {
    auto c = std::make_shared<Common>();
    auto gaps = std::make_shared<std::string>("150e-6");
    auto speeds = std::make_shared<std::string>();
    auto f = std::make_shared<FrontPositionOptions>();
    auto* sub = g->add_subcommand("front-position", "Clean-state front position vs gap and sleeve speed (§5.1)");
    add_common(sub, c, "front-position");
    sub->add_option("--gap", *gaps, "gaps w_h [m], comma-separated")->capture_default_str();
    sub->add_option("--sleeve-speed", *speeds, "sleeve surface speeds [m/min], comma-separated (default: the preset's)");
    sub->add_option("--max-time", f->max_time_s, "give up after this simulated time [s]")->capture_default_str();
    sub->add_option("--min-time", f->min_time_s, "earliest time a run may be called steady [s]")->capture_default_str();
    sub->callback([=] {
      f->gaps_m = parse_list(*gaps, "--gap");
      if (!speeds->empty()) f->sleeve_speeds_m_per_min = parse_list(*speeds, "--sleeve-speed");
      finish(c, "front-position", [&] { return front_position(c->o, *f); });
    });
  }
  {
    auto c = std::make_shared<Common>();
    auto rs = std::make_shared<std::string>("1");
    auto r = std::make_shared<ReductionOptions>();
    auto* sub = g->add_subcommand("reduction", "Reduction experiment: removal by the sleeve vs r = F_coh/F_adh (§4.6)");
    add_common(sub, c, "reduction");
    sub->add_option("--r", *rs, "cohesion ratios r, comma-separated")->capture_default_str();
    sub->add_option("--time", r->time_s, "observation time [s] (thesis: 0.1)")->capture_default_str();
    sub->add_option("--pile-width", r->pile_width_m, "initial assembly width [m]")->capture_default_str();
    sub->add_option("--pile-height", r->pile_height_m, "initial assembly height [m]")->capture_default_str();
    sub->add_option("--pits", r->pits, "sleeve pits entering upstream: empty (clean sleeve), filled, or preset")->capture_default_str();
    sub->callback([=] {
      r->cohesion_ratios = parse_list(*rs, "--r");
      finish(c, "reduction", [&] { return reduction(c->o, *r); });
    });
  }
  {
    auto c = std::make_shared<Common>();
    auto v = std::make_shared<VoOptions>();
    auto* sub = g->add_subcommand("vo-level", "Lowest drum voltage that prints (§5.2), statistics over seeds");
    add_common(sub, c, "vo-level");
    sub->add_option("--step", v->step_V, "voltage step [V]")->capture_default_str();
    sub->add_option("--coarse-step", v->coarse_step_V, "0, or a multiple of --step: step coarsely, then refine below the first printing voltage (docs/analysis.md)")->capture_default_str();
    sub->add_option("--v0", v->v0_V, "first voltage [V]")->capture_default_str();
    sub->add_option("--vmax", v->v_max_V, "give up above this voltage [V]")->capture_default_str();
    sub->add_option("--seeds", v->seeds, "independent realizations")->capture_default_str();
    sub->add_option("--line-length", v->print.line_length_m, "printed line length on the drum [m]")->capture_default_str();
    sub->add_option("--line-start", v->print.line_start_m, "drum position where the line starts [m] (s = 0 at the nip at t = 0)")->capture_default_str();
    sub->add_option("--extra-time", v->print.extra_time_s, "run this long after the line's end has left the window [s]")->capture_default_str()->check(CLI::Range(0.0, 1.0));
    sub->callback([=] { finish(c, "vo-level", [&] { return vo_level(c->o, *v); }); });
  }
  {
    auto c = std::make_shared<Common>();
    auto e = std::make_shared<EdgeOptions>();
    auto* sub = g->add_subcommand("edge-sharpness", "Edge widths (10-90 %) of printed lines over realizations (§1.4, §5.3)");
    add_common(sub, c, "edge-sharpness");
    sub->add_option("--realizations", e->realizations, "printed lines")->capture_default_str();
    sub->add_option("--line-length", e->print.line_length_m, "printed line length on the drum [m]")->capture_default_str();
    sub->add_option("--line-start", e->print.line_start_m, "drum position where the line starts [m] (s = 0 at the nip at t = 0)")->capture_default_str();
    sub->add_option("--extra-time", e->print.extra_time_s, "run this long after the line's end has left the window [s] (printing goes on after the track is off)")->capture_default_str()->check(CLI::Range(0.0, 1.0));
    sub->add_option("--margin", e->margin_m, "analysis range beyond each end of the line [m]; each run lasts until line end + margin has left the window")->capture_default_str();
    sub->add_option("--bootstrap", e->bootstrap, "bootstrap resamples")->capture_default_str();
    sub->callback([=] { finish(c, "edge-sharpness", [&] { return edge_sharpness(c->o, *e); }); });
  }
  {
    auto c = std::make_shared<Common>();
    auto k = std::make_shared<nipdem::calibrate::CohesionOptions>();
    auto* cal = nipdem::cli::group(app, "calibrate");
    auto* sub = cal->add_subcommand("cohesion", "Fit r = F_coh/F_adh to a measured reduction speed (Table 4.3) over reduction runs (§4.6)");
    add_common(sub, c, "cohesion", /*mpi=*/false);
    sub->add_option("--target-speed", k->target_speed_m_per_s, "measured reduction speed [m/s] (Table 4.3: black 7.6e-4, colour 2.5e-4)")->required();
    sub->add_option("--r-min", k->r_min, "lower end of the first r range")->capture_default_str();
    sub->add_option("--r-max", k->r_max, "upper end of the first r range")->capture_default_str();
    sub->add_option("--points", k->points, "reduction runs per round (log-spaced in r)")->capture_default_str();
    sub->add_option("--rounds", k->rounds, "rounds: the first over [r-min, r-max], then inside the bracket")->capture_default_str();
    sub->add_option("--time", k->reduction.time_s, "observation time per run [s] (thesis: 0.1)")->capture_default_str();
    sub->add_option("--pile-width", k->reduction.pile_width_m, "initial assembly width [m]")->capture_default_str();
    sub->add_option("--pile-height", k->reduction.pile_height_m, "initial assembly height [m]")->capture_default_str();
    sub->add_option("--pits", k->reduction.pits, "sleeve pits entering upstream: empty (clean sleeve), filled, or preset")->capture_default_str();
    auto sweep = std::make_shared<std::string>();
    auto range = std::make_shared<std::string>();
    sub->add_option("--from-sweep", *sweep, "no runs: fit r to the removed counts of finished `experiment reduction` JSONs (comma-separated files of one preset and model are pooled; seeds = repeated r; docs/reduction.md)");
    sub->add_option("--target-range", *range, "with --from-sweep: LO:HI of the measured speed [m/s] (Table 4.3's three experiments: black 7.4e-4:7.8e-4, colour 2.0e-4:2.9e-4)");
    sub->callback([=] {
      if (sweep->empty()) {
        if (!range->empty()) nipdem::throw_input("calibrate cohesion", "--target-range", *range, "only with --from-sweep");
        finish(c, "cohesion", [&] { return nipdem::calibrate::calibrate_cohesion(c->o, *k); });
        return;
      }
      nipdem::calibrate::CountTarget t;
      t.speed = t.speed_lo = t.speed_hi = k->target_speed_m_per_s;
      t.time_s = k->reduction.time_s;
      t.pile_width_m = k->reduction.pile_width_m;
      if (!range->empty()) {
        const auto colon = range->find(':');
        std::vector<double> v;
        if (colon != std::string::npos) v = parse_list(range->substr(0, colon) + "," + range->substr(colon + 1), "--target-range");
        if (v.size() != 2) nipdem::throw_input("calibrate cohesion", "--target-range", *range, "expected LO:HI in m/s");
        t.speed_lo = v[0];
        t.speed_hi = v[1];
      }
      finish(c, "cohesion", [&] { return nipdem::calibrate::calibrate_cohesion_from_sweep(c->o, *sweep, t); });
    });
  }
  {
    auto c = std::make_shared<Common>();
    auto reports = std::make_shared<std::string>();
    auto* cal = nipdem::cli::group(app, "calibrate");
    auto* sub = cal->add_subcommand("cohesion-joint", "One r for several units: joint chi2 over `calibrate cohesion --from-sweep` reports (§4.6; docs/reduction.md)");
    sub->add_option("REPORTS", *reports, "comma-separated cohesion reports (JSON), one per unit; a unit is named by its file's stem")->required();
    sub->add_option("--out", c->out, "output folder (default runs/cohesion-joint)");
    sub->add_flag("--json", c->json, "print one JSON object on stdout");
    sub->add_flag("--quiet", c->quiet, "no progress on stderr");
    sub->callback([=] { finish(c, "cohesion-joint", [&] { return nipdem::calibrate::calibrate_cohesion_joint(c->o, *reports); }); });
  }
});
}  // namespace
