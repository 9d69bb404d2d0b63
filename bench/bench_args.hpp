// "--key value" command-line parsing shared by the benchmark programs (not part of the library).
#pragma once
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <string>

namespace nipdem::bench {

// Every option takes one value; an unknown option or a missing value prints `usage` and exits 2.
inline void parse_args(int argc, char** argv, const std::string& usage,
                       const std::map<std::string, std::function<void(const std::string&)>>& options) {
  for (int a = 1; a < argc; ++a) {
    const auto it = options.find(argv[a]);
    if (it == options.end() || a + 1 >= argc) {
      std::fprintf(stderr, "%s%s\nusage: %s\n", it == options.end() ? "unknown option " : "missing value for ", argv[a], usage.c_str());
      std::exit(2);
    }
    it->second(argv[++a]);
  }
}

}  // namespace nipdem::bench
