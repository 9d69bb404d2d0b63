// An LDC setup file as `nipdem ldc solve` reads it (JSON when the text starts with '{', else
// TOML), then the solver's validation and — for a grid of at most 16 x 16 cells and 3 discs —
// a solve of at most 5 LDC iterations. (Larger setups are valid but slow: discs close together
// get finite-difference local problems of up to 4e5 fine nodes, 0.3 s each in a Release build and
// over 20 s under ASan on a loaded machine, which libFuzzer reports as a timeout.)
#include <algorithm>

#include "fuzz_common.hpp"
#include "nipdem/solvers/ldc/ldc_solver.hpp"
#include "nipdem/solvers/ldc/setup_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return nipdem::fuzz::run_one(data, size, [](const std::string& text) {
    const auto first = text.find_first_not_of(" \t\r\n");
    const bool is_toml = first == std::string::npos || text[first] != '{';
    auto setup = nipdem::ldc::parse_setup(text, is_toml ? "fuzz.toml" : "fuzz.json", is_toml);
    auto& p = setup.params;
    nipdem::ldc::validate(p);
    nipdem::ldc::validate_discs(p, setup.discs);
    if (p.cells_x > 16 || p.cells_y > 16 || setup.discs.size() > 3) return;
    p.max_iterations = std::min(p.max_iterations, 5);
    nipdem::ldc::LdcSolver solver(p);
    solver.solve(setup.discs);
    for (int k = 0; k < solver.disc_count(); ++k) (void)solver.force(k);
  });
}
