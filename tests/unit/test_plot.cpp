// PNG plots (io/plot) and CSV tables (io/csv).
#include <gtest/gtest.h>

#include <array>
#include <cairo.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/analysis/fit.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/csv.hpp"
#include "nipdem/io/plot.hpp"
#include "nipdem/io/render.hpp"
#include "nipdem/analysis/report.hpp"

using namespace nipdem;
namespace fs = std::filesystem;

namespace {
fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_plot_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
// Counts pixels close to the colour (r, g, b) in a PNG; also returns its size.
int count_colour(const fs::path& png, double r, double g, double b, int* w = nullptr, int* h = nullptr) {
  cairo_surface_t* s = cairo_image_surface_create_from_png(png.c_str());
  EXPECT_EQ(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
  const int W = cairo_image_surface_get_width(s), H = cairo_image_surface_get_height(s);
  const int stride = cairo_image_surface_get_stride(s);
  const unsigned char* d = cairo_image_surface_get_data(s);
  int n = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::uint32_t px = *reinterpret_cast<const std::uint32_t*>(d + y * stride + 4 * x);  // ARGB32
      const double R = ((px >> 16) & 255) / 255.0, G = ((px >> 8) & 255) / 255.0, B = (px & 255) / 255.0;
      if (std::abs(R - r) < 0.08 && std::abs(G - g) < 0.08 && std::abs(B - b) < 0.08) ++n;
    }
  if (w) *w = W;
  if (h) *h = H;
  cairo_surface_destroy(s);
  return n;
}
}  // namespace

TEST(AnalysisPlot, NiceTicks) {
  EXPECT_EQ(io::nice_ticks(0.0, 1.0, 5), (std::vector<double>{0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0}));
  const auto t = io::nice_ticks(-3.7e-6, 12.1e-6, 6);
  ASSERT_GE(t.size(), 3u);
  EXPECT_NEAR(t[1] - t[0], 5e-6, 1e-18);
  EXPECT_GE(t.front(), -3.7e-6);
  EXPECT_LE(t.back(), 12.1e-6);
  EXPECT_EQ(io::log_ticks(1e-3, 1e2).size(), 6u);  // 6 decades: powers of ten only
  EXPECT_EQ(io::log_ticks(1.0, 10.0), (std::vector<double>{1, 2, 5, 10}));
  // a range within one 1-2-5 step (the reduction plot of 563 and 600 removed toner) still gets
  // labelled ticks: linear steps inside the range
  const auto narrow = io::log_ticks(560.0, 602.0);
  ASSERT_GE(narrow.size(), 3u);
  for (double v : narrow) {
    EXPECT_GE(v, 560.0);
    EXPECT_LE(v, 602.0);
  }
  EXPECT_EQ(io::log_ticks(0.9, 1.1).size(), 5u);  // 0.9, 0.95, 1.0, 1.05, 1.1 (1 alone was a 1-2-5 value)
  EXPECT_EQ(io::tick_label(0.25, 0.05), "0.25");
  EXPECT_EQ(io::tick_label(150, 50), "150");
  EXPECT_EQ(io::tick_label(2e-6, 1e-6), "2e-06");
  EXPECT_EQ(io::tick_labels({-2.5e-4, -2e-4, -1.5e-4}, false), (std::vector<std::string>{"-2.5e-4", "-2.0e-4", "-1.5e-4"}));
  EXPECT_EQ(io::tick_labels({0, 0.5, 1.0}, false), (std::vector<std::string>{"0", "0.5", "1.0"}));
  EXPECT_EQ(io::tick_labels({1, 10, 100}, true), (std::vector<std::string>{"1", "10", "100"}));
}

