// Error types. InputError means "the user gave us something invalid" (CLI exit 2);
// every other exception is an internal or runtime failure (CLI exit 1).
#pragma once
#include <stdexcept>
#include <string>

namespace nipdem {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Builds the standard message: "<where>: key '<key>' = <value>: <problem> (allowed: <range>)".
// `where` is a file name or a component name; empty parts are left out.
std::string input_message(const std::string& where, const std::string& key, const std::string& value,
                          const std::string& problem, const std::string& allowed = {});

[[noreturn]] void throw_input(const std::string& where, const std::string& key, const std::string& value,
                              const std::string& problem, const std::string& allowed = {});

// Checks lo <= v <= hi (either bound may be +-inf) and throws an InputError naming the key otherwise.
void require_range(const std::string& where, const std::string& key, double v, double lo, double hi);
// Checks v > 0 and finite.
void require_positive(const std::string& where, const std::string& key, double v);

}  // namespace nipdem
