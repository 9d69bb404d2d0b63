// Drum voltage pattern of one ring-electrode track (thesis §2.5.1: a track is at V = 40 V
// while a line is printed, 0 V otherwise).
//
// A track is one ring electrode, so at a given time the whole track has one voltage. The
// pattern is described along the drum surface: position s [m] is the arc length of drum
// surface that has passed the print reference line (the nip) since t = 0, so the track
// voltage at time t is voltage_at(s = v_drum * t). A pattern is a sorted list of disjoint
// "on" intervals [begin, end) with their voltage; outside them the track is at off_voltage.
//
// Sources: a single line, a sequence of lines, or one row of a 1-bit PBM bitmap (P1 or P4;
// 1 = print) mapped onto s with a pixel pitch. Config (one TOML table, e.g. [print]):
//   pattern = "line" | "lines" | "pbm" | "none"
//   voltage_V = 40.0        # on voltage [V]
//   off_voltage_V = 0.0     # [V]
//   line:  start_m, length_m                       (length > 0)
//   lines: starts_m = [...], lengths_m = [...]     (same length; or start_m, length_m,
//                                                   period_m, count for a regular sequence)
//   pbm:   file (relative to the config file), row = 0, pixel_pitch_m (default 600 dpi),
//          start_m = 0, width_px (optional check of the bitmap width)
// Errors (bad PBM header, wrong width, unknown/invalid keys) throw InputError naming the
// file, key, value and allowed range.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <toml++/toml.h>
#include <vector>

namespace nipdem::io {

struct Bitmap {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;  // row-major, 1 = black (print)
  bool at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x] != 0; }
};

// Parses a PBM (P1 plain or P4 raw). `source` names the file in error messages.
Bitmap parse_pbm(const std::string& bytes, const std::string& source);
Bitmap read_pbm(const std::filesystem::path& path);

struct PrintSegment {
  double begin_m = 0.0, end_m = 0.0;  // drum surface positions [m], begin < end
  double voltage_V = 0.0;
};

class PrintPattern {
 public:
  PrintPattern() = default;
  // Segments may be unsorted but must not overlap; throws InputError otherwise.
  PrintPattern(std::vector<PrintSegment> segments, double off_voltage_V = 0.0, std::string where = "print");

  static PrintPattern none();
  static PrintPattern single_line(double start_m, double length_m, double voltage_V = 40.0);
  static PrintPattern lines(const std::vector<double>& starts_m, const std::vector<double>& lengths_m,
                            double voltage_V = 40.0);
  // Pixel k of `row` covers [start + k pitch, start + (k+1) pitch); runs of 1s merge.
  static PrintPattern from_bitmap_row(const Bitmap& bmp, int row, double pixel_pitch_m, double start_m = 0.0,
                                      double voltage_V = 40.0, const std::string& where = "print");

  // Track voltage [V] when drum surface position s [m] is at the nip.
  double voltage_at(double s_m) const;
  // Track voltage at time t [s] for drum surface speed v [m/s] (s = v t).
  double voltage_at_time(double t_s, double drum_speed_m_per_s) const { return voltage_at(drum_speed_m_per_s * t_s); }
  // Next position > s where the voltage changes (inf if none): lets the engine land a time
  // step on a switching edge.
  double next_switch_after(double s_m) const;

  const std::vector<PrintSegment>& segments() const { return segs_; }
  double off_voltage() const { return off_V_; }

 private:
  std::vector<PrintSegment> segs_;
  double off_V_ = 0.0;
};

// Builds a pattern from a TOML table (see above). `source` is the config file name used in
// messages; relative PBM paths are resolved against `base_dir`.
PrintPattern pattern_from_toml(const toml::table& print, const std::string& source,
                               const std::filesystem::path& base_dir);
// Reads `file` and builds the pattern of its table `table_name` (default [print]).
PrintPattern load_print_pattern(const std::filesystem::path& file, const std::string& table_name = "print");

inline constexpr double kPixelPitch600dpi_m = 0.0254 / 600.0;

}  // namespace nipdem::io
