// Subcommand registry: each cmd_*.cpp registers a function that adds its subcommand(s) to
// the CLI11 app, so adding a command never touches main.cpp.
//
//   static nipdem::cli::Register reg([](CLI::App& app) {
//     auto* force = nipdem::cli::group(app, "force");
//     auto* sub = force->add_subcommand("electric", "...");
//     ...; sub->callback([=] { ... });
//   });
//
// Callbacks report bad input by throwing nipdem::InputError (exit 2); anything else exits 1.
#pragma once
#include <CLI/CLI.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <functional>
#include <string>
#include <vector>

namespace nipdem::cli {

using Registrar = std::function<void(CLI::App&)>;
std::vector<Registrar>& registry();

struct Register {
  explicit Register(Registrar r) { registry().push_back(std::move(r)); }
};

// Returns the subcommand `name` of `app`, creating it (with its description from the table in
// main.cpp, which a new group has to be entered in) if absent. Lets several files add children
// to one group such as "force" or "experiment".
CLI::App* group(CLI::App& app, const std::string& name);

// Prints one JSON document (already serialised) on stdout followed by a newline.
void print_json(const std::string& json);

// Parses "a,b,c" into numbers; a bad item or an empty list is an InputError naming `where` and `key`.
std::vector<double> parse_number_list(const std::string& text, const std::string& where, const std::string& key);

// Writes `j` to OUT/NAME.json; prints it on stdout with --json, otherwise prints `summary` on
// stdout and names the folder on stderr (the calibrations and front-force).
void finish_report(const nlohmann::json& j, const std::filesystem::path& out, const std::string& name, bool json,
                   const std::string& summary);

}  // namespace nipdem::cli