TEST(AnalysisPlot, PngHasRequestedSizeAndDrawsSeries) {
  const fs::path dir = fresh_dir("png");
  io::PlotSpec p;
  p.title = "test";
  p.x_label = "x [m]";
  p.y_label = "y [1]";
  p.width = 640;
  p.height = 480;
  io::Series red;
  red.label = "red line";
  red.x = {0, 1};
  red.y = {0.5, 0.5};
  red.color = std::array<double, 3>{1.0, 0.0, 0.0};
  red.line_width = 3;
  p.series.push_back(red);
  const fs::path png = dir / "a.png";
  io::write_plot_png(png, p);
  // PNG signature and IHDR size (big-endian width/height at bytes 16..23).
  std::ifstream in(png, std::ios::binary);
  std::array<unsigned char, 24> hd{};
  in.read(reinterpret_cast<char*>(hd.data()), 24);
  const std::array<unsigned char, 8> sig{0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  EXPECT_TRUE(std::equal(sig.begin(), sig.end(), hd.begin()));
  auto be32 = [&](int o) { return (hd[o] << 24) | (hd[o + 1] << 16) | (hd[o + 2] << 8) | hd[o + 3]; };
  EXPECT_EQ(be32(16), 640);
  EXPECT_EQ(be32(20), 480);
  int W = 0, H = 0;
  // The 3 px red line spans the plot width (> 400 px here): well over 1000 red pixels; the rest
  // is mostly white background.
  const int n_red = count_colour(png, 1, 0, 0, &W, &H);
  EXPECT_EQ(W, 640);
  EXPECT_EQ(H, 480);
  EXPECT_GT(n_red, 1000);
  EXPECT_GT(count_colour(png, 1, 1, 1), W * H / 2);
  EXPECT_EQ(count_colour(png, 0, 0, 1), 0);  // no blue drawn
  // Nothing but the PNG in the folder: the temp file was renamed.
  int files = 0;
  for (auto& e : fs::directory_iterator(dir)) { (void)e; ++files; }
  EXPECT_EQ(files, 1);
  fs::remove_all(dir);
}

TEST(AnalysisPlot, CoverageCurveWithFitExample) {
  // The kind of figure edge-sharpness produces (thesis fig. 1.8): average coverage of 50 noisy
  // realizations, the product-of-logistics fit and error bars on a few points; plus a log-log
  // plot. Written to the build tree's temp folder; also the image checked by eye (docs).
  const fs::path dir = fresh_dir("example");
  std::vector<double> x, c;
  Rng rng(1);
  for (int i = 0; i <= 700; ++i) {
    const double xi = (-200 + 1.2 * i) * 1e-6;
    const double p = 1 / (1 + std::exp(-xi / 45e-6)) / (1 + std::exp((xi - 500e-6) / 27e-6));
    int k = 0;
    for (int r = 0; r < 50; ++r) k += rng.uniform() < p;
    x.push_back(xi);
    c.push_back(k / 50.0);
  }
  const auto fit = analysis::fit_line_edges(x, c);
  io::PlotSpec p;
  p.title = "Average coverage and sigmoid fit";
  p.x_label = "position along the drum x [µm]";
  p.y_label = "coverage [-]";
  io::Series data, model;
  data.label = "average of 50 lines";
  data.line = false;
  data.markers = true;
  data.marker_size = 1.8;
  model.label = "sigmoid fit";
  for (std::size_t i = 0; i < x.size(); ++i) {
    data.x.push_back(x[i] * 1e6);
    data.y.push_back(c[i]);
    model.x.push_back(x[i] * 1e6);
    model.y.push_back(analysis::evaluate(fit, x[i]));
  }
  p.series = {data, model};
  io::write_plot_png(dir / "coverage.png", p);
  EXPECT_GT(count_colour(dir / "coverage.png", 0.12, 0.47, 0.71), 500);  // palette colour 0 drawn

  io::PlotSpec q;
  q.title = "Removed particles vs r";
  q.x_label = "r = F_coh / F_adh [-]";
  q.y_label = "removed in 100 ms [-]";
  q.log_x = q.log_y = true;
  io::Series s;
  s.label = "black";
  s.markers = true;
  s.x = {0.1, 0.3, 1, 3, 10};
  s.y = {500, 300, 120, 40, 8};
  s.y_err = {50, 30, 15, 8, 3};
  q.series = {s};
  io::write_plot_png(dir / "loglog.png", q);
  EXPECT_TRUE(fs::exists(dir / "loglog.png"));
  if (const char* keep = std::getenv("NIPDEM_KEEP_PLOTS")) {
    fs::copy_file(dir / "coverage.png", fs::path(keep) / "coverage.png", fs::copy_options::overwrite_existing);
    fs::copy_file(dir / "loglog.png", fs::path(keep) / "loglog.png", fs::copy_options::overwrite_existing);
  }
  fs::remove_all(dir);
}

TEST(AnalysisPlot, HeatmapColoursBySignUnderTheSeries) {
  const fs::path d = fresh_dir("heat");
  io::PlotSpec p;
  io::Heatmap h;
  h.x = {0, 1, 2, 3};
  h.y = {0, 1};
  h.z = {-2, -2, 2, 2, -2, -2, 2, 2};  // left half negative, right half positive
  h.z_label = "F [nN]";
  p.heatmap = h;
  io::write_plot_png(d / "h.png", p);
  const auto blue = io::diverging_colour(-1.0), red = io::diverging_colour(1.0);
  const int nb = count_colour(d / "h.png", blue[0], blue[1], blue[2]);
  const int nr = count_colour(d / "h.png", red[0], red[1], red[2]);
  EXPECT_GT(nb, 20000);  // each half of the ~700 x 450 px area, less the grid lines
  EXPECT_GT(nr, 20000);
  EXPECT_NEAR(static_cast<double>(nb) / nr, 1.0, 0.1);  // equal halves (the colour bar adds a little of each)
  const auto w = io::diverging_colour(0.0);
  EXPECT_DOUBLE_EQ(w[0] + w[1] + w[2], 3.0);  // white at zero
  EXPECT_EQ(io::diverging_colour(5.0), red);      // display saturation beyond the limits
  // Bad heat maps are input errors naming the problem.
  p.heatmap->z.pop_back();
  EXPECT_THROW(io::write_plot_png(d / "bad.png", p), InputError);
  p.heatmap = h;
  p.heatmap->y = {1, 0};
  EXPECT_THROW(io::write_plot_png(d / "bad.png", p), InputError);
  p.heatmap = h;
  p.log_x = true;
  EXPECT_THROW(io::write_plot_png(d / "bad.png", p), InputError);
  fs::remove_all(d);
}

TEST(AnalysisPlot, BadDataIsAnInputError) {
  const fs::path dir = fresh_dir("bad");
  io::PlotSpec p;
  EXPECT_THROW(io::write_plot_png(dir / "e.png", p), InputError);  // nothing to plot
  io::Series s;
  s.x = {1, 2, 3};
  s.y = {1, 2};
  p.series = {s};
  EXPECT_THROW(io::write_plot_png(dir / "e.png", p), InputError);
  p.series[0].y = {1, 0, 2};
  p.log_y = true;
  EXPECT_THROW(io::write_plot_png(dir / "e.png", p), InputError);  // 0 on a log axis
  p.log_y = false;
  p.series[0].y_err = {1};
  EXPECT_THROW(io::write_plot_png(dir / "e.png", p), InputError);
  EXPECT_FALSE(fs::exists(dir / "e.png"));
  fs::remove_all(dir);
}

TEST(AnalysisCsv, RoundTripAndColumns) {
  const fs::path dir = fresh_dir("csv");
  io::write_csv(dir / "t.csv", {"gap_m", "front_m"}, {{1e-4, -2.5e-5}, {1.2e-4, 0.1 + 0.2}});
  const auto t = io::read_csv(dir / "t.csv");
  EXPECT_EQ(t.columns, (std::vector<std::string>{"gap_m", "front_m"}));
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[1][1], 0.1 + 0.2);  // shortest round-trip format is exact
  EXPECT_EQ(t.column("gap_m"), (std::vector<double>{1e-4, 1.2e-4}));
  const auto c = io::parse_csv("# comment\r\na, b\r\n\r\n 1 , +2\r\n-3e-2,inf\r\n", "mem");
  EXPECT_EQ(c.rows.size(), 2u);
  EXPECT_EQ(c.rows[0][1], 2.0);
  EXPECT_TRUE(std::isinf(c.rows[1][1]));
  EXPECT_EQ(io::format_csv_columns({"a", "b"}, {{1, 2}, {3, 4}}), "a,b\n1,3\n2,4\n");
  fs::remove_all(dir);
}

