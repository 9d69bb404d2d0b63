#include "nipdem/experiments/presets.hpp"

#include "nipdem/core/error.hpp"
#include "nipdem/embedded_preset_black.hpp"
#include "nipdem/embedded_preset_color.hpp"

namespace nipdem::experiments {
std::vector<std::string> preset_names() { return {"black", "color"}; }
std::string preset_text(const std::string& name) {
  if (name == "black") return kPreset_black;
  if (name == "color" || name == "colour") return kPreset_color;
  throw_input("presets", "NAME", "\"" + name + "\"", "unknown preset", "black, color");
}
}  // namespace nipdem::experiments
