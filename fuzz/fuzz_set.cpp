// `--set KEY=VALUE` strings (one per line of the input) applied to the black preset.
#include <sstream>
#include <vector>

#include "fuzz_common.hpp"
#include "nipdem/nip/nip_config.hpp"
#include "nipdem/nip/presets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string preset = nipdem::nip::preset_text("black");
  return nipdem::fuzz::run_one(data, size, [](const std::string& text) {
    std::vector<std::string> sets;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) sets.push_back(line);
    nipdem::nip::parse_nip_config(preset, "preset:black", sets);
  });
}
