#include "nipdem/nip/run_driver.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/core/wait_policy.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/progress.hpp"
#include "nipdem/io/vtk.hpp"
#include "nipdem/version.hpp"

namespace nipdem::nip {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {
const char* exit_name(Exit e) { return e == Exit::developed ? "developed" : e == Exit::returned ? "returned" : "lost"; }

std::string removals_csv(const NipRun& run) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& e : run.removals())
    rows.push_back({fmt::format("{:.9g}", e.time), exit_name(e.where), fmt::format("{:.9g}", e.x), fmt::format("{:.9g}", e.y),
                    fmt::format("{:.6g}", e.size), fmt::format("{}", e.id)});
  return io::format_csv_cells({"time_s", "exit", "x_m", "y_m", "diameter_m", "body_id"}, rows);
}

// timeseries.csv: one row per snapshot (it grows row by row and is cut back on resume).
const std::vector<std::string> kSeriesColumns = {"time_s", "bodies", "discs", "inserted", "developed", "returned", "lost", "contacts",
                                                 "kinetic_energy_J", "drum_voltage_V", "printable", "charged_over_1V", "max_voltage_V"};
const std::vector<std::string> kSeriesFormats = {"{:.9g}", "{:.0f}", "{:.0f}", "{:.0f}", "{:.0f}", "{:.0f}", "{:.0f}", "{:.0f}",
                                                 "{:.6g}", "{:g}", "{:.0f}", "{:.0f}", "{:.4g}"};
// Temp files "<name>.tmp.<pid>" of a writer that no longer runs (killed between the write and
// the rename of write_file_atomic): removed, so a killed run leaves nothing behind after the next.
void remove_stale_temp_files(const fs::path& out) {
  for (const fs::path& dir : {out, out / "particles"}) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) continue;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      const std::string name = e.path().filename().string();
      const auto at = name.rfind(".tmp.");
      if (at == std::string::npos || !e.is_regular_file(ec)) continue;
      const std::string pid = name.substr(at + 5);
      if (pid.empty() || pid.size() > 9 || pid.find_first_not_of("0123456789") != std::string::npos) continue;
      if (std::stol(pid) == static_cast<long>(::getpid()) || fs::exists("/proc/" + pid, ec)) continue;  // a live writer
      fs::remove(e.path(), ec);
    }
  }
}
}  // namespace

