// "--key value" command-line parsing shared by the benchmark programs (not part of the library).
#pragma once
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <exception>
#include <map>
#include <stdexcept>
#include <string>

namespace nipdem::bench {

// Numbers in full ("12abc", "", "abc" and out-of-range values throw std::invalid_argument or
// std::out_of_range): std::stol and friends alone accept a leading number and ignore the rest.
inline long to_long(const std::string& v) {
  std::size_t used = 0;
  const long x = std::stol(v, &used);
  if (used != v.size()) throw std::invalid_argument("not an integer");
  return x;
}
inline int to_int(const std::string& v) {
  const long x = to_long(v);
  if (x < -2147483647L || x > 2147483647L) throw std::out_of_range("out of the int range");
  return static_cast<int>(x);
}
inline double to_double(const std::string& v) {
  std::size_t used = 0;
  const double x = std::stod(v, &used);
  if (used != v.size()) throw std::invalid_argument("not a number");
  return x;
}

// A value below `lo` is refused (std::out_of_range), never raised to it.
template <class T> T at_least(T v, T lo) {
  if (v < lo) throw std::out_of_range("must be >= " + std::to_string(lo));
  return v;
}

// Every option takes one value; an unknown option, a missing value or a value its handler
// refuses (it throws: not a number, out of range) prints the reason and `usage` and exits 2.
inline void parse_args(int argc, char** argv, const std::string& usage,
                       const std::map<std::string, std::function<void(const std::string&)>>& options) {
  for (int a = 1; a < argc; ++a) {
    const auto it = options.find(argv[a]);
    if (it == options.end() || a + 1 >= argc) {
      std::fprintf(stderr, "%s%s\nusage: %s\n", it == options.end() ? "unknown option " : "missing value for ", argv[a], usage.c_str());
      std::exit(2);
    }
    const char* option = argv[a];
    const char* value = argv[++a];
    try {
      it->second(value);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: value '%s' not accepted (%s)\nusage: %s\n", option, value, e.what(), usage.c_str());
      std::exit(2);
    }
  }
}

}  // namespace nipdem::bench
