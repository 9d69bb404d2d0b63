// The setup file of `nipdem ldc solve` (JSON, or TOML with the same keys; keys in docs/ldc.md):
// solver parameters and discs. It lives in the library rather than in the command so that the
// fuzzer (fuzz/fuzz_ldc.cpp) reads setups exactly as the command does.
#pragma once
#include <string>
#include <vector>

#include "nipdem/solvers/ldc/problem.hpp"

namespace nipdem::ldc {

struct Setup {
  Params params;
  std::vector<Disc> discs;
};

// Parses `text` (TOML if is_toml, else JSON). Invalid syntax, an unknown side kind, a value of the
// wrong type (a number, an integer within int, an object, an array where one belongs) or a missing
// `discs` array is an InputError naming `where` and the key. The values' ranges are checked by
// validate() / validate_discs() (the solver calls them).
Setup parse_setup(const std::string& text, const std::string& where, bool is_toml);

}  // namespace nipdem::ldc
