// How OpenMP threads wait at barriers, chosen by the program (docs/performance.md, "Threads on
// a shared machine"). libgomp spins ~300,000 iterations before it sleeps; when another job
// holds a core, a spinning barrier waits for a descheduled partner and 2 threads run slower
// than 1. libgomp reads its settings once, when it is loaded (before main), so the program
// re-executes itself once with the setting in its environment.
#pragma once
#include <string>

namespace nipdem {

// The policy nipdem runs with unless the user chose one: a waiting thread spins 10,000
// iterations (~0.1-0.3 ms), then sleeps. Measured (docs/performance.md, "Issue 18, tenth pass"):
// on free cores 2 threads run 1.88x (packing) and 1.84x (nip) of 1 thread against 1.64x and
// 1.20x with passive waits (a futex sleep and wake-up at each of a step's barriers); with one
// core taken the engine's thread choice (engine/team_tuner.hpp) runs 1 thread either way, and
// the spin costs nothing measurable there (1.000 vs 1.006 of 1 thread). Before that choice
// existed, long spins were ruinous under contention (20,000: 0.6x; libgomp's default ~300,000:
// 0.2-0.4x), which is why the spin is short.
inline constexpr const char* kWaitVariable = "GOMP_SPINCOUNT";
inline constexpr const char* kWaitPolicy = "10000";

// Unless OMP_WAIT_POLICY or GOMP_SPINCOUNT is set, sets kWaitVariable=kWaitPolicy and
// re-executes /proc/self/exe with argv (same pid, same open files). Returns only if nothing
// had to be done or the re-execution failed (then the run goes on with libgomp's default).
void apply_wait_policy(char** argv);

// The policy in force, for benchmark and run headers ("GOMP_SPINCOUNT=10000", ...).
std::string wait_policy();

}  // namespace nipdem
