// `nipdem plot DATA.csv --x COL --y COL[,COL...] --out FILE.png`: quick PNG of CSV columns
// (front position vs gap, coverage curves, reduction counts vs r ...). Column names are the
// CSV header names (with their unit suffix); axis labels and legend entries default to them in
// words with the unit (io::column_words: "front_std_m" with --yscale 1e6 -> "front std [µm]").
#include <cmath>
#include <cstdio>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>

#include "nipdem/core/error.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"
#include "registry.hpp"

namespace {

// Largest magnitude drawn: the axis range (with its padding) of values up to this stays finite.
constexpr double kMaxPlotted = 1e300;
// --xscale / --yscale: non-zero (0 collapses the axis) and not absurd.
constexpr double kMinScale = 1e-30, kMaxScale = 1e30;

void check_scale(const char* key, double s) {
  if (!(std::abs(s) >= kMinScale && std::abs(s) <= kMaxScale))
    nipdem::throw_input("plot", key, fmt::format("{:g}", s), "out of range",
                        fmt::format("{:g} <= |{}| <= {:g} (negative flips the axis)", kMinScale, key, kMaxScale));
}

// Multiplies column `col` of `t` by `scale` (option `key`); a finite value that the scale takes
// beyond +-kMaxPlotted (or that is already beyond it) cannot be drawn: refused naming the file,
// line, column and option. Non-finite values stay non-finite (gaps in the line).
std::vector<double> scaled_column(const nipdem::io::CsvTable& t, const std::string& col, double scale, const char* key) {
  std::vector<double> v = t.column(col);
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double s = v[i] * scale;
    if (std::isfinite(v[i]) && !(std::abs(s) <= kMaxPlotted))
      nipdem::throw_input(fmt::format("{}:{}", t.source, i < t.lines.size() ? t.lines[i] : i + 2),
                          scale == 1.0 ? fmt::format("column '{}'", col) : fmt::format("column '{}' x {}", col, key),
                          scale == 1.0 ? fmt::format("{:g}", v[i]) : fmt::format("{:g} x {:g}", v[i], scale), "too large to draw",
                          scale == 1.0 ? fmt::format("|value| <= {:g}", kMaxPlotted) : fmt::format("|value x {}| <= {:g}", key, kMaxPlotted));
    v[i] = s;
  }
  return v;
}

struct Opts {
  std::string data, x, out, title, xlabel, ylabel;
  std::vector<std::string> y, yerr, labels;
  bool logx = false, logy = false, markers = false, no_lines = false, json = false;
  int width = 800, height = 560;
  double xscale = 1.0, yscale = 1.0;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* sub = app.add_subcommand("plot", "Plot columns of a CSV file to a PNG");
  auto o = std::make_shared<Opts>();
  sub->add_option("data", o->data, "CSV file with a header line")->required();
  sub->add_option("--x", o->x, "column for the horizontal axis")->required();
  sub->add_option("--y", o->y, "column(s) to plot, comma separated")->required()->delimiter(',');
  sub->add_option("--yerr", o->yerr, "error-bar column(s), one per --y column")->delimiter(',');
  sub->add_option("--out", o->out, "output PNG")->required();
  sub->add_option("--title", o->title, "plot title");
  sub->add_option("--labels", o->labels, "legend entries, one per --y column, comma separated (default: the columns in words)")->delimiter(',');
  sub->add_option("--xlabel", o->xlabel, "x axis label with unit (default: the column in words with its unit)");
  sub->add_option("--ylabel", o->ylabel, "y axis label with unit (default: the first y column in words)");
  sub->add_option("--xscale", o->xscale, "multiply x values (e.g. 1e6 to show metres as µm)")->capture_default_str();
  sub->add_option("--yscale", o->yscale, "multiply y values and error bars")->capture_default_str();
  sub->add_flag("--logx", o->logx, "logarithmic x axis");
  sub->add_flag("--logy", o->logy, "logarithmic y axis");
  sub->add_flag("--markers", o->markers, "draw markers");
  sub->add_flag("--no-lines", o->no_lines, "markers only");
  sub->add_option("--width", o->width, "image width [px]")->capture_default_str();
  sub->add_option("--height", o->height, "image height [px]")->capture_default_str();
  sub->add_flag("--json", o->json, "print one JSON object on stdout");
  sub->callback([o] {
    check_scale("--xscale", o->xscale);
    check_scale("--yscale", o->yscale);
    const auto t = nipdem::io::read_csv(o->data);
    if (t.rows.empty())
      nipdem::throw_input(o->data, "rows", "0", "no data rows after the header: nothing to plot", ">= 1 data row");
    if (!o->yerr.empty() && o->yerr.size() != o->y.size())
      nipdem::throw_input("plot", "--yerr", std::to_string(o->yerr.size()) + " columns",
                          "needs one error column per --y column", std::to_string(o->y.size()));
    nipdem::io::PlotSpec p;
    p.title = o->title;
    if (!o->labels.empty() && o->labels.size() != o->y.size())
      nipdem::throw_input("plot", "--labels", std::to_string(o->labels.size()) + " entries", "needs one legend entry per --y column",
                          std::to_string(o->y.size()));
    p.x_label = o->xlabel.empty() ? nipdem::io::column_words(o->x, o->xscale) : o->xlabel;
    p.y_label = o->ylabel.empty() ? nipdem::io::column_words(o->y.front(), o->yscale) : o->ylabel;
    p.log_x = o->logx;
    p.log_y = o->logy;
    p.width = o->width;
    p.height = o->height;
    const auto x = scaled_column(t, o->x, o->xscale, "--xscale");
    bool any_point = false;  // a row with finite x and y in some series
    for (std::size_t k = 0; k < o->y.size(); ++k) {
      nipdem::io::Series s;
      s.label = !o->labels.empty() ? o->labels[k]
                : o->y.size() > 1 || !o->yerr.empty() ? nipdem::io::column_words(o->y[k], o->yscale) : "";
      s.x = x;
      s.y = scaled_column(t, o->y[k], o->yscale, "--yscale");
      if (!o->yerr.empty()) s.y_err = scaled_column(t, o->yerr[k], std::abs(o->yscale), "--yscale");
      for (std::size_t i = 0; i < x.size(); ++i) any_point = any_point || (std::isfinite(x[i]) && std::isfinite(s.y[i]));
      s.markers = o->markers || o->no_lines;
      s.line = !o->no_lines;
      p.series.push_back(std::move(s));
    }
    if (!any_point)
      nipdem::throw_input(o->data, "--x, --y", o->x + " vs " + fmt::format("{}", fmt::join(o->y, ",")),
                          "no row has finite values in both columns: nothing to plot", ">= 1 row with finite x and y");
    nipdem::io::write_plot_png(o->out, p);
    if (o->json)
      nipdem::cli::print_json(nlohmann::json{{"png", o->out}, {"rows", t.rows.size()}, {"series", o->y.size()}}.dump());
    else
      std::printf("wrote %s (%zu rows, %zu series)\n", o->out.c_str(), t.rows.size(), o->y.size());
  });
});

}  // namespace
