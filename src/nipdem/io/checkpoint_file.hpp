// The frame around every checkpoint nipdem writes (docs/reliability.md): a versioned header
// and a CRC-32C of the payload, so that a truncated, extended or damaged file is refused
// before a single byte of it is trusted.
//
//   offset  size  field
//   0       8     magic "NIPDEMCK"
//   8       4     format version (kCheckpointFormat)
//   12      4     reserved, 0
//   16      8     payload size [bytes]
//   24      4     CRC-32C of the payload
//   28      4     CRC-32C of bytes 0..27 (the header itself)
//   32      ...   payload (NipRun state, then the engine's, then each force provider's)
//
// Integers are in the machine's byte order (x86-64 and arm64: little-endian); a checkpoint is
// meant to be read back by the same build on the same kind of machine.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace nipdem::io {

// Version 4 (2026-12-04): first framed, checksummed format. Run checkpoints before it started
// with "NIPDEMRUN2"/"NIPDEMRUN3" and are refused with a message saying so.
inline constexpr std::uint32_t kCheckpointFormat = 4;
inline constexpr std::size_t kCheckpointHeaderBytes = 32;

// Frames `payload`.
std::string seal_checkpoint(std::string_view payload);
// Checks the frame of `blob` and returns its payload (a view into blob). Throws InputError
// "<where>: ..." naming what is wrong (not a checkpoint, older format, size, checksum).
std::string_view open_checkpoint(std::string_view blob, const std::string& where);

}  // namespace nipdem::io
