// Configuration of a nip simulation (one TOML file; see `nipdem presets show black`).
// Every key carries its unit; the loader rejects unknown keys and out-of-range values with a
// message naming file, key, value and the allowed range.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "nipdem/core/vec2.hpp"
#include "nipdem/engine/simulation.hpp"
#include "nipdem/experiments/nip_forces.hpp"
#include "nipdem/experiments/toner.hpp"
#include "nipdem/models/collision_params.hpp"
#include "nipdem/models/hamaker.hpp"

namespace nipdem::experiments {

struct CollisionType {
  double restitution = 0.5;  // e_n [-] (§4.2.1)
  double k = 0.0;            // linear spring constant [N/m] (Table 4.2)
  double mu_s = 0.0;         // static friction [-] (§4.3.1)
  double mu_d = 0.0;         // dynamic friction [-]
};

struct NipConfig {
  std::string file;          // where it came from (for messages)
  // [run]
  std::uint64_t seed = 1;
  double end_time = 1e-3;            // [s]
  double output_interval = 1e-4;     // [s] particle snapshots
  double checkpoint_interval = 5e-4; // [s]
  int threads = 1;
  engine::Integrator integrator = engine::Integrator::velocity_verlet;
  double dt = 0.0;                   // [s]; 0 = dt_fraction * smallest contact time
  double dt_fraction = 0.04;         // of the smallest contact time
  double list_skin_d50 = 0.3;        // contact neighbour-list skin [d50]: a speed knob only,
                                     // the forces do not depend on it (docs/performance.md)
  // [geometry]
  double gap = 150e-6;               // w_h [m] (§4.1)
  double drum_radius = 0.02;         // [m]
  double roller_radius = 0.05;       // [m]
  double drum_speed = 6.7 / 60;      // surface speed [m/s] (§4.1: 6.7 m/min)
  double roller_speed = 30.0 / 60;   // surface speed [m/s] (§4.1: 30 m/min black)
  double nip_x = 0.0;                // x of the line through both axes [m]
  double x_min = -600e-6, x_max = 600e-6;  // simulated window [m]
  bool roughness = true;
  double rough_height = 15e-6, rough_base = 50e-6, rough_spacing = 20e-6;  // §2.1
  // [toner]
  SizeDistribution size;
  double density = 1700;             // [kg/m^3] (Table 2.1)
  std::string cluster = "tri3";
  std::string cluster_file;          // optional own templates
  // [collision]
  CollisionType tt, ti, td;          // toner-toner, toner-imaging roller, toner-DI drum
  double stiffness_scale = 1.0;      // k -> scale k, restitution kept (end of §4.2.2)
  models::DampingConvention damping = models::DampingConvention::physical;
  // [adhesion]
  models::HamakerParams::Distance adhesion_distance = models::HamakerParams::Distance::surface;
  double min_separation = 4e-10;     // D0 [m]
  double adhesion_cutoff = 4e-9;     // [m]
  double adhesion_roller_force = 1e-10;  // F_adh, d50 toner on the imaging roller [N] (§4.6)
  double adhesion_drum_force = 1e-10;    // d50 toner on the drum [N]
  double cohesion_ratio = 1.0;           // r = F_coh / F_adh (eq. 4.6.1)
  // [inflow]
  double layer_thickness = 30e-6;    // toner layer on the drum entering the window [m]
  double area_fraction = 0.5;        // of that layer (2D) [-]
  int insert_interval = 200;         // steps between inflow/outflow passes
  bool prefill = true;               // start with the layer over the whole window
  // Roughness pits of the sleeve entering the window (and at the start) are filled with
  // toner (docs/geometry.md "Filled pits"): the steady state of a sleeve whose pits the
  // supply roller does not empty.
  bool roller_pits_filled = false;
  // [initial_assembly]: toner resting on the roller at the start, e.g. a DI toner assembly that
  // fills the nip as in the clean state of §5.1 (print runs start from it, §5.2-5.3).
  struct InitialAssembly {
    bool enabled = false;
    double x_min = -250e-6, x_max = 150e-6;  // [m], magnet-edge frame
    double height = 0.0;                     // above the lands [m]; 0 = up to the drum
    double area_fraction = 0.6;              // 2D fill by random sequential addition [-]
  } assembly;
  // [gravity]
  Vec2 gravity{0.0, -9.81};
  // [magnet]
  MagnetConfig magnet;
  // [electric] and [print]
  ElectricConfig electric;
  // [output]
  bool vtk = true;

  std::vector<ClusterTemplate> templates;  // resolved library
  std::string resolved_toml;               // the effective configuration (for summary.json)
  std::string resume_key;                  // the configuration minus keys a resume may change
  // resume_key minus print.voltage_V: runs that differ only in the track's on voltage are
  // identical until the track first switches on (NipRun::restore_before_print_switch).
  std::string prefix_key;
};

// Loads and validates. `overrides` are KEY=VALUE strings (from --set).
NipConfig load_nip_config(const std::string& path, const std::vector<std::string>& overrides = {});
NipConfig parse_nip_config(const std::string& text, const std::string& file, const std::vector<std::string>& overrides = {});

// Derived collision parameters of one type for reporting (d50 particles).
struct CollisionReport {
  std::string name;
  double k, gamma, ks, restitution, contact_time, dt_max_newmark, dt_max_verlet, m_red;
  double gamma_thesis;  // gamma with eq. 2.2.7 as printed (Table 4.2 convention)
};
std::vector<CollisionReport> collision_report(const NipConfig& c);
// Mass of a toner particle of volume-equivalent diameter d [kg].
double toner_mass(const NipConfig& c, double d);
// Engine interactions [toner_toner, toner_roller, toner_drum] with k scaled, gamma from e.
std::vector<engine::Interaction> make_interactions(const NipConfig& c);
// Time step actually used and the bound it must respect (throws InputError if dt > bound).
struct TimeStep { double dt, bound; std::string limiting; };
TimeStep choose_time_step(const NipConfig& c);

}  // namespace nipdem::experiments
