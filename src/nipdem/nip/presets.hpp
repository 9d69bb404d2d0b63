// CPS700 presets (data/presets/*.toml, embedded at build time): the one place that knows what
// "black" and "color" mean. Everything a preset implies (its magnet, its toner) is read from
// the preset's configuration, not restated in code.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/models/magnet_field.hpp"
#include "nipdem/models/magnetisation.hpp"

namespace nipdem::nip {
std::vector<std::string> preset_names();
// Complete TOML text of a preset; throws InputError for an unknown name.
std::string preset_text(const std::string& name);

// The analytic magnet of a preset's [magnet] field ("knife" or "color_pole"), with the depth
// of its tip and the remanence of its blade / pole replaced where given (the `field` commands).
struct MagnetOverrides {
  std::optional<double> tip_depth_m;  // [m]
  std::optional<double> br_T;         // [T]
};
magnet::BlockAssembly preset_magnet(const std::string& name, const MagnetOverrides& o = {});

// The toner of a preset: its magnetisation curve ([magnet] pigment) and d50 radius [m] ([toner]).
struct PresetToner {
  magnet::MagnetisationParams magnetisation;
  double d50_radius_m;
};
PresetToner preset_toner(const std::string& name);

// What the `field` commands (the CLI's and the Python module's) act on: the field of a preset's
// magnet, with its tip depth / remanence changed where given, or of a field map instead; the
// preset's toner and its radius.
struct FieldOptions {
  std::string preset = "black";
  std::string map;                       // field-map CSV (x_m,y_m,Bx_T,By_T); empty: the preset magnet
  std::optional<double> radius_m;        // [m]; default d50/2 of the preset toner
  std::optional<double> tip_depth_m;     // [m]; default the preset magnet's (not with a map)
  std::optional<double> br_T;            // [T]; default the preset magnet's (not with a map)
};
// Checks the options that were given against their physical range (never ignored, issue 21);
// messages name `where` and the command-line options (--preset, --radius, --tip-depth, --br).
void check_field_options(const FieldOptions& o, const std::string& where);

struct FieldSetup {
  std::unique_ptr<magnet::MagnetField> field;
  magnet::MagnetisationParams toner;
  double radius_m;
};
// The field, toner and radius of `o` (checked with check_field_options first); throws InputError
// for magnet overrides given with a map, or a map that does not read.
FieldSetup make_field_setup(const FieldOptions& o);
// The magnet's material (closed polygons, [m], MagnetField::material()) holds no toner: the field
// there is the one inside a magnet, and on the blocks' corners the analytic field is singular
// (log; NaN exactly on one). Empty for a source that does not know its material (a field map).
class MagnetMaterial {
 public:
  explicit MagnetMaterial(const magnet::MagnetField& f);
  // Throws InputError (where, keys, "point (x, y) m") for a point on or inside a block, naming the
  // region allowed: "<allowed_prefix> outside the magnet's blocks, e.g. y > <top> m (their top)".
  void require_outside(Vec2 p, const std::string& where, const std::string& keys, const std::string& allowed_prefix) const;
  double top() const { return top_; }  // highest point of the material (above it a point is outside)

 private:
  std::vector<std::vector<Vec2>> blocks_;
  double top_;
};
// Backstop for what the material test cannot see (a point next to a corner, a map with a tiny
// spacing): throws InputError naming `keys` and the point unless every value is finite.
void require_finite(const std::vector<double>& values, Vec2 p, const std::string& where, const std::string& keys,
                    const std::string& allowed);

// `field probe` -- the one check and computation of the CLI command and of Python's
// nipdem.field_probe: B, grad B, the induced moment (eq. 4.5.1 magnetisation curve)
// and the magnet force (m . grad) B (eq. 2.4.34) on a toner of the options' radius at (x, y) [m];
// checks x, y in [-1, 1] m, the options, a point on or inside an analytic magnet's blocks and
// values that are not finite (InputError naming `field probe` and the option). JSON keys as
// docs/cli-contract.md: preset, source, x_m, y_m, Bx_T, By_T, B_T, dB*_d*_T_per_m, radius_m,
// mx_Am2, my_Am2, moment_Am2, Fx_N, Fy_N, force_N.
nlohmann::json field_probe(const FieldOptions& o, double x_m, double y_m);
}  // namespace nipdem::nip
