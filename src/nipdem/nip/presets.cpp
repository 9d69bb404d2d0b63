#include "nipdem/nip/presets.hpp"

#include "nipdem/core/error.hpp"
#include "nipdem/embedded_preset_black.hpp"
#include "nipdem/embedded_preset_color.hpp"
#include "nipdem/nip/nip_config.hpp"

namespace nipdem::experiments {
std::vector<std::string> preset_names() { return {"black", "color"}; }
std::string preset_text(const std::string& name) {
  if (name == "black") return kPreset_black;
  if (name == "color" || name == "colour") return kPreset_color;
  throw_input("presets", "NAME", "\"" + name + "\"", "unknown preset", "black, color");
}

magnet::BlockAssembly preset_magnet(const std::string& name, const MagnetOverrides& o) {
  const NipConfig c = read_nip_config(preset_text(name), "preset:" + name);
  if (c.magnet.field == "knife") {
    magnet::KnifeParams k;
    if (o.tip_depth_m) k.tip_depth_m = *o.tip_depth_m;
    if (o.br_T) k.blade_Br_T = *o.br_T;
    return magnet::make_knife(k);
  }
  if (c.magnet.field == "color_pole") {
    magnet::ColorPoleParams k;
    if (o.tip_depth_m) k.tip_depth_m = *o.tip_depth_m;
    if (o.br_T) k.Br_T = *o.br_T;
    return magnet::make_color_pole(k);
  }
  throw_input("preset:" + name, "magnet.field", c.magnet.field, "not an analytic magnet", "knife, color_pole");
}

PresetToner preset_toner(const std::string& name) {
  const NipConfig c = read_nip_config(preset_text(name), "preset:" + name);
  return {c.magnet.toner, 0.5 * c.size.d50};
}
}  // namespace nipdem::experiments
