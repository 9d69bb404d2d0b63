#include "nipdem/io/atomic_file.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

#include "nipdem/core/error.hpp"

namespace nipdem::io {

void write_file_atomic(const std::filesystem::path& path, std::string_view content) {
  namespace fs = std::filesystem;
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  fs::path tmp = path;
  tmp += ".tmp." + std::to_string(::getpid());
  {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw std::runtime_error("cannot open '" + tmp.string() + "' for writing");
    const bool ok = std::fwrite(content.data(), 1, content.size(), f) == content.size() &&
                    std::fflush(f) == 0 && ::fsync(::fileno(f)) == 0;
    std::fclose(f);
    if (!ok) {
      fs::remove(tmp);
      throw std::runtime_error("cannot write '" + tmp.string() + "' (disk full?)");
    }
  }
  fs::rename(tmp, path);
}

std::string read_file(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto st = fs::status(path, ec);  // follows symlinks
  if (ec || !fs::exists(st)) throw InputError(path.string() + ": cannot open file (missing or unreadable)");
  if (fs::is_directory(st)) throw InputError(path.string() + ": is a folder, not a file");
  if (!fs::is_regular_file(st)) throw InputError(path.string() + ": is not a regular file (a device, FIFO or socket)");
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError(path.string() + ": cannot open file (missing or unreadable)");
  if (size > max_bytes)
    throw InputError(path.string() + ": file of " + std::to_string(size) + " bytes is larger than the " +
                     std::to_string(max_bytes >> 20) + " MiB nipdem reads (wrong file?)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open file (missing or unreadable)");
  std::string s(static_cast<std::size_t>(size), '\0');
  in.read(s.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size || in.bad())
    throw InputError(path.string() + ": read failed (file changed while being read?)");
  return s;
}

}  // namespace nipdem::io
