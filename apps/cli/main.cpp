// nipdem: one executable, subcommands registered by the cmd_*.cpp files (see registry.hpp).
#include <cctype>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "nipdem/core/error.hpp"
#include "nipdem/core/wait_policy.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/version.hpp"
#include "registry.hpp"

namespace nipdem::cli {

std::vector<Registrar>& registry() {
  static std::vector<Registrar> r;
  return r;
}

CLI::App* group(CLI::App& app, const std::string& name) {
  // Each group's description, once: several files add to "calibrate", "experiment" and "force",
  // and which file registers first is up to the linker.
  static const std::map<std::string, std::string> kDescriptions = {
      {"calibrate", "Calibrate model parameters from experiments"},
      {"experiment", "Experiments of thesis chapters 4-5 (ensembles on threads or MPI)"},
      {"field", "Magnet field of the imaging roller and the force on toner"},
      {"force", "Evaluate single force laws"},
      {"ldc", "Local defect correction electrostatic solver (thesis ch. 3)"},
      {"params", "Derived model parameters"},
      {"presets", "CPS700 preset configurations (black, color)"},
      {"rc", "Probe-circuit (charge model) tools, thesis §4.7"},
  };
  for (CLI::App* s : app.get_subcommands([](CLI::App*) { return true; })) {
    if (s->get_name() == name) return s;
  }
  const auto d = kDescriptions.find(name);
  if (d == kDescriptions.end()) throw std::logic_error("cli::group: no description for the group \"" + name + "\" (apps/cli/main.cpp)");
  CLI::App* g = app.add_subcommand(name, d->second);
  g->require_subcommand(1);
  return g;
}

void print_json(const std::string& json) {
  std::fwrite(json.data(), 1, json.size(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

std::vector<double> parse_number_list(const std::string& text, const std::string& where, const std::string& key) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t pos = 0;
      v.push_back(std::stod(item, &pos));
      if (pos != item.size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw_input(where, key, "\"" + text + "\"", "expected a comma-separated list of numbers");
    }
  }
  if (v.empty()) throw_input(where, key, "\"" + text + "\"", "empty list");
  return v;
}

void finish_report(const nlohmann::json& j, const std::filesystem::path& out, const std::string& name, bool json,
                   const std::string& summary) {
  std::filesystem::create_directories(out);
  io::write_file_atomic(out / (name + ".json"), j.dump(2));
  if (json) {
    print_json(j.dump());
  } else {
    std::fputs(summary.c_str(), stdout);
    std::fprintf(stderr, "%s: results in %s\n", name.c_str(), out.string().c_str());
  }
}

namespace {
// Every numeric option of every command accepts only what its type can hold exactly: a finite
// decimal number for FLOAT (no nan/inf: CLI11 would pass them on), a plain decimal integer for
// INT/UINT (CLI11 would read "-1" as 2^64-1 for an unsigned option and "010" as octal 8). The
// commands then check their ranges; this makes sure a NaN never reaches them silently.
bool plain_integer(const std::string& s, bool allow_sign) {
  std::size_t i = 0;
  if (allow_sign && i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
  if (i == s.size() || s.size() - i > 19) return false;
  if (s[i] == '0' && s.size() - i > 1) return false;  // no octal / hex look-alikes
  for (; i < s.size(); ++i) if (s[i] < '0' || s[i] > '9') return false;
  return true;
}
void harden_numeric_options(CLI::App* app) {
  for (CLI::Option* o : app->get_options()) {
    // (the type name carries a validator's description after it, e.g. "INT in [1 - 256]" for
    // CLI::Range: matched by its start, or such an option escaped the check: --jobs 010)
    const std::string t = o->get_type_name();
    auto is = [&t](const char* type) { return t.rfind(type, 0) == 0 && (t.size() == std::strlen(type) || !std::isalnum(static_cast<unsigned char>(t[std::strlen(type)]))); };
    if (is("FLOAT")) {
      o->check(CLI::Validator(
          [](std::string& v) -> std::string {
            char* end = nullptr;
            const double x = std::strtod(v.c_str(), &end);
            if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(x)) return "'" + v + "' is not a finite number";
            return {};
          },
          "", "finite"));
    } else if (is("INT") || is("UINT")) {
      const bool sign = is("INT");
      o->check(CLI::Validator(
          [sign](std::string& v) -> std::string {
            if (!plain_integer(v, sign))
              return "'" + v + "' is not a plain decimal integer" + std::string(sign ? "" : " >= 0") +
                     " (no leading zeros: they would be read as octal)";
            return {};
          },
          "", "integer"));
    }
  }
  for (CLI::App* s : app->get_subcommands([](CLI::App*) { return true; })) harden_numeric_options(s);
}
}  // namespace

}  // namespace nipdem::cli

int main(int argc, char** argv) {
  nipdem::apply_wait_policy(argv);  // may re-execute once (core/wait_policy.hpp)
  CLI::App app{"nipdem: discrete element simulation of toner in the development nip of a DI printer"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("nipdem ") + nipdem::kVersion + " (" + nipdem::kGitHash + ")");
  for (auto& reg : nipdem::cli::registry()) reg(app);
  nipdem::cli::harden_numeric_options(&app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;  // CLI.md: bad usage exits 2
  } catch (const nipdem::InputError& e) {
    std::cerr << "nipdem: error: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "nipdem: failure: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
