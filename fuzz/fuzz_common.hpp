// libFuzzer entry points (docs/reliability.md "Fuzzing"): each target feeds bytes to one reader
// and accepts exactly two outcomes, success or nipdem::InputError. Anything else (another
// exception, a crash, a sanitizer report, a hang) is a finding.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

#include "nipdem/core/error.hpp"

namespace nipdem::fuzz {
template <class F> int run_one(const std::uint8_t* data, std::size_t size, F&& f) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    f(bytes);
  } catch (const InputError&) {
  }
  return 0;
}
}  // namespace nipdem::fuzz
