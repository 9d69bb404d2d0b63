// Runs the nipdem executable (NIPDEM_CLI_PATH) with `args` and captures stdout, stderr and the
// exit status, for tests of the command-line contract (exit 2 on bad input, --json on stdout).
#pragma once
#include <array>
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

// `tag` keeps the stderr files of test files running in parallel apart.
inline CliResult run_cli(const std::string& args, const std::string& tag = "cli") {
  const std::filesystem::path err =
      std::filesystem::temp_directory_path() / ("nipdem_" + tag + "_err_" + std::to_string(::getpid()));
  FILE* p = popen((std::string(NIPDEM_CLI_PATH) + " " + args + " 2>" + err.string()).c_str(), "r");
  CliResult r{};
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.err = io::read_file(err);
  std::filesystem::remove(err);
  return r;
}

}  // namespace nipdem::test
