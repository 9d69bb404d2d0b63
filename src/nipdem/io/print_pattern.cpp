#include "nipdem/io/print_pattern.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::io {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// --- PBM ---------------------------------------------------------------------------------
struct PbmReader {
  const std::string& b;
  const std::string& src;
  std::size_t pos = 0;
  void skip_ws_and_comments() {
    while (pos < b.size()) {
      const unsigned char c = static_cast<unsigned char>(b[pos]);
      if (c == '#') {
        while (pos < b.size() && b[pos] != '\n' && b[pos] != '\r') ++pos;
      } else if (std::isspace(c)) {
        ++pos;
      } else {
        break;
      }
    }
  }
  long header_int(const char* what) {
    skip_ws_and_comments();
    const std::size_t start = pos;
    while (pos < b.size() && std::isdigit(static_cast<unsigned char>(b[pos]))) ++pos;
    if (pos == start) {
      const std::string got = pos < b.size() ? b.substr(pos, std::min<std::size_t>(8, b.size() - pos)) : "end of file";
      throw_input(src, fmt::format("PBM header {}", what), got, "bad PBM header: expected a positive integer",
                  "1..100000");
    }
    const std::string digits = b.substr(start, pos - start);
    const long v = digits.size() > 7 ? 100000000L : std::stol(digits);
    if (v < 1 || v > 100000) throw_input(src, fmt::format("PBM header {}", what), digits, "bad PBM header", "1..100000");
    return v;
  }
};
}  // namespace

Bitmap parse_pbm(const std::string& bytes, const std::string& source) {
  if (bytes.size() < 2 || bytes[0] != 'P' || (bytes[1] != '1' && bytes[1] != '4')) {
    std::string magic;
    for (std::size_t i = 0; i < std::min<std::size_t>(2, bytes.size()); ++i)
      magic += std::isprint(static_cast<unsigned char>(bytes[i])) ? bytes[i] : '?';
    throw_input(source, "PBM magic", magic.empty() ? "(empty file)" : magic, "bad PBM header", "P1 (plain) or P4 (raw)");
  }
  const bool raw = bytes[1] == '4';
  PbmReader r{bytes, source, 2};
  if (r.pos < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[r.pos])) && bytes[r.pos] != '#')
    throw_input(source, "PBM magic", bytes.substr(0, std::min<std::size_t>(4, bytes.size())), "bad PBM header",
                "P1 or P4 followed by whitespace");
  Bitmap bmp;
  bmp.width = static_cast<int>(r.header_int("width"));
  bmp.height = static_cast<int>(r.header_int("height"));
  const std::size_t n = static_cast<std::size_t>(bmp.width) * bmp.height;
  if (n > 50'000'000) throw_input(source, "PBM size", fmt::format("{}x{}", bmp.width, bmp.height), "too large", "<= 5e7 pixels");
  bmp.pixels.assign(n, 0);
  if (raw) {
    if (r.pos >= bytes.size() || !std::isspace(static_cast<unsigned char>(bytes[r.pos])))
      throw_input(source, "PBM header", "", "bad PBM header: missing whitespace before raster", "one whitespace character");
    ++r.pos;
    const std::size_t row_bytes = (static_cast<std::size_t>(bmp.width) + 7) / 8;
    const std::size_t need = row_bytes * bmp.height;
    const std::size_t have = bytes.size() - r.pos;
    if (have != need)
      throw_input(source, "P4 raster", fmt::format("{} bytes", have),
                  fmt::format("wrong size for width {} x height {} (rows of {} bytes)", bmp.width, bmp.height, row_bytes),
                  fmt::format("exactly {} bytes", need));
    for (int y = 0; y < bmp.height; ++y)
      for (int x = 0; x < bmp.width; ++x) {
        const auto byte = static_cast<unsigned char>(bytes[r.pos + y * row_bytes + x / 8]);
        bmp.pixels[static_cast<std::size_t>(y) * bmp.width + x] = (byte >> (7 - x % 8)) & 1u;
      }
    return bmp;
  }
  // P1: '0'/'1' characters, whitespace and comments ignored. Lines are checked for the width
  // when the file is laid out one row per line (the usual case) so that a wrong width is
  // reported where it happens; the total count is always checked.
  std::size_t k = 0;
  int line = 1;
  std::vector<std::pair<int, std::size_t>> lines;  // (raster line number, pixels) of non-empty lines
  std::size_t line_count = 0;
  for (std::size_t i = r.pos; i < bytes.size(); ++i) {
    const char c = bytes[i];
    if (c == '#') {
      while (i + 1 < bytes.size() && bytes[i + 1] != '\n') ++i;
      continue;
    }
    if (c == '\n') {
      if (line_count > 0) lines.push_back({line, line_count});
      line_count = 0;
      ++line;
      continue;
    }
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    if (c != '0' && c != '1')
      throw_input(source, fmt::format("P1 pixel (raster line {})", line), std::string(1, c), "not a pixel", "0 or 1");
    if (k >= n)
      throw_input(source, "P1 raster", fmt::format("more than {} pixels", n),
                  fmt::format("wrong size for width {} x height {}", bmp.width, bmp.height), fmt::format("exactly {} pixels", n));
    bmp.pixels[k++] = static_cast<std::uint8_t>(c - '0');
    ++line_count;
  }
  if (line_count > 0) lines.push_back({line, line_count});
  // One row per line (the usual layout): check every row's width where it happens.
  if (static_cast<int>(lines.size()) == bmp.height)
    for (const auto& [ln, cnt] : lines)
      if (cnt != static_cast<std::size_t>(bmp.width))
        throw_input(source, fmt::format("P1 row width (raster line {})", ln), std::to_string(cnt),
                    "raster row does not match the header width", std::to_string(bmp.width));
  if (k != n)
    throw_input(source, "P1 raster", fmt::format("{} pixels", k), fmt::format("wrong size for width {} x height {}", bmp.width, bmp.height),
                fmt::format("exactly {} pixels", n));
  return bmp;
}

