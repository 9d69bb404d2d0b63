// Never lose results already written: write to "<path>.tmp.<pid>" then rename over <path>.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace nipdem::io {

// Writes `content` to `path` atomically (temp file in the same folder, fsync, rename).
// Throws InputError naming the path if it cannot be an output file (see check_replaceable, or
// its folder cannot be made or written), std::runtime_error naming it if writing fails (disk
// full); the old file is left untouched and no temp file is left behind.
void write_file_atomic(const std::filesystem::path& path, std::string_view content);

// Throws InputError naming `path` unless an output file may be written there by replacing
// what is at it: nothing, a regular file or a symlink (replaced itself, its target untouched).
// An empty path, a folder, a device, a FIFO or a socket is refused: a rename over a device
// node would replace it with a regular file (as root, /dev/null).
void check_replaceable(const std::filesystem::path& path);

// Largest input file (config, CSV, map, pattern, JSON) nipdem reads [bytes]: far above any real
// one, small enough that a wrong path (a disk image, a log) is refused before it is read.
inline constexpr std::uintmax_t kMaxInputBytes = 256ull << 20;
// Largest checkpoint [bytes] (about 10^7 particles).
inline constexpr std::uintmax_t kMaxCheckpointBytes = 16ull << 30;

// Reads a whole file; throws InputError naming the path if it is not a regular file (a folder,
// a device such as /dev/zero, a FIFO), is larger than max_bytes, or cannot be read.
std::string read_file(const std::filesystem::path& path, std::uintmax_t max_bytes = kMaxInputBytes);

}  // namespace nipdem::io
