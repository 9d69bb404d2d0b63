// `nipdem presets list` and `nipdem presets show NAME`
#include <cstdio>

#include "nipdem/nip/presets.hpp"
#include "registry.hpp"

namespace {
nipdem::cli::Register reg([](CLI::App& app) {
  auto* g = nipdem::cli::group(app, "presets");
  g->add_subcommand("list", "List the presets")->callback([] {
    for (const auto& n : nipdem::nip::preset_names()) std::printf("%s\n", n.c_str());
  });
  auto name = std::make_shared<std::string>();
  auto* show = g->add_subcommand("show", "Print a preset's complete TOML configuration with thesis references");
  show->add_option("name", *name, "black or color")->required();
  show->callback([name] { std::fputs(nipdem::nip::preset_text(*name).c_str(), stdout); });
});
}  // namespace
