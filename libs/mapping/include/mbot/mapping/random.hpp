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

// The layers of a 128-layer ziggurat under the standard normal density (Marsaglia & Tsang 2000, in
// Doornik's 2005 form): x[i] the layers' right edges, ratio[i] = x[i + 1] / x[i].
struct NormalZiggurat {
  static constexpr int kLayers = 128;
  static constexpr double kTailStart = 3.442619855899;       // R: the base layer's rectangle ends here
  static constexpr double kLayerArea = 9.91256303526217e-3;  // V: the area of every layer
  double x[kLayers + 1];
  double ratio[kLayers];
  NormalZiggurat();
  static const NormalZiggurat& Get();
};

class CounterRng {
 public:
  explicit CounterRng(uint64_t key) : state_(key) {}
  uint64_t Bits() {
    state_ = SplitMix64(state_);
    return state_;
  }
  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(Bits() >> 11) * (1.0 / 9007199254740992.0); }
  // Standard normal by the ziggurat: one 64-bit draw per sample almost always (98.8 %): 7 bits pick
  // the layer, 53 others give the abscissa; the wedges and the tail are sampled exactly.
  double Normal() {
    const NormalZiggurat& z = NormalZiggurat::Get();
    while (true) {
      const uint64_t bits = Bits();
      const int layer = static_cast<int>(bits & (NormalZiggurat::kLayers - 1));
      const double u = static_cast<double>(bits >> 11) * (2.0 / 9007199254740992.0) - 1.0;  // [-1, 1)
      if (std::abs(u) < z.ratio[layer]) return u * z.x[layer];
      if (layer == 0) return Tail(u < 0.0);
      const double x = u * z.x[layer];
      const double f0 = std::exp(-0.5 * (z.x[layer] * z.x[layer] - x * x));
      const double f1 = std::exp(-0.5 * (z.x[layer + 1] * z.x[layer + 1] - x * x));
      if (f1 + Uniform() * (f0 - f1) < 1.0) return x;
    }
  }

 private:
  // Beyond R (Marsaglia 1964).
  double Tail(bool negative) {
    constexpr double r = NormalZiggurat::kTailStart;
    double x, y;
    do {
      x = std::log(1.0 - Uniform()) / r;  // 1 − U is in (0, 1]
      y = std::log(1.0 - Uniform());
    } while (-2.0 * y < x * x);
    return negative ? x - r : r - x;
  }

  uint64_t state_;
};

inline NormalZiggurat::NormalZiggurat() {
  double f = std::exp(-0.5 * kTailStart * kTailStart);
  x[0] = kLayerArea / f;  // the base layer: its rectangle plus the tail, as wide as one layer's area
  x[1] = kTailStart;
  x[kLayers] = 0.0;
  for (int i = 2; i < kLayers; ++i) {
    x[i] = std::sqrt(-2.0 * std::log(kLayerArea / x[i - 1] + f));
    f = std::exp(-0.5 * x[i] * x[i]);
  }
  for (int i = 0; i < kLayers; ++i) ratio[i] = x[i + 1] / x[i];
}

inline const NormalZiggurat& NormalZiggurat::Get() {
  static const NormalZiggurat z;
  return z;
}

}  // namespace mbot::mapping
