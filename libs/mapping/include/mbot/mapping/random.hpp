// Counter-based random numbers: a stream is a pure function of its key (seed, step, particle), so
// particles can be sampled on any number of threads and the result does not change.
#pragma once

#include <cmath>
#include <cstdint>

namespace mbot::mapping {

inline uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

inline uint64_t StreamKey(uint64_t seed, uint64_t step, uint64_t index) {
  return SplitMix64(SplitMix64(SplitMix64(seed) ^ step) ^ index);
}

class CounterRng {
 public:
  explicit CounterRng(uint64_t key) : state_(key) {}
  // Uniform in [0, 1).
  double Uniform() {
    state_ = SplitMix64(state_);
    return static_cast<double>(state_ >> 11) * (1.0 / 9007199254740992.0);
  }
  // Standard normal (Box–Muller; the second value is kept for the next call).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = Uniform();
    if (u1 < 1e-300) u1 = 1e-300;
    const double u2 = Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }

 private:
  uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace mbot::mapping
