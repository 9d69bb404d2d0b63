// CPS700 presets (data/presets/*.toml, embedded at build time): the one place that knows what
// "black" and "color" mean. Everything a preset implies (its magnet, its toner) is read from
// the preset's configuration, not restated in code.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "nipdem/models/magnet_field.hpp"
#include "nipdem/models/magnetisation.hpp"

namespace nipdem::experiments {
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
}  // namespace nipdem::experiments
