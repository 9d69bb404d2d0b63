// CPS700 presets (data/presets/*.toml, embedded at build time).
#pragma once
#include <string>
#include <vector>

namespace nipdem::experiments {
std::vector<std::string> preset_names();
// Complete TOML text of a preset; throws InputError for an unknown name.
std::string preset_text(const std::string& name);
}  // namespace nipdem::experiments
