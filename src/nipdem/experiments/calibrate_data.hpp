// Measured records for the chapter-4 calibrations (friction §4.3, adhesion §4.4,
// magnetisation §4.5): strict reading of a CSV with named columns, and the checks every
// calibration needs. Each failure is an InputError naming the file, the line (1-based, as
// io::CsvTable counts it), the column, the value and the allowed range (CLI exit 2).
// Shared here so that the three calibrations word their input errors the same way.
#pragma once
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "nipdem/io/csv.hpp"

namespace nipdem::calibrate {

// One required column and its allowed values [lo, hi]; `lo_open` excludes lo itself.
struct ColumnSpec {
  std::string name;
  double lo = -1e300, hi = 1e300;
  bool lo_open = false;
};

// Columns picked out of a CSV, each value checked finite and in range.
struct Record {
  std::string source;                     // file name used in messages
  std::vector<std::string> names;         // = the specs' names
  std::vector<std::vector<double>> cols;  // cols[j][i]: column j, row i
  std::vector<std::size_t> lines;         // file line of row i
  std::size_t rows() const { return lines.size(); }
  // "file:line" of row i.
  std::string where(std::size_t i) const;
};

// Picks `specs` out of `table` (extra columns are ignored). Throws InputError for a missing
// column (naming the header line and the columns present), a non-finite or out-of-range value
// (naming its line and column) and fewer than `min_rows` data rows.
Record make_record(const io::CsvTable& table, const std::vector<ColumnSpec>& specs, std::size_t min_rows);
Record read_record(const std::filesystem::path& path, const std::vector<ColumnSpec>& specs, std::size_t min_rows);
Record parse_record(std::string_view text, const std::string& source, const std::vector<ColumnSpec>& specs,
                    std::size_t min_rows);

// CSV text of a record: `comment` (each line prefixed with "# "), then the header and rows.
std::string format_record(const Record& r, const std::string& comment);

// Throws InputError naming the first line where column j does not increase (strictly, or
// non-decreasing when `strict` is false), for records whose order carries meaning.
void require_ascending(const Record& r, std::size_t j, bool strict = true);

// Mean and sample standard deviation (n - 1) of v (v.size() >= 2 for the deviation; 0 otherwise).
struct MeanStd {
  double mean = 0, std = 0;
};
MeanStd mean_std(const std::vector<double>& v);

// Standard normal quantile z with Phi(z) = p, 0 < p < 1 (bisection on erfc, |error| < 1e-12).
double normal_quantile(double p);

}  // namespace nipdem::calibrate
