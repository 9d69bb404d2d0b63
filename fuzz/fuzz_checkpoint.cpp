// Checkpoint loading: the first byte chooses the mode. 0: the bytes are a whole checkpoint file
// (exercises the frame: magic, version, size, CRC). Otherwise: the bytes are a payload that the
// harness seals with a correct CRC first, so the mutations reach the runner, engine and provider
// parsers (damage a checksum cannot see). The run is built once from a small configuration.
#include <memory>

#include "fuzz_common.hpp"
#include "nipdem/nip/nip.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/io/checkpoint_file.hpp"

namespace {
nipdem::nip::NipRun& target() {
  static auto run = std::make_unique<nipdem::nip::NipRun>(nipdem::nip::parse_nip_config(
      nipdem::nip::preset_text("black"), "preset:black",
      {"geometry.window_x_min_m=-100e-6", "geometry.window_x_max_m=100e-6", "collision.stiffness_scale=0.01", "output.vtk=false",
       "magnet.dipole_dipole=true"}));
  return *run;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  return nipdem::fuzz::run_one(data + 1, size - 1, [&](const std::string& bytes) {
    auto& run = target();
    if (data[0] == 0) run.restore(bytes, "fuzz");
    else run.restore(nipdem::io::seal_checkpoint(bytes), "fuzz");
  });
}