Bitmap read_pbm(const std::filesystem::path& path) { return parse_pbm(read_file(path), path.string()); }

// --- pattern -----------------------------------------------------------------------------
PrintPattern::PrintPattern(std::vector<PrintSegment> segments, double off_voltage_V, std::string where)
    : segs_(std::move(segments)), off_V_(off_voltage_V) {
  if (!std::isfinite(off_V_)) throw_input(where, "off_voltage_V", fmt::format("{:g}", off_V_), "must be finite");
  for (const auto& s : segs_) {
    if (!std::isfinite(s.begin_m) || !std::isfinite(s.end_m) || !(s.end_m > s.begin_m))
      throw_input(where, "segment", fmt::format("[{:g}, {:g}) m", s.begin_m, s.end_m), "empty or invalid interval",
                  "finite begin < end");
    if (!std::isfinite(s.voltage_V)) throw_input(where, "voltage_V", fmt::format("{:g}", s.voltage_V), "must be finite");
  }
  std::sort(segs_.begin(), segs_.end(), [](const PrintSegment& a, const PrintSegment& b) { return a.begin_m < b.begin_m; });
  for (std::size_t i = 1; i < segs_.size(); ++i)
    if (segs_[i].begin_m < segs_[i - 1].end_m)
      throw_input(where, "segments", fmt::format("[{:g}, {:g}) and [{:g}, {:g}) m", segs_[i - 1].begin_m, segs_[i - 1].end_m,
                                                 segs_[i].begin_m, segs_[i].end_m),
                  "lines overlap", "disjoint lines");
}

PrintPattern PrintPattern::none() { return PrintPattern(); }

PrintPattern PrintPattern::single_line(double start_m, double length_m, double voltage_V) {
  require_range("print", "start_m", start_m, -kInf, kInf);
  require_positive("print", "length_m", length_m);
  return PrintPattern({{start_m, start_m + length_m, voltage_V}});
}

PrintPattern PrintPattern::lines(const std::vector<double>& starts, const std::vector<double>& lengths, double V) {
  if (starts.size() != lengths.size())
    throw_input("print", "lengths_m", fmt::format("{} values", lengths.size()), "must match starts_m",
                fmt::format("{} values", starts.size()));
  std::vector<PrintSegment> s;
  for (std::size_t i = 0; i < starts.size(); ++i) {
    require_range("print", fmt::format("starts_m[{}]", i), starts[i], -kInf, kInf);
    require_positive("print", fmt::format("lengths_m[{}]", i), lengths[i]);
    s.push_back({starts[i], starts[i] + lengths[i], V});
  }
  return PrintPattern(std::move(s));
}

