// `nipdem render RUN_DIR [--color-by speed|force] [--width PX] [--color-max V] [--movie]`
#include <cstdio>

#include "nipdem/io/render.hpp"
#include "registry.hpp"

namespace {
struct Opts {
  std::string dir;
  nipdem::io::RenderOptions ro;
  bool movie = false;
};
nipdem::cli::Register reg([](CLI::App& app) {
  auto o = std::make_shared<Opts>();
  auto* sub = app.add_subcommand("render", "Draw PNG pictures of every snapshot of a run (RUN_DIR/frames/)");
  sub->add_option("run_dir", o->dir, "output folder of `nipdem run`")->required();
  sub->add_option("--color-by", o->ro.color_by, "speed or force")->capture_default_str();
  sub->add_option("--width", o->ro.width_px, "image width [px]")->capture_default_str()->check(CLI::Range(200, 8000));
  sub->add_option("--color-max", o->ro.color_max, "value mapped to the top of the colour bar [m/s or N] (0 = median over the frames of each frame's 98th percentile)");
  sub->add_flag("--movie", o->movie, "also assemble frames/movie.mp4 (needs ffmpeg on PATH)");
  sub->callback([o] {
    const int n = nipdem::io::render_run(o->dir, o->ro);
    std::fprintf(stderr, "nipdem render: %d frames in %s/frames/\n", n, o->dir.c_str());
    if (o->movie) {
      const auto movie = nipdem::io::write_movie(o->dir);
      std::fprintf(stderr, "nipdem render: %s\n", movie.string().c_str());
    }
  });
});
}  // namespace
