#include "nipdem/core/error.hpp"

#include <cmath>
#include <fmt/format.h>

namespace nipdem {

std::string input_message(const std::string& where, const std::string& key, const std::string& value,
                          const std::string& problem, const std::string& allowed) {
  std::string m = where.empty() ? std::string{} : where + ": ";
  if (!key.empty()) m += "key '" + key + "'";
  if (!value.empty()) m += " = " + value;
  if (!key.empty() || !value.empty()) m += ": ";
  m += problem;
  if (!allowed.empty()) m += " (allowed: " + allowed + ")";
  return m;
}

void throw_input(const std::string& where, const std::string& key, const std::string& value,
                 const std::string& problem, const std::string& allowed) {
  throw InputError(input_message(where, key, value, problem, allowed));
}

static std::string bound(double b) {
  if (std::isinf(b)) return b > 0 ? "inf" : "-inf";
  return fmt::format("{:g}", b);
}

void require_range(const std::string& where, const std::string& key, double v, double lo, double hi) {
  if (!(v >= lo && v <= hi) || std::isnan(v)) {
    throw_input(where, key, fmt::format("{:g}", v), "out of range", "[" + bound(lo) + ", " + bound(hi) + "]");
  }
}

void require_positive(const std::string& where, const std::string& key, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    throw_input(where, key, fmt::format("{:g}", v), "must be positive and finite", "(0, inf)");
  }
}

}  // namespace nipdem
