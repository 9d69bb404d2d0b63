// A TOML configuration file as nipdem run reads it (the whole parse and every cross-check).
#include "fuzz_common.hpp"
#include "nipdem/nip/nip_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return nipdem::fuzz::run_one(data, size, [](const std::string& text) { nipdem::nip::parse_nip_config(text, "fuzz.toml"); });
}
