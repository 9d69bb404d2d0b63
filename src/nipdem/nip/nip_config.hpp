// Configuration of a nip simulation (one TOML file; see `nipdem presets show black`).
// One source of defaults: the file's keys are laid over a preset (top-level key `preset`,
// "black" when absent; data/presets/*.toml), and the loader reads every key from that merged
// table, so NipConfig and the loader carry no defaults of their own. The sub-structs
// (SizeDistribution, MagnetConfig, ElectricConfig) keep member defaults for code that builds
// them without a config; tests/unit/test_nip_config.cpp checks those equal the black preset.
// Every key carries its unit; the loader rejects unknown keys and out-of-range values with a
// message naming file, key, value and the allowed range.
//
// The typed fields are the configuration. Code that varies it (the experiments) edits the
// fields of a copy and calls validate(), which checks what depends on more than one key and
// regenerates the resolved table and the resume keys from the fields: no `key=value` strings,
// no second reading of the file.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "nipdem/core/vec2.hpp"
#include "nipdem/engine/simulation.hpp"
#include "nipdem/nip/nip_forces.hpp"
#include "nipdem/nip/toner.hpp"
#include "nipdem/models/collision_params.hpp"
#include "nipdem/models/hamaker.hpp"

namespace nipdem::nip {

struct CollisionType {
  double restitution{};  // e_n [-] (§4.2.1)
  double k{};            // linear spring constant [N/m] (Table 4.2)
  double mu_s{};         // static friction [-] (§4.3.1)
  double mu_d{};         // dynamic friction [-]
};

struct NipConfig {
  std::string file;          // where it came from (for messages)
  std::string preset;        // the preset the file was laid over ("black" or "color")
  // [run]
  std::uint64_t seed{};
  double end_time{};            // [s]
  double output_interval{};     // [s] particle snapshots
  double checkpoint_interval{}; // [s]
  int threads{};
  engine::Integrator integrator{};
  double dt{};                   // [s]; 0 = dt_fraction * smallest contact time
  double dt_fraction{};         // of the smallest contact time
  double list_skin_d50{};        // contact neighbour-list skin [d50]: a speed knob only,
                                     // the forces do not depend on it (docs/performance.md)
  // [geometry]
  double gap{};               // w_h [m] (§4.1)
  double drum_radius{};         // [m]
  double roller_radius{};       // [m]
  double drum_speed{};      // surface speed [m/s] (§4.1: 6.7 m/min)
  double roller_speed{};   // surface speed [m/s] (§4.1: 30 m/min black)
  double nip_x{};                // x of the line through both axes [m]
  double x_min{}, x_max{};  // simulated window [m]
  bool roughness{};
  double rough_height{}, rough_base{}, rough_spacing{};  // §2.1
  // [toner]
  SizeDistribution size;
  double density{};             // [kg/m^3] (Table 2.1)
  std::string cluster{};
  std::string cluster_file;          // optional own templates
  // [collision]
  CollisionType tt, ti, td;          // toner-toner, toner-imaging roller, toner-DI drum
  double stiffness_scale{};      // k -> scale k, restitution kept (end of §4.2.2)
  models::DampingConvention damping{};
  // [adhesion]
  models::HamakerParams::Distance adhesion_distance{};
  double min_separation{};     // D0 [m]
  double adhesion_cutoff{};     // [m]
  double adhesion_roller_force{};  // F_adh, d50 toner on the imaging roller [N] (§4.6)
  double adhesion_drum_force{};    // d50 toner on the drum [N]
  double cohesion_ratio{};           // r = F_coh / F_adh (eq. 4.6.1)
  // [inflow]
  double layer_thickness{};    // toner layer on the drum entering the window [m]
  double area_fraction{};        // of that layer (2D) [-]
  int insert_interval{};         // steps between inflow/outflow passes
  bool prefill{};               // start with the layer over the whole window
  // Roughness pits of the sleeve entering the window (and at the start) are filled with
  // toner (docs/geometry.md "Filled pits"): the steady state of a sleeve whose pits the
  // supply roller does not empty.
  bool roller_pits_filled{};
  // [initial_assembly]: toner resting on the roller at the start, e.g. a DI toner assembly that
  // fills the nip as in the clean state of §5.1 (print runs start from it, §5.2-5.3).
  struct InitialAssembly {
    bool enabled{};
    double x_min{}, x_max{};  // [m], magnet-edge frame
    double height{};                     // above the lands [m]; 0 = up to the drum
    double area_fraction{};              // 2D fill by random sequential addition [-]
  } assembly;
  // [gravity]
  Vec2 gravity;
  // [magnet]
  MagnetConfig magnet;
  std::string magnet_pigment;        // "black" | "color": the base of magnet.toner
  // [electric] and [print]
  ElectricConfig electric;
  std::string charge_preset;         // "black" | "color": the base of electric.rc
  // [print] as given: the small pattern language of io/print_pattern.hpp; validate() compiles
  // it into electric.pattern. print_given: the file (or an experiment) gave a [print] table
  // (the preset's pattern = "none" does not count: [electric] enabled needs one).
  toml::table print;
  bool print_given{};
  // [output]
  bool vtk{};