TEST(AnalysisCsv, ErrorsNameFileLineAndColumn) {
  auto msg = [](const std::string& text) {
    try {
      io::parse_csv(text, "data.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string ragged = msg("frequency_Hz,amplitude_V,phase_deg\n1,2,3\n4,5\n");
  EXPECT_NE(ragged.find("data.csv:3"), std::string::npos) << ragged;
  EXPECT_NE(ragged.find("2 cells"), std::string::npos) << ragged;
  const std::string nonnum = msg("frequency_Hz,amplitude_V,phase_deg\n1,2,3\n4,five,6\n");
  EXPECT_NE(nonnum.find("data.csv:3"), std::string::npos) << nonnum;
  EXPECT_NE(nonnum.find("'amplitude_V (column 2)'"), std::string::npos) << nonnum;
  EXPECT_NE(nonnum.find("'five'"), std::string::npos) << nonnum;
  EXPECT_NE(msg("a,b\n1,2x\n").find("not a number"), std::string::npos);
  EXPECT_NE(msg("a,b\n1,\n").find("not a number"), std::string::npos);
  EXPECT_NE(msg("").find("empty CSV"), std::string::npos);
  const auto t = io::parse_csv("a,b\n1,2\n", "data.csv");
  try {
    t.column("c");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'c'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("a, b"), std::string::npos);
  }
  EXPECT_THROW(io::read_csv("/nonexistent/nipdem.csv"), InputError);
}

TEST(AnalysisCsv, CliPlotExitsTwoOnBadCsv) {
  const fs::path dir = fresh_dir("clicsv");
  io::write_file_atomic(dir / "bad.csv", "x_m,y_m\n1,2\n3\n");
  io::write_file_atomic(dir / "good.csv", "x_m,y_m\n1,2\n3,5\n4,4\n");
  const std::string cli = NIPDEM_CLI_PATH;
  const std::string err = (dir / "err.txt").string();
  int st = std::system((cli + " plot " + (dir / "bad.csv").string() + " --x x_m --y y_m --out " +
                        (dir / "o.png").string() + " 2>" + err)
                           .c_str());
  EXPECT_EQ(WEXITSTATUS(st), 2);
  const std::string e = io::read_file(err);
  EXPECT_NE(e.find("bad.csv:3"), std::string::npos) << e;
  st = std::system((cli + " plot " + (dir / "good.csv").string() + " --x x_m --y y_m --markers --out " +
                    (dir / "o.png").string() + " >/dev/null 2>&1")
                       .c_str());
  EXPECT_EQ(WEXITSTATUS(st), 0);
  EXPECT_TRUE(fs::exists(dir / "o.png"));
  st = std::system((cli + " plot " + (dir / "good.csv").string() + " --x x_m --y nope --out " +
                    (dir / "o.png").string() + " >/dev/null 2>&1")
                       .c_str());
  EXPECT_EQ(WEXITSTATUS(st), 2);
  fs::remove_all(dir);
}

TEST(Pictures, ViridisEndsAndIsMonotoneInLightness) {
  // The map's published end colours (#440154, #fde725) and a brightness that rises throughout
  // (perceptually ordered, readable in grey).
  const auto a = io::viridis(0.0), b = io::viridis(1.0);
  EXPECT_NEAR(a[0], 68 / 255.0, 1e-12);
  EXPECT_NEAR(a[2], 84 / 255.0, 1e-12);
  EXPECT_NEAR(b[0], 253 / 255.0, 1e-12);
  EXPECT_NEAR(b[1], 231 / 255.0, 1e-12);
  double last = -1;
  for (int i = 0; i <= 100; ++i) {
    const auto c = io::viridis(i / 100.0);
    const double luma = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    EXPECT_GT(luma, last) << i;
    last = luma;
  }
  EXPECT_EQ(io::viridis(2.0), b);   // clamped for display
  EXPECT_EQ(io::viridis(NAN), a);
}

TEST(Pictures, PercentileColourRangeIgnoresAFewFastStrays) {
  std::vector<double> v(1000);
  for (int i = 0; i < 1000; ++i) v[i] = 0.1 + 0.4 * i / 999.0;  // 0.1 ... 0.5 m/s
  const double clean = io::percentile(v, 0.95);
  for (int i = 0; i < 10; ++i) v.push_back(50.0);  // ten strays, 100x faster
  const double with_strays = io::percentile(v, 0.95);
  EXPECT_NEAR(clean, 0.48, 0.01);
  EXPECT_LT(with_strays / clean, 1.02);
  EXPECT_EQ(io::percentile({}, 0.95), 0.0);
  EXPECT_EQ(io::colour_scale("speed", 0.5).label, "speed [mm/s]");
  EXPECT_EQ(io::colour_scale("force", 1e-9).label, "|force| per disc [nN]");
}

TEST(Pictures, LegendsAndAxesInWordsWithUnits) {
  EXPECT_EQ(io::column_words("front_std_m", 1e6), "front std [µm]");
  EXPECT_EQ(io::column_words("s_begin_m", 1e6), "s begin [µm]");
  EXPECT_EQ(io::column_words("coverage"), "coverage");
  EXPECT_EQ(io::column_words("time_s", 1e3), "time [ms]");
  EXPECT_EQ(io::column_words("force_N", 1e9), "force [nN]");
  EXPECT_EQ(io::column_words("sleeve_speed_m_per_s"), "sleeve speed [m/s]");
  EXPECT_EQ(io::column_words("removed_per_100ms"), "removed per 100ms");
}

TEST(Pictures, NoLineWhereTheDataDoNotResolveATrend) {
  io::Series s;
  s.x = {100, 150, 200};
  s.y = {-80, -70, -84};
  s.y_err = {15, 20, 12};  // every step within the spread
  s.line_only_if_resolved = true;
  EXPECT_FALSE(io::draws_line(s));
  s.y = {-80, -140, -200};  // steps of 60 um against spreads of ~25 um
  EXPECT_TRUE(io::draws_line(s));
  s.line = false;
  EXPECT_FALSE(io::draws_line(s));
  io::Series plain;
  plain.x = {1, 2};
  plain.y = {1, 1};
  EXPECT_TRUE(io::draws_line(plain));  // the default is unchanged
}

TEST(Pictures, CoveragePlotsMarkTheIntendedLine) {
  // Edge-sharpness's average-coverage plot: the line the track printed is drawn as a dashed box.
  std::vector<double> x = {0.0, 1e-4, 2e-4, 3e-4}, c = {0, 0.5, 1, 0};
  analysis::LineEdgesFit fit{};
  const auto p = analysis::coverage_plot(x, c, fit, "t", 1e-4, 2.5e-4);
  ASSERT_EQ(p.series.size(), 3u);
  EXPECT_EQ(p.series[2].label, "intended line (track voltage on)");
  EXPECT_EQ(p.series[2].x, (std::vector<double>{100, 100, 250, 250}));
  EXPECT_FALSE(io::draws_line(p.series[0]));  // the bins are markers
  EXPECT_NE(p.x_label.find("[µm]"), std::string::npos);
  // A single run's coverage.csv: bins, and the intended line from the track voltage column.
  const fs::path dir = fresh_dir("coverage_run");
  std::string csv = "s_begin_m,s_end_m,coverage,particles,track_voltage_V\n";
  for (int i = 0; i < 40; ++i) {
    const double s0 = i * 2.5e-6;
    const bool on = s0 >= 25e-6 && s0 < 60e-6;
    csv += fmt::format("{},{},{},{},{}\n", s0, s0 + 2.5e-6, on && i % 3 ? 1 : 0, on ? 1 : 0, on ? 40 : 0);
  }
  io::write_file_atomic(dir / "coverage.csv", csv);
  io::write_coverage_png(dir / "coverage.csv", dir / "coverage.png");
  int w = 0, h = 0;
  EXPECT_GT(count_colour(dir / "coverage.png", 0.85, 0.33, 0.10, &w, &h), 30);  // the dashed intended line
  EXPECT_EQ(w, 900);
  fs::remove_all(dir);
}

TEST(Pictures, RenderWritesFramesAndAMovieForAnyFolderName) {
  // `render --movie` starts ffmpeg without a shell: a folder name with spaces, a quote and a $
  // reaches it unchanged. Needs ffmpeg (scripts/install-deps); skipped without it.
  const fs::path base = fresh_dir("movie");
  const fs::path run = base / "run a'b $HOME";
  auto quote = [](const std::string& s) {
    std::string q = "'";
    for (char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    return q + "'";
  };
  const std::string ex = std::string(NIPDEM_SOURCE_DIR) + "/examples/nip_black_small.toml";
  const std::string cli = NIPDEM_CLI_PATH;
  ASSERT_EQ(std::system((cli + " run " + ex + " --out " + quote(run.string()) +
                         " --quiet --set run.end_time_s=4e-5 --set run.output_interval_s=2e-5 --set geometry.window_x_min_m=-1e-4"
                         " --set geometry.window_x_max_m=1e-4 2>/dev/null").c_str()),
            0);
  const bool have_ffmpeg = std::system("command -v ffmpeg >/dev/null 2>&1") == 0;
  const int rc = std::system((cli + " render " + quote(run.string()) + (have_ffmpeg ? " --movie" : "") + " 2>/dev/null").c_str());
  EXPECT_EQ(rc, 0);
  EXPECT_TRUE(fs::exists(run / "frames" / "frame_000000.png"));
  EXPECT_TRUE(fs::exists(run / "frames" / "frame_000002.png"));
  if (have_ffmpeg) {
    EXPECT_TRUE(fs::exists(run / "frames" / "movie.mp4"));
    EXPECT_GT(fs::file_size(run / "frames" / "movie.mp4"), 1000u);
  } else {
    GTEST_SKIP() << "ffmpeg not installed: movie not checked";
  }
  fs::remove_all(base);
}
