// Body forces of the DI toner assembly, plugged into the engine as BodyForce providers:
// the magnet inside the imaging roller acting on induced toner moments (eq. 2.4.34 with
// eq. 4.5.1) and the dipole-dipole force between toner particles (eqs. 2.4.38-2.4.39).
#pragma once
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "nipdem/engine/simulation.hpp"
#include "nipdem/io/print_pattern.hpp"
#include "nipdem/models/electric_force.hpp"
#include "nipdem/models/electric_screening.hpp"
#include "nipdem/models/rc_charge.hpp"
#include "nipdem/solvers/conduction_path.hpp"
#include "nipdem/models/dipole.hpp"
#include "nipdem/models/magnet_field.hpp"
#include "nipdem/models/magnetisation.hpp"

namespace nipdem::nip {

struct MagnetConfig {
  std::string field = "knife";     // "knife" (black unit), "color_pole", "map" or "none"
  std::string map_file;            // CSV field map (field = "map")
  magnet::MagnetisationParams toner = magnet::black_toner();  // Tables 2.1-2.2
  bool dipole_dipole = true;
  double dipole_cutoff = 42e-6;    // [m]: 8 R50 (docs/magnetic.md: ~1.3 % mean truncation error)
  int dipole_interval = 10;        // steps between dipole-dipole re-evaluations
  double dipole_skin = 8e-6;       // [m] reach of the persistent dipole pair list beyond the
                                   // cut-off (saves the search only: the sum is exact within it)
  int field_interval = 10;         // steps between magnet-field force re-evaluations: a toner moves
                                   // < 0.1 um in 10 steps, the field varies over >= 100 um
  int threads = 1;                 // OpenMP threads for the per-particle field force (set it to
                                   // the engine's thread count; results do not depend on it)
};

// Magnet force on every toner body: moment m = 4/3 pi R^3 eta M(B) at the centre of mass
// ("cherry pit"), R the volume-equivalent radius (body size / 2), F = (m . grad) B.
// An analytic field (anything but a field map) is tabulated lazily on a fixed lattice of
// square tiles (h = 20 um, bicubic Hermite as io::FieldMap): about 3x cheaper per particle,
// force error < 1e-4 relative (docs/performance.md). A tile's content depends only on its
// position, never on when it was built, so results stay deterministic and resume-exact.
// A cell whose interpolation stencil (the cell and two nodes beyond it on each side) touches a
// magnet face, where the field jumps, is never interpolated: it is evaluated exactly
// (docs/magnetic.md, "Field tables"). Where toner may go at all is checked at setup
// (check_field_region).
// Optionally the dipole-dipole force between the induced moments within a cut-off, with the
// moments induced by the magnet's field only (§4.5); it is re-evaluated every
// `dipole_interval` steps and held in between (multiple time stepping; docs/magnetic.md),
// summed over a persistent pair list (dipole::PairSum: exact cut-off sum, rebuilt after load).
class MagnetForce final : public engine::BodyForce {
 public:
  MagnetForce(std::shared_ptr<const magnet::MagnetField> field, MagnetConfig cfg);
  std::string name() const override { return "magnetic"; }
  void add(const BodyStore& b, const DiscStore& d, double t, std::span<double> fx, std::span<double> fy,
           std::span<double> torque) override;
  // The field force and the dipole-dipole force of the last evaluation, for the engine to add
  // (engine::BodyForce::Held; add() then leaves them out).
  Held held() const override;
  bool reads_contacts() const override { return false; }  // (positions, sizes and ids only)
  // Dipole-dipole part of the last evaluation, per body [N] (for tests and output).
  const std::vector<double>& dipole_fx() const { return dfx_; }
  const std::vector<double>& dipole_fy() const { return dfy_; }
  // Induced moments of the last field evaluation, per body [A m^2].
  const std::vector<Vec2>& moments() const { return moment_; }
  const dipole::PairSum& dipole_pairs() const { return pairs_; }
  // The field sample the force uses at p (from the table where it applies, built on demand;
  // not thread-safe): for tests and benchmarks that check the table against the source.
  magnet::Sample field_sample(Vec2 p) { return field_at(p); }
  void save(std::ostream& o) const override;
  void load(std::istream& in) override;

