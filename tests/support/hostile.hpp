// What the hostile-input tests (tests/hostile/*.cpp, docs/reliability.md) share: a case is a
// command line and the words its stderr must contain; each is run under a time bound and must
// end with the expected status, no signal and no time-out. NIPDEM_HOSTILE_VERBOSE=1 prints every
// message for review.
#pragma once
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "../cli_run.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::test::hostile {

struct Case {
  std::string args;                  // after `nipdem`
  std::vector<std::string> needles;  // each must appear in stderr
};

// What every case of one call must show besides its needles.
struct Expect {
  int status = 2;              // exit status (2: invalid input)
  int bound_s = 60;            // wall-clock bound of one case [s]; beyond it the case is killed
  double max_seconds = 0.0;    // > 0: the case must also end within this [s]
  bool stdout_empty = false;   // nothing printed on stdout (no result of refused input)
  bool no_null = false;        // no JSON null on stdout
  std::size_t max_err = 0;     // > 0: stderr at most this many bytes (one short message)
};

// A fresh scratch folder named prefix + name + pid under the temp folder.
inline std::filesystem::path scratch(const std::string& prefix, const std::string& name) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / (prefix + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline std::string write(const std::filesystem::path& p, const std::string& text) {
  nipdem::io::write_file_atomic(p, text);
  return p.string();
}

inline void expect_cases(const std::vector<Case>& cases, const std::string& tag, const Expect& e = {}) {
  for (const auto& c : cases) {
    SCOPED_TRACE("nipdem " + c.args);
    const auto r = nipdem::test::run_cli_bounded(c.args, tag, e.bound_s);
    if (std::getenv("NIPDEM_HOSTILE_VERBOSE")) std::fprintf(stderr, "[%d] nipdem %s\n    %s", r.status, c.args.c_str(), r.err.c_str());
    EXPECT_FALSE(r.timed_out) << "hung (killed after " << e.bound_s << " s)";
    EXPECT_EQ(r.signal, 0) << "died of signal " << r.signal << ": " << r.err.substr(0, 500);
    EXPECT_EQ(r.status, e.status) << r.err.substr(0, 500) << "\nstdout: " << r.out.substr(0, 400);
    if (e.stdout_empty) EXPECT_TRUE(r.out.empty()) << "printed a result: " << r.out.substr(0, 300);
    if (e.no_null) EXPECT_EQ(r.out.find("null"), std::string::npos) << r.out.substr(0, 400);
    if (e.max_err > 0) EXPECT_LE(r.err.size(), e.max_err) << "message not one short line: " << r.err.substr(0, 300) << "...";
    for (const auto& n : c.needles)
      EXPECT_NE(r.err.find(n), std::string::npos) << "stderr does not name '" << n << "': " << r.err.substr(0, 500);
    if (e.max_seconds > 0.0) EXPECT_LT(r.seconds, e.max_seconds);
  }
}

}  // namespace nipdem::test::hostile
