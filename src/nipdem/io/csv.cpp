#include "nipdem/io/csv.hpp"

#include <charconv>
#include <fmt/format.h>
#include <stdexcept>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::io {

namespace {

std::string_view trim(std::string_view s) {
  const auto ws = " \t\r\n";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(ws);
  return s.substr(b, e - b + 1);
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const auto pos = line.find(',', start);
    if (pos == std::string_view::npos) {
      cells.push_back(trim(line.substr(start)));
      break;
    }
    cells.push_back(trim(line.substr(start, pos - start)));
    start = pos + 1;
  }
  return cells;
}

std::string join_columns(const std::vector<std::string>& cols) {
  std::string s;
  for (std::size_t i = 0; i < cols.size(); ++i) s += (i ? ", " : "") + cols[i];
  return s;
}

}  // namespace

std::size_t CsvTable::column_index(const std::string& name) const {
  for (std::size_t j = 0; j < columns.size(); ++j)
    if (columns[j] == name) return j;
  throw InputError(input_message(source, "column", "'" + name + "'", "no such column in the header",
                                 join_columns(columns)));
}

bool CsvTable::has_column(const std::string& name) const {
  for (const auto& c : columns)
    if (c == name) return true;
  return false;
}

std::vector<double> CsvTable::column(const std::string& name) const {
  const std::size_t j = column_index(name);
  std::vector<double> v;
  v.reserve(rows.size());
  for (const auto& r : rows) v.push_back(r[j]);
  return v;
}

namespace {
std::string header_line(const std::vector<std::string>& columns, const char* who) {
  std::string out;
  for (std::size_t j = 0; j < columns.size(); ++j) {
    if (columns[j].find_first_of(",\n\r") != std::string::npos)
      throw std::invalid_argument(std::string(who) + ": column name '" + columns[j] + "' contains a comma or newline");
    out += (j ? "," : "") + columns[j];
  }
  return out + '\n';
}
}  // namespace

std::string format_csv_cells(const std::vector<std::string>& columns, const std::vector<std::vector<std::string>>& rows) {
  std::string out = header_line(columns, "format_csv_cells");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != columns.size())
      throw std::invalid_argument(fmt::format("format_csv_cells: row {} has {} values, header has {}", i, rows[i].size(), columns.size()));
    for (std::size_t j = 0; j < rows[i].size(); ++j) {
      if (rows[i][j].find_first_of(",\n\r") != std::string::npos)
        throw std::invalid_argument(fmt::format("format_csv_cells: row {} column '{}' holds a comma or newline", i, columns[j]));
      if (j) out += ',';
      out += rows[i][j];
    }
    out += '\n';
  }
  return out;
}

std::string format_csv_header(const std::vector<std::string>& columns) { return header_line(columns, "format_csv"); }

std::string format_csv_row(const std::vector<double>& values, const std::vector<std::string>& formats) {
  if (formats.size() != values.size())
    throw std::invalid_argument(fmt::format("format_csv_row: {} formats for {} values", formats.size(), values.size()));
  std::string out;
  for (std::size_t j = 0; j < values.size(); ++j) {
    if (j) out += ',';
    out += fmt::format(fmt::runtime(formats[j]), values[j]);
  }
  return out + '\n';
}

std::string format_csv(const std::vector<std::string>& columns, const std::vector<std::vector<double>>& rows,
                       const std::vector<std::string>& formats) {
  if (formats.size() != columns.size())
    throw std::invalid_argument(fmt::format("format_csv: {} formats for {} columns", formats.size(), columns.size()));
  std::string out = header_line(columns, "format_csv");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != columns.size())
      throw std::invalid_argument(fmt::format("format_csv: row {} has {} values, header has {}", i, rows[i].size(),
                                              columns.size()));
    out += format_csv_row(rows[i], formats);
  }
  return out;
}

std::string format_csv(const std::vector<std::string>& columns, const std::vector<std::vector<double>>& rows) {
  return format_csv(columns, rows, std::vector<std::string>(columns.size(), "{}"));
}

std::string format_csv_columns(const std::vector<std::string>& columns, const std::vector<std::vector<double>>& data) {
  if (data.size() != columns.size())
    throw std::invalid_argument("format_csv_columns: number of data columns differs from header");
  const std::size_t n = data.empty() ? 0 : data[0].size();
  std::vector<std::vector<double>> rows(n, std::vector<double>(columns.size()));
  for (std::size_t j = 0; j < data.size(); ++j) {
    if (data[j].size() != n) throw std::invalid_argument("format_csv_columns: columns of unequal length");
    for (std::size_t i = 0; i < n; ++i) rows[i][j] = data[j][i];
  }
  return format_csv(columns, rows);
}

void write_csv(const std::filesystem::path& path, const std::vector<std::string>& columns,
               const std::vector<std::vector<double>>& rows) {
  write_file_atomic(path, format_csv(columns, rows));
}

void write_csv(const std::filesystem::path& path, const std::vector<std::string>& columns,
               const std::vector<std::vector<double>>& rows, const std::vector<std::string>& formats) {
  write_file_atomic(path, format_csv(columns, rows, formats));
}

CsvTable parse_csv(std::string_view text, const std::string& source) {
  CsvTable t;
  t.source = source;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  bool have_header = false;
  while (pos <= text.size()) {
    auto nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    const std::string_view raw = text.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    const std::string_view line = trim(raw);
    if (line.empty() || line.front() == '#') {
      if (nl == text.size()) break;
      continue;
    }
    auto cells = split(line);
    const std::string where = fmt::format("{}:{}", source, line_no);
    if (!have_header) {
      for (std::size_t j = 0; j < cells.size(); ++j) {
        if (cells[j].empty())
          throw InputError(input_message(where, "", "", fmt::format("header column {} has an empty name", j + 1)));
        t.columns.emplace_back(cells[j]);
      }
      have_header = true;
      t.header_line = line_no;
    } else {
      if (cells.size() != t.columns.size())
        throw InputError(input_message(where, "", "",
                                       fmt::format("row has {} cells but the header has {} columns ({})",
                                                   cells.size(), t.columns.size(), join_columns(t.columns))));
      std::vector<double> row(cells.size());
      for (std::size_t j = 0; j < cells.size(); ++j) {
        const std::string_view c = cells[j];
        double v = 0.0;
        const char* b = c.data();
        const char* e = c.data() + c.size();
        if (!c.empty() && *b == '+') ++b;  // from_chars rejects a leading '+'
        const auto res = std::from_chars(b, e, v);
        if (c.empty() || res.ec != std::errc() || res.ptr != e)
          throw InputError(input_message(where, fmt::format("{} (column {})", t.columns[j], j + 1),
                                         "'" + std::string(c) + "'", "not a number"));
        row[j] = v;
      }
      t.rows.push_back(std::move(row));
      t.lines.push_back(line_no);
    }
    if (nl == text.size()) break;
  }
  if (!have_header) throw InputError(input_message(source, "", "", "empty CSV: no header line"));
  return t;
}

CsvTable read_csv(const std::filesystem::path& path) { return parse_csv(read_file(path), path.string()); }

}  // namespace nipdem::io
