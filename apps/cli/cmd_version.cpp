// `nipdem version --json`: machine-readable version and build info.
#include <nlohmann/json.hpp>

#include "nipdem/version.hpp"
#include "registry.hpp"

namespace {
nipdem::cli::Register reg([](CLI::App& app) {
  auto* sub = app.add_subcommand("version", "Print version and git hash");
  auto json = std::make_shared<bool>(false);
  sub->add_flag("--json", *json, "Print one JSON object");
  sub->callback([json] {
    if (*json) {
      nipdem::cli::print_json(nlohmann::json{{"version", nipdem::kVersion}, {"git_hash", nipdem::kGitHash}}.dump());
    } else {
      std::printf("nipdem %s (%s)\n", nipdem::kVersion, nipdem::kGitHash);
    }
  });
});
}  // namespace
