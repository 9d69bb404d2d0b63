// How OpenMP threads wait at barriers, chosen by the program (docs/performance.md, "Threads on
// a shared machine"). libgomp spins ~300,000 iterations before it sleeps; when another job
// holds a core, a spinning barrier waits for a descheduled partner and 2 threads run slower
// than 1. libgomp reads its settings once, when it is loaded (before main), so the program
// re-executes itself once with the setting in its environment.
#pragma once
#include <string>

namespace nipdem {

// The policy nipdem runs with unless the user chose one: waiting threads sleep at once
// (measured under contention, docs/performance.md: 2 threads 1.2-1.7x of 1 thread passive,
// 1.0-1.3x with a 2,000 spin, 0.6x with 20,000, 0.2-0.4x spinning).
inline constexpr const char* kWaitPolicy = "passive";

// Unless OMP_WAIT_POLICY or GOMP_SPINCOUNT is set, sets OMP_WAIT_POLICY=kWaitPolicy and
// re-executes /proc/self/exe with argv (same pid, same open files). Returns only if nothing
// had to be done or the re-execution failed (then the run goes on with libgomp's default).
void apply_wait_policy(char** argv);

// The policy in force, for benchmark and run headers ("OMP_WAIT_POLICY=passive", ...).
std::string wait_policy();

}  // namespace nipdem