  std::vector<ClusterTemplate> templates;  // resolved library
  // The merged table as read: only its layout and number kinds (an integer written as `40`
  // stays `40`) are used; validate() writes every field into it, so a configuration read from a
  // file serializes exactly as written, and a default-constructed one still lists every key.
  toml::table table;
  // Set by validate():
  std::string resolved_toml;               // the complete resolved configuration (run folder's config.toml):
                                           // preset + file + --set, with derived values recorded
  std::string resume_key;                  // the configuration minus keys a resume may change
  // resume_key minus print.voltage_V: runs that differ only in the track's on voltage are
  // identical until the track first switches on (NipRun::restore_before_print_switch).
  std::string prefix_key;
};

// The preset named by the file's `preset` key (default "black") merged with the file and the
// overrides (not yet validated). `overrides` are KEY=VALUE strings (the user's --set).
toml::table resolve_nip_table(const std::string& text, const std::string& file, const std::vector<std::string>& overrides = {});
// Reads preset + file + overrides into the typed fields, checking every key on its own (type,
// range, unknown keys); not yet validated.
NipConfig read_nip_config(const std::string& text, const std::string& file, const std::vector<std::string>& overrides = {});
// The one check of a whole configuration, after reading or after editing fields: cross-checks
// (gap vs particle size, window vs radii, initial assembly inside the window, [electric] needs
// a [print]), the [print] pattern compiled, values that follow from other fields (the drum
// geometry the electric force sees), the time step against its stability bound, resource
// bounds; then resolved_toml, resume_key and prefix_key from the fields. Throws InputError.
void validate(NipConfig& c);
// read + validate.
NipConfig load_nip_config(const std::string& path, const std::vector<std::string>& overrides = {});
NipConfig parse_nip_config(const std::string& text, const std::string& file, const std::vector<std::string>& overrides = {});
// Prints one line: [electric] on, [print] pattern = "line" from start_m over length_m, at
// voltage_V if given (else the table's own voltage_V). Other [print] keys are kept.
void set_print_line(NipConfig& c, double start_m, double length_m, std::optional<double> voltage_V = std::nullopt);

// Derived collision parameters of one type for reporting (d50 particles).
struct CollisionReport {
  std::string name;
  double k, gamma, ks, restitution, contact_time, dt_max_newmark, dt_max_verlet, m_red;
  double gamma_thesis;  // gamma with eq. 2.2.7 as printed (Table 4.2 convention)
};
std::vector<CollisionReport> collision_report(const NipConfig& c);
// `nipdem params collision --json`: the report per collision type and the time step chosen.
nlohmann::json collision_json(const NipConfig& c);
// Mass of a toner particle of volume-equivalent diameter d [kg].
double toner_mass(const NipConfig& c, double d);
// Engine interactions [toner_toner, toner_roller, toner_drum] with k scaled, gamma from e.
std::vector<engine::Interaction> make_interactions(const NipConfig& c);
// Time step actually used and the bound it must respect (throws InputError if dt > bound).
struct TimeStep { double dt, bound; std::string limiting; };
TimeStep choose_time_step(const NipConfig& c);

}  // namespace nipdem::nip
