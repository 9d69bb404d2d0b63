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

// Writes atomically (temp file then rename).
void write_csv(const std::filesystem::path& path, const std::vector<std::string>& columns,
               const std::vector<std::vector<double>>& rows);

// Parses CSV text; `source` names the origin in error messages.
CsvTable parse_csv(std::string_view text, const std::string& source);
// Reads and parses a file; a missing file is an InputError naming the path.
CsvTable read_csv(const std::filesystem::path& path);

}  // namespace nipdem::io
