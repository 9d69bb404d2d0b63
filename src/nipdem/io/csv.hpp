// Small numeric CSV tables: one header line of column names (units in the names, e.g.
// "x_m", "coverage"), then rows of numbers. Used for coverage curves, sweep results and
// measured data (`calibrate rc --data FILE.csv`).
//
// Reading is strict: a ragged row or a non-numeric cell is an InputError naming the file,
// the line (1-based, counting the header) and the column (1-based and by name).
// Empty lines and lines starting with '#' are skipped; cells are trimmed; CRLF is accepted.
// Writing goes through write_file_atomic, numbers in shortest round-trip form.
#pragma once
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace nipdem::io {

struct CsvTable {
  std::string source;                      // file name (or label) used in messages
  std::vector<std::string> columns;        // header names
  std::vector<std::vector<double>> rows;   // rows[i].size() == columns.size()
  std::vector<std::size_t> lines;          // lines[i]: 1-based file line of rows[i] (filled by parse_csv)
  std::size_t header_line = 0;             // 1-based file line of the header (parse_csv)

  // Index of column `name`; throws InputError naming the source and the available columns.
  std::size_t column_index(const std::string& name) const;
  // All values of column `name` (throws like column_index).
  std::vector<double> column(const std::string& name) const;
  bool has_column(const std::string& name) const;
};

// Formats a header and rows as CSV text. Throws std::invalid_argument on a ragged row
// (a programming error, not user input).
std::string format_csv(const std::vector<std::string>& columns, const std::vector<std::vector<double>>& rows);
// Same from columns of equal length: data[j] is column j.
std::string format_csv_columns(const std::vector<std::string>& columns, const std::vector<std::vector<double>>& data);

// Same with one fmt format per column, e.g. "{:.6g}", "{:.0f}" for a count; "{}" is the
// shortest round-trip form. NaN is written "nan".
std::string format_csv(const std::vector<std::string>& columns, const std::vector<std::vector<double>>& rows,
                       const std::vector<std::string>& formats);
// The header line, and one row of numbers (formats as above), for a file that grows row by row.
std::string format_csv_header(const std::vector<std::string>& columns);
std::string format_csv_row(const std::vector<double>& values, const std::vector<std::string>& formats);
// Cells already formatted (a text column, an empty cell, a list within a cell): the header and
// the framing only. A cell must not hold a comma or a newline.
std::string format_csv_cells(const std::vector<std::string>& columns, const std::vector<std::vector<std::string>>& rows);

// Writes atomically (temp file then rename).
void write_csv(const std::filesystem::path& path, const std::vector<std::string>& columns,
               const std::vector<std::vector<double>>& rows);
void write_csv(const std::filesystem::path& path, const std::vector<std::string>& columns,
               const std::vector<std::vector<double>>& rows, const std::vector<std::string>& formats);

// Parses CSV text; `source` names the origin in error messages.
CsvTable parse_csv(std::string_view text, const std::string& source);
// Reads and parses a file; a missing file is an InputError naming the path.
CsvTable read_csv(const std::filesystem::path& path);

}  // namespace nipdem::io
