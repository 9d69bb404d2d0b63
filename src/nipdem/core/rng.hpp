// Seeded random numbers that give the same stream on every platform and compiler
// (std:: distributions are implementation-defined, so we do not use them).
#pragma once
#include <cmath>
#include <cstdint>
#include <numbers>

namespace nipdem {

// xoshiro256** seeded by splitmix64 (Blackman & Vigna). Small, fast, reproducible.
class Rng {
 public:
  explicit Rng(std::uint64_t seed = 1) { reseed(seed); }
  void reseed(std::uint64_t seed) {
    std::uint64_t z = seed;
    for (auto& s : s_) s = splitmix(z);
  }
  std::uint64_t next_u64() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0]; s_[3] ^= s_[1]; s_[1] ^= s_[2]; s_[0] ^= s_[3];
    s_[2] ^= t; s_[3] = rotl(s_[3], 45);
    return result;
  }
  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  // Standard normal by Box-Muller (one value per call; simple and portable).
  double normal() {
    double u1 = uniform();
    while (u1 <= 0.0) u1 = uniform();
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }
  double normal(double mean, double sd) { return mean + sd * normal(); }
  // Independent stream for sub-task `k` (realization, thread) derived from this seed.
  static Rng stream(std::uint64_t seed, std::uint64_t k) { return Rng(seed ^ (0x9E3779B97F4A7C15ULL * (k + 1))); }

  // Full state, for checkpoints.
  const std::uint64_t* state() const { return s_; }
  void set_state(const std::uint64_t* s) { for (int i = 0; i < 4; ++i) s_[i] = s[i]; }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  std::uint64_t s_[4];
};

}  // namespace nipdem
