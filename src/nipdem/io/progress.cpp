#include "nipdem/io/progress.hpp"

#include <cstdio>
#include <fmt/format.h>
#include <unistd.h>

namespace nipdem::io {

Progress::Progress(std::string label, double t_start, double t_end, std::int64_t step_start)
    : Progress(std::move(label), t_start, t_end, step_start, Style{}) {}

Progress::Progress(std::string label, double t_start, double t_end, std::int64_t step_start, Style style)
    : label_(std::move(label)), t0_(t_start), t1_(t_end), s0_(step_start), style_(style),
      tty_(style.bar && ::isatty(2) != 0), start_(std::chrono::steady_clock::now()), last_(start_) {}

double Progress::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

double Progress::steps_per_s(std::int64_t steps) const {
  const double e = elapsed_s();
  return e > 0 ? static_cast<double>(steps - s0_) / e : 0.0;
}

void Progress::update(double t, std::int64_t steps, const std::string& extra) {
  if (!style_.enabled) return;
  const auto now = std::chrono::steady_clock::now();
  const double since = std::chrono::duration<double>(now - last_).count();
  if (since < (tty_ ? 0.2 : style_.every_s)) return;
  last_ = now;
  print(t, steps, extra, false);
}

void Progress::finish(double t, std::int64_t steps, const std::string& extra) {
  if (style_.enabled) print(t, steps, extra, true);
}

void Progress::print(double t, std::int64_t steps, const std::string& extra, bool final) {
  const double frac = t1_ > t0_ ? std::min(1.0, std::max(0.0, (t - t0_) / (t1_ - t0_))) : 1.0;
  const double el = elapsed_s();
  const double eta = frac > 0 ? el * (1 - frac) / frac : 0.0;
  const std::string core = fmt::format("{} t = {:.4g} / {:.4g} s  {:5.1f}%  {:.3g} steps/s  elapsed {:.0f} s  ETA {:.0f} s{}{}", label_, t,
                                       t1_, 100 * frac, steps_per_s(steps), el, eta, extra.empty() ? "" : "  ", extra);
  if (tty_) {
    const int width = 24;
    const int filled = static_cast<int>(frac * width);
    std::fprintf(stderr, "\r[%s%s] %s\033[K", std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), core.c_str());
    if (final) std::fputc('\n', stderr);
  } else {
    std::fprintf(stderr, "%s\n", core.c_str());
  }
  std::fflush(stderr);
}

}  // namespace nipdem::io
