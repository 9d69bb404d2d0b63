// Every CSV nipdem writes is framed by io::format_csv* (issue 19): per-column number formats,
// rows that grow one at a time, and cells formatted by the caller (a text column, a list).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "nipdem/io/csv.hpp"

using namespace nipdem;

TEST(CsvFormat, PerColumnFormatsCountsAndNan) {
  const std::string s = io::format_csv({"r", "removed", "speed_m_per_s"}, {{0.25, 12.0, 7.6e-4}, {3.0, -2.0, NAN}},
                                       {"{:.6g}", "{:.0f}", "{:.3g}"});
  EXPECT_EQ(s, "r,removed,speed_m_per_s\n0.25,12,0.00076\n3,-2,nan\n");
  // the shortest round-trip form by default, and the same framing row by row
  EXPECT_EQ(io::format_csv({"x"}, {{0.1}}), "x\n0.1\n");
  EXPECT_EQ(io::format_csv_header({"a", "b"}) + io::format_csv_row({1.5, 2.0}, {"{:.9g}", "{:.0f}"}), "a,b\n1.5,2\n");
  EXPECT_THROW(io::format_csv({"a", "b"}, {{1.0, 2.0}}, {"{}"}), std::invalid_argument);
  EXPECT_THROW(io::format_csv({"a", "b"}, {{1.0}}, {"{}", "{}"}), std::invalid_argument);
}

TEST(CsvFormat, CellsAreFramedAndCheckedNotFormatted) {
  EXPECT_EQ(io::format_csv_cells({"index", "exit", "starts_um"}, {{"0", "developed", "1.000;2.500"}, {"1", "", ""}}),
            "index,exit,starts_um\n0,developed,1.000;2.500\n1,,\n");
  EXPECT_THROW(io::format_csv_cells({"a"}, {{"1,2"}}), std::invalid_argument);  // a comma would shift the columns
  EXPECT_THROW(io::format_csv_cells({"a", "b"}, {{"1"}}), std::invalid_argument);
  EXPECT_THROW(io::format_csv_cells({"a,b"}, {}), std::invalid_argument);
}