PrintPattern PrintPattern::from_bitmap_row(const Bitmap& bmp, int row, double pitch, double start, double V,
                                           const std::string& where) {
  if (row < 0 || row >= bmp.height)
    throw_input(where, "row", std::to_string(row), "outside the bitmap", fmt::format("0..{}", bmp.height - 1));
  require_positive(where, "pixel_pitch_m", pitch);
  require_range(where, "start_m", start, -kInf, kInf);
  std::vector<PrintSegment> s;
  for (int x = 0; x < bmp.width;) {
    if (!bmp.at(x, row)) { ++x; continue; }
    int e = x;
    while (e < bmp.width && bmp.at(e, row)) ++e;
    s.push_back({start + x * pitch, start + e * pitch, V});
    x = e;
  }
  return PrintPattern(std::move(s), 0.0, where);
}

double PrintPattern::voltage_at(double s) const {
  // first segment with end > s
  auto it = std::upper_bound(segs_.begin(), segs_.end(), s, [](double v, const PrintSegment& g) { return v < g.end_m; });
  if (it != segs_.end() && it->begin_m <= s) return it->voltage_V;
  return off_V_;
}

double PrintPattern::next_switch_after(double s) const {
  for (const auto& g : segs_) {
    if (g.begin_m > s) return g.begin_m;
    if (g.end_m > s) return g.end_m;
  }
  return kInf;
}

// --- TOML --------------------------------------------------------------------------------
namespace {
std::string node_text(const toml::node& n) {
  std::ostringstream os;
  if (auto s = n.as_string()) return "\"" + s->get() + "\"";
  n.visit([&](auto&& v) { os << v; });
  return os.str();
}

double get_number(const toml::table& t, const std::string& src, const std::string& key, double def, bool required,
                  double lo, double hi, const std::string& allowed) {
  const toml::node* n = t.get(key);
  if (!n) {
    if (required) throw_input(src, key, "(missing)", "required key", allowed);
    return def;
  }
  std::optional<double> v = n->value<double>();
  if (!v || !(n->is_floating_point() || n->is_integer()))
    throw_input(src, key, node_text(*n), "must be a number", allowed);
  if (!(*v >= lo && *v <= hi) || !std::isfinite(*v)) throw_input(src, key, node_text(*n), "out of range", allowed);
  return *v;
}

std::vector<double> get_array(const toml::table& t, const std::string& src, const std::string& key) {
  const toml::node* n = t.get(key);
  if (!n) throw_input(src, key, "(missing)", "required key", "array of numbers");
  const toml::array* a = n->as_array();
  if (!a) throw_input(src, key, node_text(*n), "must be an array", "array of numbers");
  std::vector<double> out;
  for (const auto& e : *a) {
    auto v = e.value<double>();
    if (!v || !(e.is_floating_point() || e.is_integer()))
      throw_input(src, key, node_text(*n), "must contain only numbers", "array of numbers");
    out.push_back(*v);
  }
  return out;
}
}  // namespace

