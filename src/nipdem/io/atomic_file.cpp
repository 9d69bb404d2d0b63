#include "nipdem/io/atomic_file.hpp"

#include <cerrno>
#include <csignal>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

#include "nipdem/core/error.hpp"

namespace nipdem::io {

namespace {
// Fault injection for the kill-at-many-moments test (docs/reliability.md): with
// NIPDEM_FAULT_KILL_AT_WRITE = "N:before" (or "N:after") the process kills itself with SIGKILL
// at its N-th atomic write, between the temp file's fsync and the rename (or just after the
// rename). Read once; costs one comparison per write otherwise.
struct KillAtWrite {
  long n = -1;
  bool before = true;
  long count = 0;
  KillAtWrite() {
    if (const char* e = std::getenv("NIPDEM_FAULT_KILL_AT_WRITE")) {
      char* end = nullptr;
      n = std::strtol(e, &end, 10);
      before = !(end && std::string_view(end) == ":after");
    }
  }
};
KillAtWrite& kill_at_write() {
  static KillAtWrite k;
  return k;
}
}  // namespace

void check_replaceable(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError("output path is empty (name a file to write)");
  std::error_code ec;
  const auto st = fs::symlink_status(path, ec);  // a symlink itself is replaced, not its target
  if (ec || !fs::exists(st) || fs::is_regular_file(st) || fs::is_symlink(st)) return;
  throw InputError(path.string() + (fs::is_directory(st)
                                        ? ": is a folder; nipdem writes its output file there by replacing what is at that path, and will not replace a folder (name a file)"
                                        : ": is not a regular file (a device, FIFO or socket); nipdem writes its output by replacing what is at that path, and will not replace that (name a file)"));
}

void write_file_atomic(const std::filesystem::path& path, std::string_view content) {
  namespace fs = std::filesystem;
  check_replaceable(path);
  if (path.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    if (ec) throw InputError(path.string() + ": cannot create its folder " + path.parent_path().string() + " (" + ec.message() + ")");
  }
  fs::path tmp = path;
  tmp += ".tmp." + std::to_string(::getpid());
  {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw InputError(path.string() + ": cannot write there (cannot create '" + tmp.string() + "': " + std::strerror(errno) + ")");
    const bool ok = std::fwrite(content.data(), 1, content.size(), f) == content.size() &&
                    std::fflush(f) == 0 && ::fsync(::fileno(f)) == 0;
    std::fclose(f);
    if (!ok) {
      fs::remove(tmp);
      throw std::runtime_error("cannot write '" + tmp.string() + "' (disk full?)");
    }
  }
  auto& k = kill_at_write();
  const bool kill_now = k.n > 0 && ++k.count == k.n;
  if (kill_now && k.before) ::raise(SIGKILL);
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {  // (the path changed since the check, or a filesystem that refuses): no temp file left behind
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot replace '" + path.string() + "' by its new content: " + ec.message());
  }
  if (kill_now) ::raise(SIGKILL);
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
