// The setup file of `nipdem ldc solve` (solvers/ldc/setup_file.hpp): every malformed value is an
// InputError naming the file and the key, never a json exception (exit 1) or a silently ignored key.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "nipdem/core/error.hpp"
#include "nipdem/solvers/ldc/setup_file.hpp"

namespace {
using nipdem::ldc::parse_setup;

TEST(LdcSetup, ReadsEveryKeyFromJsonAndToml) {
  const auto s = parse_setup(R"({"box": {"x_min_m": -1, "x_max_m": 2, "y_min_m": 0, "y_max_m": 3, "cells_x": 30, "cells_y": 40},
    "boundary": {"top": {"kind": "neumann"}, "left": {"value_V": 7}}, "permittivity_F_per_m": 2e-11,
    "local_radius_factor": 4, "safety_m": 0.01, "tolerance": 1e-6, "max_iterations": 9, "fd_refinement": 3,
    "discs": [{"x_m": 0.5, "y_m": 1.5, "radius_m": 0.1, "charge_C_per_m": 3e-12}]})",
                             "s.json", false);
  EXPECT_EQ(s.params.x_min_m, -1);
  EXPECT_EQ(s.params.y_max_m, 3);
  EXPECT_EQ(s.params.cells_x, 30);
  EXPECT_EQ(s.params.cells_y, 40);
  EXPECT_EQ(s.params.top.kind, nipdem::ldc::SideKind::neumann);
  EXPECT_EQ(s.params.left.value_V, 7);
  EXPECT_EQ(s.params.permittivity_F_per_m, 2e-11);
  EXPECT_EQ(s.params.local_radius_factor, 4);
  EXPECT_EQ(s.params.safety_m, 0.01);
  EXPECT_EQ(s.params.tolerance, 1e-6);
  EXPECT_EQ(s.params.max_iterations, 9);
  EXPECT_EQ(s.params.fd_refinement, 3);
  ASSERT_EQ(s.discs.size(), 1u);
  EXPECT_EQ(s.discs[0].center_m.y, 1.5);
  EXPECT_EQ(s.discs[0].charge_C_per_m, 3e-12);
  const auto t = parse_setup("[box]\ncells_x = 12\n[[discs]]\nx_m = 0.5\ny_m = 0.5\nradius_m = 0.1\n", "s.toml", true);
  EXPECT_EQ(t.params.cells_x, 12);
  ASSERT_EQ(t.discs.size(), 1u);
  EXPECT_EQ(t.discs[0].radius_m, 0.1);
}

TEST(LdcSetup, MalformedValuesNameFileAndKey) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"([1, 2])", "JSON object"},
      {R"({"box": 5, "discs": []})", "box"},
      {R"({"box": {"cells_x": 2.5}, "discs": []})", "box.cells_x"},
      {R"({"box": {"cells_x": 4294967296}, "discs": []})", "box.cells_x"},
      {R"({"box": {"cells_x": -4294967296}, "discs": []})", "box.cells_x"},
      {R"({"box": {"cell_x": 20}, "discs": []})", "box.cell_x"},  // misspelt: used to be ignored
      {R"({"boundary": {"top": 3}, "discs": []})", "boundary.top"},
      {R"({"boundary": {"top": {"kind": 3}}, "discs": []})", "boundary.top.kind"},  // was a json type_error
      {R"({"boundary": {"top": {"kind": "robin"}}, "discs": []})", "boundary.top.kind"},
      {R"({"boundary": {"up": {}}, "discs": []})", "boundary.up"},
      {R"({"tolerance": "small", "discs": []})", "tolerance"},
      {R"({"tolerence": 1e-6, "discs": []})", "tolerence"},
      {R"({"discs": {}})", "discs"},
      {R"({})", "discs"},
      {R"({"discs": [3]})", "discs[0]"},
      {R"({"discs": [{"x_m": 0.5}, {"radius": 1}]})", "discs[1].radius"},
      {R"({"discs": [{"x_m": null}]})", "discs[0].x_m"},
      {R"({"discs": [)", "invalid JSON"},
  };
  for (const auto& [text, key] : bad) {
    try {
      parse_setup(text, "bad.json", false);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const nipdem::InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("bad.json"), std::string::npos) << m;
      EXPECT_NE(m.find(key), std::string::npos) << text << " -> " << m;
    }
  }
  try {
    parse_setup("[box]\ncells_x = \"many\"\n", "bad.toml", true);
    ADD_FAILURE() << "accepted a string grid size";
  } catch (const nipdem::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.toml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("box.cells_x"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_setup("[box\n", "bad.toml", true), nipdem::InputError);
}
}  // namespace
