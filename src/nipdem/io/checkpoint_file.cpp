#include "nipdem/io/checkpoint_file.hpp"

#include <cstring>
#include <fmt/format.h>

#include "nipdem/core/crc32c.hpp"
#include "nipdem/core/error.hpp"

namespace nipdem::io {

namespace {
constexpr char kMagic[8] = {'N', 'I', 'P', 'D', 'E', 'M', 'C', 'K'};
template <class T> void put_at(std::string& s, std::size_t at, T v) { std::memcpy(s.data() + at, &v, sizeof(T)); }
template <class T> T get_at(std::string_view s, std::size_t at) {
  T v;
  std::memcpy(&v, s.data() + at, sizeof(T));
  return v;
}
}  // namespace

std::string seal_checkpoint(std::string_view payload) {
  std::string s(kCheckpointHeaderBytes, '\0');
  std::memcpy(s.data(), kMagic, 8);
  put_at<std::uint32_t>(s, 8, kCheckpointFormat);
  put_at<std::uint32_t>(s, 12, 0);
  put_at<std::uint64_t>(s, 16, payload.size());
  put_at<std::uint32_t>(s, 24, crc32c(payload));
  put_at<std::uint32_t>(s, 28, crc32c(std::string_view(s.data(), 28)));
  s.append(payload);
  return s;
}

std::string_view open_checkpoint(std::string_view blob, const std::string& where) {
  auto fail = [&](const std::string& what) -> void { throw InputError(where + ": " + what); };
  if (blob.substr(0, 9) == "NIPDEMRUN")
    fail(fmt::format("checkpoint of an older nipdem (format '{}', before the checksummed format {}): this build "
                     "cannot resume it; start the run again (--force) with this build",
                     blob.substr(0, 10), kCheckpointFormat));
  if (blob.size() < kCheckpointHeaderBytes || std::memcmp(blob.data(), kMagic, 8) != 0)
    fail(fmt::format("not a nipdem checkpoint ({} bytes, no 'NIPDEMCK' header)", blob.size()));
  if (get_at<std::uint32_t>(blob, 28) != crc32c(blob.substr(0, 28)))
    fail("checkpoint header damaged (header checksum mismatch)");
  const auto version = get_at<std::uint32_t>(blob, 8);
  if (version != kCheckpointFormat)
    fail(fmt::format("checkpoint format version {} is not the one this build reads ({}); start the run again (--force)",
                     version, kCheckpointFormat));
  if (get_at<std::uint32_t>(blob, 12) != 0) fail("checkpoint header damaged (reserved field not 0)");
  const auto size = get_at<std::uint64_t>(blob, 16);
  const std::uint64_t have = blob.size() - kCheckpointHeaderBytes;
  if (size != have)
    fail(fmt::format("checkpoint {} (header says {} payload bytes, the file holds {})",
                     have < size ? "truncated" : "has bytes appended", size, have));
  const std::string_view payload = blob.substr(kCheckpointHeaderBytes);
  const auto want = get_at<std::uint32_t>(blob, 24);
  const auto got = crc32c(payload);
  if (got != want) fail(fmt::format("checkpoint damaged (CRC-32C of the payload is {:08x}, the header says {:08x})", got, want));
  return payload;
}

}  // namespace nipdem::io
