#include "nipdem/experiments/calibrate_data.hpp"

#include <cmath>
#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::calibrate {

std::string Record::where(std::size_t i) const { return fmt::format("{}:{}", source, lines.at(i)); }

namespace {
std::string range_text(const ColumnSpec& s) {
  const std::string lo = s.lo <= -1e300 ? "(-inf" : fmt::format("{}{:g}", s.lo_open ? "(" : "[", s.lo);
  const std::string hi = s.hi >= 1e300 ? "inf)" : fmt::format("{:g}]", s.hi);
  return lo + ", " + hi;
}
}  // namespace

Record make_record(const io::CsvTable& t, const std::vector<ColumnSpec>& specs, std::size_t min_rows) {
  Record r;
  r.source = t.source;
  r.lines = t.lines;
  std::string wanted;
  for (const auto& s : specs) wanted += (wanted.empty() ? "" : ",") + s.name;
  for (const auto& s : specs) {
    if (!t.has_column(s.name))
      throw_input(fmt::format("{}:{}", t.source, t.header_line), "column", "'" + s.name + "'",
                  "missing from the header", "a header naming " + wanted);
    r.names.push_back(s.name);
    r.cols.push_back(t.column(s.name));
  }
  for (std::size_t j = 0; j < specs.size(); ++j) {
    const ColumnSpec& s = specs[j];
    for (std::size_t i = 0; i < r.rows(); ++i) {
      const double v = r.cols[j][i];
      const bool ok = std::isfinite(v) && (s.lo_open ? v > s.lo : v >= s.lo) && v <= s.hi;
      if (!ok)
        throw_input(r.where(i), s.name, fmt::format("{:g}", v), std::isfinite(v) ? "out of range" : "not a finite number",
                    range_text(s));
    }
  }
  if (r.rows() < min_rows)
    throw_input(t.source, "rows", std::to_string(r.rows()),
                r.rows() == 0 ? "no data rows after the header"
                              : fmt::format("too few data rows (last data line {})", r.lines.back()),
                fmt::format(">= {}", min_rows));
  return r;
}

Record parse_record(std::string_view text, const std::string& source, const std::vector<ColumnSpec>& specs,
                    std::size_t min_rows) {
  return make_record(io::parse_csv(text, source), specs, min_rows);
}

Record read_record(const std::filesystem::path& path, const std::vector<ColumnSpec>& specs, std::size_t min_rows) {
  return make_record(io::read_csv(path), specs, min_rows);
}

std::string format_record(const Record& r, const std::string& comment) {
  std::string out;
  std::size_t b = 0;
  while (b < comment.size()) {
    auto e = comment.find('\n', b);
    if (e == std::string::npos) e = comment.size();
    out += "# " + comment.substr(b, e - b) + "\n";
    b = e + 1;
  }
  std::vector<std::vector<double>> rows(r.rows(), std::vector<double>(r.cols.size()));
  for (std::size_t j = 0; j < r.cols.size(); ++j)
    for (std::size_t i = 0; i < r.rows(); ++i) rows[i][j] = r.cols[j][i];
  return out + io::format_csv(r.names, rows);
}

void require_ascending(const Record& r, std::size_t j, bool strict) {
  for (std::size_t i = 1; i < r.rows(); ++i) {
    const double a = r.cols[j][i - 1], b = r.cols[j][i];
    if (strict ? !(b > a) : !(b >= a))
      throw_input(r.where(i), r.names[j], fmt::format("{:g}", b),
                  fmt::format("not {} the previous row's {:g} (line {}): the record must be in measurement order",
                              strict ? "above" : "at least", a, r.lines[i - 1]),
                  strict ? "strictly increasing" : "non-decreasing");
  }
}

MeanStd mean_std(const std::vector<double>& v) {
  MeanStd m;
  if (v.empty()) return m;
  for (double x : v) m.mean += x;
  m.mean /= static_cast<double>(v.size());
  if (v.size() < 2) return m;
  double s = 0;
  for (double x : v) s += (x - m.mean) * (x - m.mean);
  m.std = std::sqrt(s / static_cast<double>(v.size() - 1));
  return m;
}

double normal_quantile(double p) {
  if (!(p > 0.0 && p < 1.0)) throw_input("normal quantile", "p", fmt::format("{:g}", p), "out of range", "(0, 1)");
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 200 && hi - lo > 1e-13; ++i) {
    const double z = 0.5 * (lo + hi);
    if (0.5 * std::erfc(-z / std::sqrt(2.0)) < p) lo = z; else hi = z;
  }
  return 0.5 * (lo + hi);
}

}  // namespace nipdem::calibrate
