// Small Cairo PNG plots of XY data for experiment reports: several series (lines and/or
// markers, optional vertical error bars), axes with "nice" ticks, labels with units,
// title, legend (placed in the corner hiding the fewest points), optional log axes.
//
// Example (front position vs gap):
//   io::PlotSpec p;
//   p.title = "Front position, black unit";
//   p.x_label = "gap w_h [µm]";  p.y_label = "front position [µm]";
//   p.series.push_back({.label = "simulation", .x = gaps, .y = fronts, .y_err = stds,
//                       .line = true, .markers = true});
//   io::write_plot_png("front.png", p);
//
// The PNG is rendered to "<path>.tmp.<pid>.<n>.png" and renamed over <path>, so a reader
// never sees a half-written image. Bad input (x/y length mismatch, non-positive values on a
// log axis, empty plot) is an InputError naming the series; NaN points are skipped (a gap
// in the line), never clamped.
#pragma once
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace nipdem::io {

struct Series {
  std::string label;              // legend entry; empty = not in the legend
  std::vector<double> x;
  std::vector<double> y;
  std::vector<double> y_err;      // empty, or same size as y: symmetric error bar half-length
  bool line = true;               // connect points
  // Connect them only if the data resolve a trend: some neighbouring pair differs by more than
  // their combined error bars (sqrt(e_i^2 + e_j^2)); otherwise markers only.
  bool line_only_if_resolved = false;
  bool markers = false;           // draw a marker at each point
  bool dashed = false;
  double line_width = 1.8;        // [px]
  double marker_size = 4.0;       // marker half-size [px]
  std::optional<std::array<double, 3>> color;  // RGB in [0,1]; default from a palette
};

// A colour map drawn under the series (linear axes only): z[j * nx + i] is the value of the cell
// centred at (x[i], y[j]); x and y strictly increasing, at least 2 each; cell edges lie halfway
// between centres. NaN cells stay blank. Colours are diverging (blue < 0 < red, white at 0), made
// for signed data such as a net force; the limits default to +-max|z|, each side of zero is scaled
// to its own limit, and values beyond given limits take the end colours (display only; a tick at
// a limit is labelled "<=" / ">="). A colour bar labelled `z_label` (with unit) is drawn right of
// the plot.
struct Heatmap {
  std::vector<double> x, y, z;
  std::string z_label;
  std::optional<double> z_min, z_max;  // z_min < 0 < z_max when given
};

struct PlotSpec {
  std::string title;
  std::string x_label;            // with unit, e.g. "gap w_h [µm]"
  std::string y_label;
  int width = 800;                // [px]
  int height = 560;               // [px]
  bool log_x = false;
  bool log_y = false;
  std::optional<double> x_min, x_max, y_min, y_max;  // axis limits (default: data range)
  bool legend = true;
  std::vector<Series> series;
  std::optional<Heatmap> heatmap;  // drawn first; a plot may have a heat map and no series
};

// Renders `spec` and writes a PNG atomically. Throws InputError on bad data, std::runtime_error
// if Cairo or the file system fails.
void write_plot_png(const std::filesystem::path& path, const PlotSpec& spec);

// Whether `series` is drawn with a connecting line (line, and line_only_if_resolved's rule).
bool draws_line(const Series& series);

// Axis or legend text for a CSV column named with its unit suffix, shown multiplied by
// `scale`: "front_std_m" with 1e6 -> "front std [µm]", "coverage" -> "coverage".
std::string column_words(const std::string& column, double scale = 1.0);

// Diverging colour for t in [-1, 1] (clamped for display): blue at -1, white at 0, red at +1.
std::array<double, 3> diverging_colour(double t);

// Tick positions: "nice" values (1, 2, 2.5, 5 x 10^k) covering [lo, hi] with about
// `target` intervals. Exposed for tests.
std::vector<double> nice_ticks(double lo, double hi, int target = 6);
// Log-axis ticks in [lo, hi] (lo > 0): powers of ten, plus 2 and 5 per decade when the range
// spans fewer than three decades.
std::vector<double> log_ticks(double lo, double hi);
// Tick label text: shortest readable form ("0.25", "1e-06", "150").
std::string tick_label(double v, double step);
// Labels for a whole axis, consistent in format: fixed decimals for ordinary ranges, one
// common exponent ("-1.5e-4", "-2.0e-4") for tiny or huge values, "%g" on log axes.
std::vector<std::string> tick_labels(const std::vector<double>& ticks, bool log);

}  // namespace nipdem::io
