// Pictures of the nip window drawn with Cairo: rollers, roughness line pieces, every disc
// coloured by speed or force, a micrometre scale bar, the simulated time and a colour bar.
#pragma once
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "nipdem/io/vtk.hpp"

namespace nipdem::io {

struct RenderOptions {
  std::string color_by = "speed";  // "speed" or "force"
  int width_px = 1600;
  double color_max = 0.0;          // 0 = automatic (98th percentile of the run's first frame)
};

// Renders one frame to a PNG (atomic). `geometry` is summary.json's "geometry" object.
void render_frame(const Frame& f, const nlohmann::json& geometry, const RenderOptions& opt,
                  const std::filesystem::path& png, double color_max);

// Renders every snapshot of RUN_DIR into RUN_DIR/frames/frame_*.png; returns how many.
int render_run(const std::filesystem::path& run_dir, const RenderOptions& opt);

}  // namespace nipdem::io
