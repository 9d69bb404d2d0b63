// Raw binary (de)serialisation for checkpoints: trivially copyable values and vectors of them,
// in the machine's byte order (a checkpoint is read back by the same build on the same kind of
// machine). Only types without padding may be written whole (structs are written field by
// field, so the bytes on disk are a function of the state alone: two identical runs write
// identical files). Reads throw InputError on truncated or implausible data, and never
// allocate more than the data actually present (plus one chunk): a damaged length cannot
// make a reader ask for gigabytes.
#pragma once
#include <algorithm>
#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <type_traits>
#include <vector>

#include "nipdem/core/error.hpp"
#include "nipdem/core/vec2.hpp"

namespace nipdem::binary {

// Types whose bytes are all value bytes (no padding). Floating point counts (only NaN payloads
// are not unique, and a state never holds NaN); Vec2 is two doubles.
template <class T>
inline constexpr bool kWritable = (std::is_trivially_copyable_v<T> && std::has_unique_object_representations_v<T>) ||
                                  std::is_floating_point_v<T> || std::is_enum_v<T> || std::is_same_v<T, Vec2>;
static_assert(sizeof(Vec2) == 2 * sizeof(double));

template <class T> void put(std::ostream& o, const T& v) {
  static_assert(kWritable<T>, "write structs field by field (padding bytes are not deterministic)");
  o.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T> void put_vec(std::ostream& o, const std::vector<T>& v) {
  static_assert(kWritable<T>, "write structs field by field (padding bytes are not deterministic)");
  const std::uint64_t n = v.size();
  put(o, n);
  o.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
}
template <class T> void get(std::istream& i, T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  if (!i.read(reinterpret_cast<char*>(&v), sizeof(T))) throw InputError("checkpoint truncated (data ends inside a value)");
}
// Reads a vector written by put_vec; `what` names it in errors. At most `max_n` elements.
template <class T> void get_vec(std::istream& i, std::vector<T>& v, const char* what = "array",
                                std::uint64_t max_n = (1ULL << 34)) {
  static_assert(std::is_trivially_copyable_v<T>);
  std::uint64_t n;
  get(i, n);
  if (n > max_n)
    throw InputError("checkpoint corrupt: " + std::string(what) + " has " + std::to_string(n) + " elements (at most " +
                     std::to_string(max_n) + " plausible)");
  v.clear();
  // Grow chunk by chunk as the data arrives, so a damaged count fails at the end of the data.
  constexpr std::uint64_t kChunkBytes = 1u << 20;
  const std::uint64_t chunk = std::max<std::uint64_t>(1, kChunkBytes / sizeof(T));
  for (std::uint64_t done = 0; done < n;) {
    const std::uint64_t m = std::min(chunk, n - done);
    v.resize(static_cast<std::size_t>(done + m));
    if (!i.read(reinterpret_cast<char*>(v.data() + done), static_cast<std::streamsize>(m * sizeof(T))))
      throw InputError("checkpoint truncated (inside " + std::string(what) + " of " + std::to_string(n) + " elements)");
    done += m;
  }
}

}  // namespace nipdem::binary
