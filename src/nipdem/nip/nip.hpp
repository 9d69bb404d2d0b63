// A nip simulation: DI-drum and imaging roller (with line-piece roughness) around a window of
// the development nip, toner flowing in on the drum, particles removed and counted where they
// leave (thesis §2.1, §4.1, §5.1).
//
// Coordinates (docs/geometry.md): x along the process direction with the origin at the
// magnet edge on the imaging-roller surface, positive towards the supply roller; y from the
// roller surface towards the drum. The roller axis is at (nip_x, -R_roller), the drum axis at
// (nip_x, gap + R_drum). In the nip the drum surface moves towards -x (carrying developed
// toner out of the nip) and the sleeve towards +x (returning toner to the supply roller).
#pragma once
#include <cstdint>
#include <functional>
#include <istream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/core/rng.hpp"
#include "nipdem/engine/simulation.hpp"
#include "nipdem/nip/nip_config.hpp"
#include "nipdem/nip/nip_forces.hpp"

namespace nipdem::nip {

enum class Exit { developed = 0, returned = 1, lost = 2 };

struct RemovalEvent {
  double time;      // [s]
  Exit where;
  double x, y;      // centre of mass when removed [m]
  double size;      // volume-equivalent diameter [m]
  std::int64_t id;
};

class NipRun {
 public:
  explicit NipRun(NipConfig cfg);

  // Advances to time t_end, calling `on_step` every insert interval (for progress).
  void advance_to(double t_end, const std::function<void()>& on_interval = {});
  // One inflow/outflow pass (also done automatically every interval).
  void exchange();
  // Fills [x0, x1] between heights h0 and h1 above the roller surface with resting toner at
  // the given area fraction (the reduction experiment's assembly, §4.6). Returns the count.
  int fill_on_roller(double x0, double x1, double h0, double h1, double area_fraction);
  // Fills the roughness pits of the sleeve under [x_lo, x_hi] with toner moving with the
  // sleeve (random sequential addition, centres below the land level, until `max_failures`
  // consecutive attempts fail). Returns the count. No-op on a smooth roller.
  int fill_pits(double x_lo, double x_hi, int max_failures);
  // x of the bodies that belong to the assembly on the roller: centre of mass between
  // `min_height` and `max_height` above the roller's base circle [m] (front/back positions,
  // §4.6, §5.1). A min_height of about d50/2 leaves out the toner carried in filled pits.
  std::vector<double> assembly_x(double max_height, double min_height = -1.0) const;

  engine::Simulation& sim() { return *sim_; }
  const engine::Simulation& sim() const { return *sim_; }
  const NipConfig& config() const { return cfg_; }
  const TimeStep& time_step() const { return ts_; }
  std::int64_t inserted() const { return inserted_; }
  // Bodies brought in by the sleeve in its pits after the start (inflow.roller_pits = "filled").
  std::int64_t inserted_on_roller() const { return inserted_roller_; }
  std::int64_t removed(Exit e) const { return removed_[static_cast<int>(e)]; }
  const std::vector<RemovalEvent>& removals() const { return removals_; }
  // The electric force provider (null unless [electric] enabled).
  const ElectricForce* electric() const { return electric_.get(); }
  const MagnetForce* magnet() const { return magnet_.get(); }  // nullptr without a magnet
  // Position on the drum surface (arc length, s = 0 at the nip at t = 0, increasing with the
  // drum's travel) of a particle that left on the drum at time t and position x: the print
  // pattern's coordinate (§2.5.1).
  double drum_position(double t, double x) const { return cfg_.drum_speed * t + (x - cfg_.nip_x); }
  // Coverage along the drum from the developed particles: presence/absence per bin (§5.3).
  struct CoverageBin { double s0, s1; int particles; bool covered; };
  std::vector<CoverageBin> coverage(double bin_m) const;

  // Geometry helpers.
  Vec2 drum_centre() const;
  Vec2 roller_centre() const;
  double drum_surface_y(double x) const;    // y of the drum surface above x
  double roller_surface_y(double x) const;  // y of the base circle of the roller below x

  // Checkpoint of the whole run (engine + runner state) in its checksummed frame, and its
  // restore: every size, index and value is checked first; anything wrong throws InputError
  // "<where>: ..." (docs/reliability.md). After a throw the run must not be used.
  std::string checkpoint() const;
  void restore(const std::string& blob, const std::string& where = "checkpoint");
  // Restores a checkpoint of a run whose configuration differs from this one at most in
  // print.voltage_V and that was taken before the drum track first switches on. Until then
  // both runs see the off voltage and take the same steps, so one prefix serves every voltage
  // of a Vo-level scan (tested bitwise against an uninterrupted run). Throws InputError if the
  // configurations differ otherwise or the checkpoint's time is not before the first switch.
  void restore_before_print_switch(const std::string& blob, const std::string& where = "prefix checkpoint");
  // Time at which the drum track first switches away from its off voltage (inf: never).
  double first_print_switch_time() const;
  // Geometry and parameters for summary.json / rendering.
  nlohmann::json describe() const;

 private:
  // A toner drawn from the size distribution with a random orientation; extent = largest
  // member reach from the centre of mass [m].
  struct Draw { engine::BodySpec spec; double angle, extent; };
  Draw draw_toner();
  bool try_insert(double x_lo, double x_hi);
  // Insert one particle at random in x [x_lo, x_hi], height [h_lo, h_hi] above the roller.
  bool try_insert_on_roller(double x_lo, double x_hi, double h_lo, double h_hi);
  bool place(engine::BodySpec spec, Vec2 pos, double angle, Vec2 velocity, double omega);
  void prefill();
  // The checkpoint after its header (rng, counters, removals, engine).
  void restore_state(std::istream& in, const std::string& where);
  // Fills the pits of the whole window (start) or the pit(s) that entered through x_min
  // during the last inflow pass; returns the count.
  int fill_pits_entering(bool whole_window);

  NipConfig cfg_;
  TimeStep ts_;
  std::unique_ptr<engine::Simulation> sim_;
  Rng rng_;
  std::int64_t inserted_ = 0;
  std::int64_t inserted_roller_ = 0;
  std::int64_t removed_[3] = {0, 0, 0};
  double area_debt_ = 0.0;  // toner area still to insert [m^2]
  std::vector<RemovalEvent> removals_;
  const ClusterTemplate* tmpl_ = nullptr;
  std::shared_ptr<ElectricForce> electric_;
  std::shared_ptr<MagnetForce> magnet_;
};

// Where a toner centre can go in the nip `c` describes (the window, from the roller surface less
// the pit depth to the drum): what the magnet field must be valid over (check_field_region).
ReachableRegion reachable_region(const NipConfig& c);

}  // namespace nipdem::nip
