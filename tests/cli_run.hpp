// Runs the nipdem executable (NIPDEM_CLI_PATH) with `args` and captures stdout, stderr and the
// exit status, for tests of the command-line contract (exit 2 on bad input, --json on stdout).
#pragma once
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include "nipdem/io/atomic_file.hpp"

namespace nipdem::test {

struct CliResult {
  int status;
  std::string out, err;
};

// Runs a shell command line (stderr captured to a file named by `tag`).
inline CliResult run_cli_command(const std::string& command, const std::string& tag) {
  const std::filesystem::path err =
      std::filesystem::temp_directory_path() / ("nipdem_" + tag + "_err_" + std::to_string(::getpid()));
  FILE* p = popen((command + " 2>" + err.string()).c_str(), "r");
  CliResult r{};
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.err = io::read_file(err);
  std::filesystem::remove(err);
  return r;
}

// `tag` keeps the stderr files of test files running in parallel apart.
inline CliResult run_cli(const std::string& args, const std::string& tag = "cli") {
  return run_cli_command(std::string(NIPDEM_CLI_PATH) + " " + args, tag);
}

// The same under a wall-clock bound (coreutils `timeout`, SIGKILL 2 s after SIGTERM), for
// hostile inputs that must end quickly: `timed_out` if the bound was hit, `signal` > 0 if the
// program died of a signal (timeout reports 128 + n), `seconds` the wall time taken.
struct BoundedResult : CliResult {
  bool timed_out = false;
  int signal = 0;
  double seconds = 0.0;
};
inline BoundedResult run_cli_bounded(const std::string& args, const std::string& tag, int seconds) {
  const auto t0 = std::chrono::steady_clock::now();
  const CliResult r = run_cli_command("timeout -k 2 " + std::to_string(seconds) + " " + std::string(NIPDEM_CLI_PATH) + " " + args, tag);
  BoundedResult b;
  static_cast<CliResult&>(b) = r;
  b.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  b.timed_out = r.status == 124 || r.status == 137;
  if (!b.timed_out && r.status > 128) b.signal = r.status - 128;
  if (r.status < 0) b.signal = -1;
  return b;
}

}  // namespace nipdem::test
