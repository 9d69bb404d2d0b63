// Raw binary (de)serialisation for checkpoints: trivially copyable values and vectors of them,
// in the machine's byte order (a checkpoint is read back by the same build on the same kind of
// machine). Reads throw std::runtime_error on truncated or implausible data.
#pragma once
#include <cstdint>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace nipdem::binary {

template <class T> void put(std::ostream& o, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  o.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T> void put_vec(std::ostream& o, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  put(o, n);
  o.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
}
template <class T> void get(std::istream& i, T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  if (!i.read(reinterpret_cast<char*>(&v), sizeof(T))) throw std::runtime_error("checkpoint truncated");
}
template <class T> void get_vec(std::istream& i, std::vector<T>& v) {
  std::uint64_t n;
  get(i, n);
  if (n > (1ULL << 34)) throw std::runtime_error("checkpoint corrupt (vector size)");
  v.resize(n);
  if (!i.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T))))
    throw std::runtime_error("checkpoint truncated");
}

}  // namespace nipdem::binary
