// How OpenMP threads wait at barriers, chosen by the program (docs/performance.md, "Threads on
// a shared machine"). libgomp spins ~300,000 iterations before it sleeps; when another job
// holds a core, a spinning barrier waits for a descheduled partner and 2 threads run slower
// than 1. libgomp reads its settings once, when it is loaded (before main), so the program
// re-executes itself once with the setting in its environment.
#pragma once
#include <string>

namespace nipdem {

// The GOMP_SPINCOUNT nipdem runs with unless the user chose a policy.
inline constexpr const char* kSpinCount = "20000";

// Unless OMP_WAIT_POLICY or GOMP_SPINCOUNT is set, sets GOMP_SPINCOUNT=kSpinCount and
// re-executes /proc/self/exe with argv (same pid, same open files). Returns only if nothing
// had to be done or the re-execution failed (then the run goes on with libgomp's default).
void apply_wait_policy(char** argv);

// The policy in force, for benchmark and run headers ("GOMP_SPINCOUNT=20000", ...).
std::string wait_policy();

}  // namespace nipdem
