// A PBM print pattern (P1 plain or P4 raw).
#include "fuzz_common.hpp"
#include "nipdem/io/print_pattern.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return nipdem::fuzz::run_one(data, size, [](const std::string& bytes) { nipdem::io::parse_pbm(bytes, "fuzz.pbm"); });
}
