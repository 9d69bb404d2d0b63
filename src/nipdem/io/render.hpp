// Pictures of the nip window drawn with Cairo: rollers, roughness line pieces, every disc
// coloured by speed or force (viridis, range robust to strays: percentiles), axes in µm, a 100 µm scale bar,
// the simulated time and a colour bar naming its quantity and unit.
#pragma once
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/io/vtk.hpp"

namespace nipdem::io {

struct RenderOptions {
  std::string color_by = "speed";  // "speed" or "force"
  int width_px = 1600;
  double color_max = 0.0;          // [SI: m/s or N]; 0 = automatic: median over the frames of each frame's 98th percentile
};

// Viridis colour of v in [0, 1] (clamped; NaN -> 0), RGB in [0, 1].
std::array<double, 3> viridis(double v);
// q-quantile (q in [0, 1], nearest rank) of the finite values; 0 for none.
double percentile(std::vector<double> values, double q);
// What the colour bar shows: label with unit, factor from SI to that unit, top value [SI].
struct ColourScale { std::string label; double factor = 1.0, max = 0.0; };
ColourScale colour_scale(const std::string& color_by, double max_si);

// Renders one frame to a PNG (atomic). `geometry` is summary.json's "geometry" object.
void render_frame(const Frame& f, const nlohmann::json& geometry, const RenderOptions& opt,
                  const std::filesystem::path& png, double color_max);

// Renders every snapshot of RUN_DIR into RUN_DIR/frames/frame_*.png, and RUN_DIR/coverage.png
// when the run printed (coverage.csv); returns how many frames.
int render_run(const std::filesystem::path& run_dir, const RenderOptions& opt);

// Assembles RUN_DIR/frames/frame_*.png into RUN_DIR/frames/movie.mp4 with ffmpeg (run without a
// shell, so any folder name is safe; written to a temporary name, then renamed). Throws
// std::runtime_error if ffmpeg is missing or fails.
std::filesystem::path write_movie(const std::filesystem::path& run_dir, int fps = 10);

// Coverage of one print run (coverage.csv of `nipdem run`): each d50/4 bin of the drum track
// covered or not, and the intended line (where the track voltage is on) marked.
void write_coverage_png(const std::filesystem::path& coverage_csv, const std::filesystem::path& png);

}  // namespace nipdem::io
