// Measured-record reading shared by the chapter-4 calibrations: every bad input names the file
// and the line (missing column, NaN, out of range, unsorted, empty, too few rows).
#include <gtest/gtest.h>

#include <string>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/calibrate_data.hpp"

using namespace nipdem;
using namespace nipdem::calibrate;

namespace {
const std::vector<ColumnSpec> kSpecs = {{"x_m"}, {"force_N", 0.0, 1e300, true}};

std::string error_of(const std::string& text, std::size_t min_rows = 2, bool sorted = true) {
  try {
    const Record r = parse_record(text, "rec.csv", kSpecs, min_rows);
    if (sorted) require_ascending(r, 0);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(CalibrationRecord, PicksColumnsByNameAndKeepsLines) {
  const Record r = parse_record("# comment\nforce_N,extra,x_m\n1.5,9,0\n\n2.5,9,1e-3\n", "rec.csv", kSpecs, 2);
  ASSERT_EQ(r.rows(), 2u);
  EXPECT_EQ(r.cols[0][1], 1e-3);
  EXPECT_EQ(r.cols[1][0], 1.5);
  EXPECT_EQ(r.lines[0], 3u);
  EXPECT_EQ(r.lines[1], 5u);
  EXPECT_EQ(r.where(1), "rec.csv:5");
}

TEST(CalibrationRecord, BadInputNamesFileLineAndColumn) {
  struct C { std::string text, needle; };
  for (const C& c : {C{"x_m,F\n0,1\n1,2\n", "rec.csv:1"},               // missing column: the header line
                     C{"x_m,force_N\n0,1\n1,nan\n", "rec.csv:3"},       // NaN on line 3
                     C{"x_m,force_N\n0,1\ninf,2\n", "rec.csv:3"},       // inf
                     C{"x_m,force_N\n0,1\n1,-2\n", "rec.csv:3"},        // out of range (force > 0)
                     C{"x_m,force_N\n0,1\n2,1\n1,1\n", "rec.csv:4"},    // unsorted: line 4 goes back
                     C{"x_m,force_N\n0,1\n0,1\n", "rec.csv:3"},         // repeated x
                     C{"", "rec.csv"},                                  // empty
                     C{"x_m,force_N\n", "no data rows"},                // header only
                     C{"x_m,force_N\n0,1\n", "last data line 2"},       // one row
                     C{"x_m,force_N\n0,1,3\n", "rec.csv:2"}}) {         // ragged row
    SCOPED_TRACE(c.text);
    const std::string e = error_of(c.text);
    EXPECT_NE(e.find("rec.csv"), std::string::npos) << e;
    EXPECT_NE(e.find(c.needle), std::string::npos) << e;
  }
  EXPECT_NE(error_of("x_m,force_N\n0,1\n1,-2\n").find("(0, inf)"), std::string::npos);  // names the allowed range
}

TEST(CalibrationRecord, FormatRoundTrips) {
  const Record r = parse_record("x_m,force_N\n0,1.25\n0.001,2.5\n", "a", kSpecs, 2);
  const std::string text = format_record(r, "synthetic\nsecond line");
  EXPECT_EQ(text.rfind("# synthetic\n# second line\n", 0), 0u);
  const Record s = parse_record(text, "b", kSpecs, 2);
  EXPECT_EQ(s.cols, r.cols);
}

TEST(CalibrationRecord, NormalQuantileMatchesKnownValues) {
  EXPECT_NEAR(normal_quantile(0.975), 1.959963984540054, 1e-10);  // tabulated z_0.975
  EXPECT_NEAR(normal_quantile(0.5), 0.0, 1e-12);
  EXPECT_NEAR(normal_quantile(0.1), -1.2815515655446004, 1e-10);
  EXPECT_THROW(normal_quantile(1.0), InputError);
}
