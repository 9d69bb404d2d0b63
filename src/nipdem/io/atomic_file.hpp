// Never lose results already written: write to "<path>.tmp.<pid>" then rename over <path>.
#pragma once
#include <filesystem>
#include <string>
#include <string_view>

namespace nipdem::io {

// Writes `content` to `path` atomically (temp file in the same folder, fsync, rename).
// Throws std::runtime_error naming the path on failure; the old file is left untouched.
void write_file_atomic(const std::filesystem::path& path, std::string_view content);

// Reads a whole file; throws InputError naming the path if it cannot be read.
std::string read_file(const std::filesystem::path& path);

}  // namespace nipdem::io