 private:
  void dipole_pass(const BodyStore& b, bool same_set);
  void field_pass(const BodyStore& b);
  // One tile of the table: an interpolant over its cells, or nothing (evaluate the source: a
  // node on a magnet corner), and the cells whose stencil touches a magnet face.
  struct Tile {
    std::shared_ptr<const magnet::MagnetField> map;  // null: exact everywhere in the tile
    double x0 = 0.0, y0 = 0.0;                      // lower-left corner of the tile's first cell [m]
    std::vector<unsigned char> exact_cell;          // kTileCells^2, row-major in y; empty if none
  };
  magnet::Sample field_at(Vec2 p);
  const Tile* tile_for(Vec2 p);  // builds the tile if needed; null = outside the table: use field_
  int tile_index(Vec2 p) const;  // index of p's tile in tiles_, -1 outside the table (or none)
  magnet::Sample sample(const Tile* t, Vec2 p) const;
  std::shared_ptr<const magnet::MagnetField> field_;
  // Tabulated field: tiles_[ty * kTilesX + tx] covers [x_lo + tx T, x_lo + (tx+1) T) x (same in y).
  static constexpr double kTileH = 20e-6;  // node spacing [m]
  static constexpr int kTileCells = 20;    // cells per tile side (T = 400 um)
  static constexpr int kTilesX = 64, kTilesY = 32;
  bool tabulate_ = false;
  std::vector<std::unique_ptr<Tile>> tiles_;
  MagnetConfig cfg_;
  std::vector<Vec2> moment_;
  std::vector<double> dfx_, dfy_;
  std::vector<std::int64_t> ids_;         // body ids the held forces belong to
  std::uint64_t seen_version_ = 0;        // the engine's body-set number at the last call (0: none)
  std::vector<char> pending_;             // field_pass: particles whose tile was not built yet
  std::vector<double> ffx_, ffy_;         // held magnet-field force per body [N]
  long calls_ = 0;
  dipole::PairSum pairs_;                 // persistent pair list (not saved: rebuilt after load)
};

struct ElectricConfig {
  bool enabled = false;
  electric::ElectricForceParams force;      // exact | series | approx (§2.5.3; docs/electric.md)
  bool dielectric_layer = true;             // d = l + d_l/eps_2, eq. 2.5.43
  double layer_thickness = 600e-9;          // d_l [m]
  double layer_permittivity = 5.0;          // eps_2 [-]
  charge::RcChargeParams rc = charge::RcChargeParams::black();  // §2.5.5, §4.7
  double corridor_fraction = 0.0;           // screening corridor width / r (docs/electric.md)
  int path_interval = 50;                   // steps between conduction-path/screening updates
  io::PrintPattern pattern;                 // drum track voltage vs drum surface position
  double drum_speed = 0.0;                  // [m/s], s = v t at the nip
  Vec2 drum_centre{};                       // [m]
  double drum_radius = 0.0;                 // [m]
  int roller_wall = 0, drum_wall = 1;       // wall indices in the engine
};

// Electric print force (§2.5): toner within d50 of the drum and not screened by another
// particle is a capacitor C_td to the drum, charged through its shortest conducting path to
// the grounded imaging roller (RC model, §2.5.5); the voltage u over that capacitor drives
// the force of a conducting sphere (radius = volume-equivalent radius) at gap l from a plate
// (bispherical/capacitance solution, §2.5.3), pulling it towards the drum along the normal
// through its nearest disc. Paths and screening are refreshed every `path_interval` steps;
// charges are updated every step (exact exponential update).
class ElectricForce final : public engine::BodyForce {
 public:
  ElectricForce(const engine::Simulation* sim, ElectricConfig cfg);
  std::string name() const override { return "electric"; }
  void add(const BodyStore& b, const DiscStore& d, double t, std::span<double> fx, std::span<double> fy,
           std::span<double> torque) override;
  // Capacitor voltage u [V] of each body (same order as the body arrays), last evaluation.
  const std::vector<double>& voltage() const { return u_; }
  double drum_voltage() const { return v_drum_; }
  int printable_count() const { return n_printable_; }
  void save(std::ostream& o) const override;
  void load(std::istream& in) override;

 private:
  void refresh(const BodyStore& b, const DiscStore& d);
  const engine::Simulation* sim_;
  ElectricConfig cfg_;
  electric::ElectricForceTable table_;
  conduction::ConductionPaths paths_;
  std::vector<double> u_;                   // per body
  std::vector<std::int64_t> ids_;           // body ids u_ belongs to
  std::uint64_t seen_version_ = 0;          // the engine's body-set number at the last call (0: none)
  std::vector<charge::DrumCoupling> coupling_;
  std::vector<char> printable_;
  std::vector<int> near_disc_;              // disc of each body nearest the drum
  std::vector<double> gap_;                 // its surface gap to the drum [m]
  std::vector<double> r_path_;              // path resistance at the last refresh [ohm]
  // refresh()'s scratch (kept between calls: no allocation per refresh)
  std::vector<std::pair<int, int>> pair_scratch_;
  std::vector<int> layer_scratch_;
  std::vector<double> layer_x_scratch_;
  std::vector<electric::Disc> others_scratch_;
  double v_drum_ = 0.0, t_last_ = -1.0;
  long calls_ = 0;
  int n_printable_ = 0;
};

// The field a MagnetConfig names (throws InputError for an unreadable map).
std::shared_ptr<const magnet::MagnetField> make_magnet_field(const MagnetConfig& c);

// The part of the process plane a toner centre can reach: x in [x_min, x_max], y from the
// imaging-roller surface less the pit depth up to the drum surface (both circles).
struct ReachableRegion {
  double x_min = 0.0, x_max = 0.0;       // [m] the window
  Vec2 roller_centre{}, drum_centre{};   // [m]
  double roller_radius = 0.0, drum_radius = 0.0, pit_depth = 0.0;  // [m]
  double y_low(double x) const;   // lowest reachable y at x (roller surface - pit depth)
  double y_high(double x) const;  // the drum surface at x
};
// Refuses (InputError naming the window keys and the region where the field is valid) a field
// that is not valid where toner can go: magnet material reaching into the region (the field a
// toner feels is never the one inside a magnet), or a field map that does not cover it.
void check_field_region(const magnet::MagnetField& f, const ReachableRegion& r, const std::string& field_name);

}  // namespace nipdem::nip