json run_nip(const NipConfig& cfg, const fs::path& out, const RunOptions& opt_in) {
  RunOptions opt = opt_in;
  if (fs::exists(out) && !fs::is_directory(out)) throw InputError(out.string() + ": --out names a file, not a folder");
  {
    std::error_code ec;
    fs::create_directories(out, ec);
    if (ec) throw InputError(out.string() + ": --out folder cannot be created (" + ec.message() + ")");
  }
  remove_stale_temp_files(out);
  const fs::path ckpt = out / "checkpoint.bin";
  // A run killed before its first checkpoint has nothing worth keeping: --resume starts it
  // again from t = 0, and so does a plain run (issue 21). Results (a summary or a checkpoint)
  // are never overwritten without --force.
  const bool has_results = fs::exists(out / "summary.json") || fs::exists(ckpt);
  if (opt.resume) {
    if (!fs::exists(ckpt)) {
      if (fs::exists(out / "summary.json"))
        throw InputError(ckpt.string() + ": no checkpoint to resume from, but the folder holds a finished run's summary.json");
      std::fprintf(stderr, "nipdem run: %s: no checkpoint yet (the run stopped before its first one): starting from t = 0\n",
                   out.string().c_str());
      opt.resume = false;
    }
  } else if (!opt.force && has_results) {
    throw InputError(out.string() + ": already holds results of a run; use --resume to continue it, --force to overwrite, or another --out");
  }
  NipRun run(cfg);
  std::vector<std::pair<double, std::string>> frames;
  std::string series = io::format_csv_header(kSeriesColumns);
  const double dt = run.time_step().dt;
  if (opt.resume) {
    run.restore(io::read_file(ckpt, io::kMaxCheckpointBytes), ckpt.string());
    // An end time before the checkpoint is an error; one at the checkpoint's time only finishes
    // the outputs of a run killed after its last checkpoint (no summary yet), else nothing is left.
    const double tc = run.sim().time();
    if (cfg.end_time < tc - 0.5 * dt || (cfg.end_time < tc + 0.5 * dt && fs::exists(out / "summary.json")))
      throw_input(cfg.file, "run.end_time_s", fmt::format("{:g}", cfg.end_time),
                  fmt::format("the checkpoint {} is at t = {:g} s{}: nothing left to run", ckpt.string(), tc,
                              cfg.end_time < tc - 0.5 * dt ? "" : " and the run's summary.json exists"),
                  fmt::format("> {:g} s (the checkpoint's time plus half a step)", tc + 0.5 * dt));
    // A run writes timeseries.csv (and, with snapshots, frames.json) at t = 0, before its first
    // checkpoint: without them a resume would start the files afresh, losing the rows before the
    // checkpoint (and writing snapshots over the first ones). Refused, naming the file.
    for (const char* name : {"timeseries.csv", "frames.json"}) {
      if (std::string_view(name) == "frames.json" && !cfg.vtk) continue;
      if (!fs::exists(out / name))
        throw InputError(fmt::format("{}: missing: the run wrote it before its checkpoint (t = {:g} s); resuming without it "
                                     "would lose what it held. Put it back, or start the run again without --resume",
                                     (out / name).string(), run.sim().time()));
    }
    if (fs::exists(out / "frames.json")) {
      const fs::path fj = out / "frames.json";
      try {
        for (auto& f : json::parse(io::read_file(fj))) frames.emplace_back(f.at(0).get<double>(), f.at(1).get<std::string>());
      } catch (const json::exception& e) {
        throw InputError(fj.string() + ": not a frame list of a nipdem run (" + e.what() + ")");
      }
    }
    if (fs::exists(out / "timeseries.csv")) series = io::read_file(out / "timeseries.csv");
    // Drop snapshots and rows written after the checkpoint (they will be written again). Rows
    // carry time to 9 digits, so "after" means more than half a step later: the row at the
    // checkpoint's own time is kept whichever way its printed time rounded.
    const double t_keep = run.sim().time() + 0.5 * dt;
    while (!frames.empty() && frames.back().first > t_keep) frames.pop_back();
    std::string kept;
    std::size_t pos = 0;
    int line = 0;
    while (pos < series.size()) {
      const auto nl = series.find('\n', pos);
      const std::string row = series.substr(pos, nl - pos + 1);
      if (line++ > 0) {
        char* end = nullptr;
        const double t_row = std::strtod(row.c_str(), &end);
        if (end == row.c_str() || *end != ',' || !std::isfinite(t_row))
          throw InputError(fmt::format("{}:{}: row does not start with a time (damaged file?)", (out / "timeseries.csv").string(), line));
        if (t_row > t_keep) break;  // rows are in time order
      }
      kept += row;
      pos = nl == std::string::npos ? series.size() : nl + 1;
    }
    series = kept;
  }
  io::write_file_atomic(out / "config.toml", cfg.resolved_toml);

  auto snapshot = [&] {
    auto& sim = run.sim();
    if (cfg.vtk) {
      const int idx = static_cast<int>(frames.size());
      sim.update_adhesive_parts();  // (the frame's adhesive part; step() does not keep it)
      frames.emplace_back(sim.time(), io::write_vtp(out, idx, sim));
      io::write_pvd(out, frames);
      json fj = json::array();
      for (auto& [t, f] : frames) fj.push_back({t, f});
      io::write_file_atomic(out / "frames.json", fj.dump());
    }
    double vd = 0, vmax = 0;
    int printable = 0, charged = 0;
    if (const auto* e = run.electric()) {
      vd = e->drum_voltage();
      printable = e->printable_count();
      for (double u : e->voltage()) { vmax = std::max(vmax, std::fabs(u)); charged += std::fabs(u) > 1.0; }
    }
    auto count = [](auto n) { return static_cast<double>(n); };
    series += io::format_csv_row({sim.time(), count(sim.bodies().x.size()), count(sim.discs().x.size()), count(run.inserted()),
                                  count(run.removed(Exit::developed)), count(run.removed(Exit::returned)), count(run.removed(Exit::lost)),
                                  count(sim.contacts()), sim.energy().kinetic, vd, count(printable), count(charged), vmax},
                                 kSeriesFormats);
    io::write_file_atomic(out / "timeseries.csv", series);
  };
  auto save_checkpoint = [&] {
    io::write_file_atomic(ckpt, run.checkpoint());
    io::write_file_atomic(out / "removals.csv", removals_csv(run));
    if (cfg.electric.enabled) {
      std::vector<std::vector<double>> cov;
      for (const auto& b : run.coverage(0.25 * cfg.size.d50))
        cov.push_back({b.s0, b.s1, b.covered ? 1.0 : 0.0, static_cast<double>(b.particles), cfg.electric.pattern.voltage_at(0.5 * (b.s0 + b.s1))});
      io::write_csv(out / "coverage.csv", {"s_begin_m", "s_end_m", "coverage", "particles", "track_voltage_V"}, cov,
                    {"{:.9g}", "{:.9g}", "{:.0f}", "{:.0f}", "{:g}"});
    }
  };

  const std::int64_t step0 = run.sim().step_count();
  std::int64_t disc_steps = 0;
  io::Progress progress("nipdem run", run.sim().time(), cfg.end_time, step0);
  if (!opt.resume) {
    run.sim().compute_forces();
    snapshot();
  }
  auto next_multiple = [&](double interval) {
    // time is a sum of dt, so it lands within dt/2 of a multiple, on either side: round
    return (std::round(run.sim().time() / interval) + 1.0) * interval;
  };
  double next_out = next_multiple(cfg.output_interval);
  double next_ck = next_multiple(cfg.checkpoint_interval);
  while (run.sim().time() < cfg.end_time - 0.5 * dt) {
    const double target = std::min({next_out, next_ck, cfg.end_time});
    run.advance_to(target, [&] {
      disc_steps += static_cast<std::int64_t>(run.sim().discs().x.size()) * cfg.insert_interval;
      if (opt.progress)
        progress.update(run.sim().time(), run.sim().step_count(),
                        fmt::format("particles {}  developed {}  returned {}", run.sim().bodies().x.size(),
                                    run.removed(Exit::developed), run.removed(Exit::returned)));
    });
    if (run.sim().time() >= next_out - 0.5 * dt) { snapshot(); next_out = next_multiple(cfg.output_interval); }
    if (run.sim().time() >= next_ck - 0.5 * dt) { save_checkpoint(); next_ck = next_multiple(cfg.checkpoint_interval); }
  }
  save_checkpoint();
  const double wall = progress.elapsed_s();
  const std::int64_t steps = run.sim().step_count() - step0;
  if (opt.progress) progress.finish(run.sim().time(), run.sim().step_count());
  const double sim_ms = static_cast<double>(steps) * dt * 1e3;
  json coll = json::object();
  for (const auto& r : collision_report(cfg))
    coll[r.name] = {{"k_N_per_m", r.k}, {"gamma_Ns_per_m", r.gamma}, {"ks_N_per_m", r.ks}, {"restitution", r.restitution},
                    {"contact_time_s", r.contact_time}, {"dt_max_s", r.dt_max_newmark}};
  json summary = {
      {"nipdem_version", kVersion},
      {"git_hash", kGitHash},
      {"config_file", cfg.file},
      {"seed", cfg.seed},
      {"time_s", run.sim().time()},
      {"steps", run.sim().step_count()},
      {"dt_s", dt},
      {"dt_bound_s", run.time_step().bound},
      {"dt_limited_by", run.time_step().limiting},
      {"integrator", cfg.integrator == engine::Integrator::velocity_verlet ? "velocity_verlet" : "newmark_explicit"},
      {"threads", cfg.threads},
      {"omp_waits", wait_policy()},  // how OpenMP threads waited (core/wait_policy.hpp)
      // how many of them ran the engine's steps at the end (measured choice, engine/team_tuner.hpp;
      // speed only: results do not depend on it) and how often the choice changed
      {"threads_running", run.sim().team_tuner().team()},
      {"thread_choice_switches", run.sim().team_tuner().switches()},
      // how often this session (this process) built the contact and dipole pair lists (speed only: run.neighbor_skin_d50,
      // magnet.dipole_skin_m; a change of the body set at an exchange rebuilds both)
      {"neighbor_list_builds_this_session", run.sim().neighbor_list().builds()},
      {"dipole_list_builds_this_session", run.magnet() ? run.magnet()->dipole_pairs().builds() : 0},
      // and how often the pair kernel took its per-step sublist of the contact list (engine/simulation.hpp)
      {"pair_sublist_builds_this_session", run.sim().pair_sublist_builds()},
      {"particles_in_window", run.sim().bodies().x.size()},
      {"discs_in_window", run.sim().discs().x.size()},
      {"inserted", run.inserted()},
      {"inserted_in_roller_pits", run.inserted_on_roller()},
      {"developed", run.removed(Exit::developed)},
      {"returned", run.removed(Exit::returned)},
      {"lost", run.removed(Exit::lost)},
      {"wall_time_s", wall},
      {"steps_this_session", steps},
      {"disc_steps_per_s", wall > 0 ? disc_steps / wall : 0.0},
      {"wall_s_per_simulated_ms", sim_ms > 0 ? wall / sim_ms : 0.0},
      {"collision", coll},
      {"geometry", run.describe()},
      {"frames", frames.size()},
      {"resumed", opt.resume},
      {"electric_enabled", cfg.electric.enabled},
      {"printed", cfg.electric.enabled ? run.removed(Exit::developed) : 0},
  };
  io::write_file_atomic(out / "summary.json", summary.dump(2));
  return summary;
}

}  // namespace nipdem::nip
