// CRC-32C (Castagnoli polynomial 0x1EDC6F41, reflected 0x82F63B78; RFC 3720 appendix B.4), the
// checksum of checkpoint payloads: detects every burst error up to 32 bits and all but ~2^-32 of
// other damage. Plain table-driven software version (one table lookup per byte, ~0.5 GB/s):
// a checkpoint is written every few seconds of wall time at most, so speed does not matter.
// Check value: crc32c("123456789") == 0xE3069283 (tested).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace nipdem {

namespace detail {
constexpr std::array<std::uint32_t, 256> make_crc32c_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    t[i] = c;
  }
  return t;
}
inline constexpr std::array<std::uint32_t, 256> kCrc32cTable = make_crc32c_table();
}  // namespace detail

// CRC-32C of `data`, continuing from a previous result `crc` (0 to start).
inline std::uint32_t crc32c(std::string_view data, std::uint32_t crc = 0) {
  std::uint32_t c = ~crc;
  for (const char ch : data) c = detail::kCrc32cTable[(c ^ static_cast<unsigned char>(ch)) & 0xFFu] ^ (c >> 8);
  return ~c;
}

}  // namespace nipdem
