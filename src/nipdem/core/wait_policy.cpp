#include "nipdem/core/wait_policy.hpp"

#include <cstdlib>

#include <unistd.h>

namespace nipdem {

void apply_wait_policy(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  // The binary's own path (not /proc/self/exe itself, which would rename the process "exe" in
  // ps and top).
  char path[4096];
  const ssize_t len = readlink("/proc/self/exe", path, sizeof path - 1);
  if (len <= 0 || len >= static_cast<ssize_t>(sizeof path - 1)) return;
  path[len] = '\0';
  if (setenv(kWaitVariable, kWaitPolicy, 1) != 0) return;
  execv(path, argv);
  unsetenv(kWaitVariable);  // exec failed: go on with libgomp's default
}

std::string wait_policy() {
  std::string s;
  for (const char* k : {"OMP_WAIT_POLICY", "GOMP_SPINCOUNT"}) {
    if (const char* v = std::getenv(k)) s += (s.empty() ? "" : " ") + std::string(k) + "=" + v;
  }
  return s.empty() ? "libgomp default" : s;
}

}  // namespace nipdem