PrintPattern pattern_from_toml(const toml::table& t, const std::string& src0, const std::filesystem::path& base_dir) {
  const std::string src = src0 + " [print]";
  const toml::node* pn = t.get("pattern");
  if (!pn) throw_input(src, "pattern", "(missing)", "required key", "\"line\", \"lines\", \"pbm\", \"none\"");
  auto pattern = pn->value<std::string>();
  if (!pattern) throw_input(src, "pattern", node_text(*pn), "must be a string", "\"line\", \"lines\", \"pbm\", \"none\"");
  std::set<std::string> allowed_keys{"pattern", "voltage_V", "off_voltage_V"};
  if (*pattern == "line") allowed_keys.insert({"start_m", "length_m"});
  else if (*pattern == "lines") allowed_keys.insert({"starts_m", "lengths_m", "start_m", "length_m", "period_m", "count"});
  else if (*pattern == "pbm") allowed_keys.insert({"file", "row", "pixel_pitch_m", "start_m", "width_px"});
  else if (*pattern != "none")
    throw_input(src, "pattern", node_text(*pn), "unknown pattern", "\"line\", \"lines\", \"pbm\", \"none\"");
  for (const auto& [k, v] : t) {
    const std::string key(k.str());
    if (!allowed_keys.count(key)) {
      std::string list;
      for (const auto& a : allowed_keys) list += (list.empty() ? "" : ", ") + a;
      throw_input(src, key, node_text(v), fmt::format("unknown key for pattern \"{}\"", *pattern), list);
    }
  }
  const double V = get_number(t, src, "voltage_V", 40.0, false, -1e4, 1e4, "[-1e4, 1e4] V");
  const double Voff = get_number(t, src, "off_voltage_V", 0.0, false, -1e4, 1e4, "[-1e4, 1e4] V");
  std::vector<PrintSegment> segs;
  if (*pattern == "line") {
    const double s0 = get_number(t, src, "start_m", 0.0, true, -1.0, 1.0, "[-1, 1] m");
    const double L = get_number(t, src, "length_m", 0.0, true, 1e-9, 1.0, "[1e-9, 1] m");
    segs.push_back({s0, s0 + L, V});
  } else if (*pattern == "lines") {
    if (t.get("starts_m") || t.get("lengths_m")) {
      const auto s = get_array(t, src, "starts_m");
      const auto l = get_array(t, src, "lengths_m");
      if (s.size() != l.size())
        throw_input(src, "lengths_m", fmt::format("{} values", l.size()), "must have as many values as starts_m",
                    fmt::format("{} values", s.size()));
      for (std::size_t i = 0; i < s.size(); ++i) {
        if (!(l[i] > 0.0) || !(l[i] <= 1.0))
          throw_input(src, fmt::format("lengths_m[{}]", i), fmt::format("{:g}", l[i]), "out of range", "(0, 1] m");
        if (!(std::fabs(s[i]) <= 1.0))
          throw_input(src, fmt::format("starts_m[{}]", i), fmt::format("{:g}", s[i]), "out of range", "[-1, 1] m");
        segs.push_back({s[i], s[i] + l[i], V});
      }
    } else {
      const double s0 = get_number(t, src, "start_m", 0.0, true, -1.0, 1.0, "[-1, 1] m");
      const double L = get_number(t, src, "length_m", 0.0, true, 1e-9, 1.0, "[1e-9, 1] m");
      const double P = get_number(t, src, "period_m", 0.0, true, 1e-9, 1.0, "(length_m, 1] m");
      const double n = get_number(t, src, "count", 1, true, 1, 1e5, "integer 1..100000");
      if (n != std::floor(n)) throw_input(src, "count", fmt::format("{:g}", n), "must be an integer", "1..100000");
      if (!(P > L)) throw_input(src, "period_m", fmt::format("{:g}", P), "lines would touch or overlap", "> length_m");
      for (int i = 0; i < static_cast<int>(n); ++i) segs.push_back({s0 + i * P, s0 + i * P + L, V});
    }
  } else if (*pattern == "pbm") {
    const toml::node* fn = t.get("file");
    if (!fn) throw_input(src, "file", "(missing)", "required key", "path of a P1/P4 PBM file");
    auto file = fn->value<std::string>();
    if (!file) throw_input(src, "file", node_text(*fn), "must be a string", "path of a P1/P4 PBM file");
    std::filesystem::path path(*file);
    if (path.is_relative()) path = base_dir / path;
    const Bitmap bmp = read_pbm(path);
    if (t.get("width_px")) {
      const double w = get_number(t, src, "width_px", 0, false, 1, 1e5, "integer 1..100000");
      if (w != bmp.width)
        throw_input(path.string(), "width", std::to_string(bmp.width),
                    fmt::format("bitmap width differs from width_px = {:g} in {}", w, src), fmt::format("{:g}", w));
    }
    const double row = get_number(t, src, "row", 0, false, 0, bmp.height - 1, fmt::format("integer 0..{}", bmp.height - 1));
    if (row != std::floor(row)) throw_input(src, "row", fmt::format("{:g}", row), "must be an integer", fmt::format("0..{}", bmp.height - 1));
    const double pitch = get_number(t, src, "pixel_pitch_m", kPixelPitch600dpi_m, false, 1e-7, 1e-2, "[1e-7, 1e-2] m");
    const double s0 = get_number(t, src, "start_m", 0.0, false, -1.0, 1.0, "[-1, 1] m");
    const PrintPattern p = PrintPattern::from_bitmap_row(bmp, static_cast<int>(row), pitch, s0, V, src);
    segs = p.segments();
  }
  return PrintPattern(std::move(segs), Voff, src);
}

PrintPattern load_print_pattern(const std::filesystem::path& file, const std::string& table_name) {
  const std::string text = read_file(file);
  toml::table root;
  try {
    root = toml::parse(text, file.string());
  } catch (const toml::parse_error& e) {
    throw_input(file.string(), "", "", fmt::format("TOML syntax error at line {}: {}", e.source().begin.line, e.description()));
  }
  const toml::node* n = root.get(table_name);
  if (!n || !n->is_table())
    throw_input(file.string(), "[" + table_name + "]", n ? "not a table" : "(missing)", "required table", "a [print] table");
  return pattern_from_toml(*n->as_table(), file.string(), file.parent_path());
}

}  // namespace nipdem::io
