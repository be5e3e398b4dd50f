// The counter-based generator's normals: the ziggurat must give a standard normal (moments, tails,
// the whole distribution by a Kolmogorov–Smirnov test) and a stream must depend on its key only.
#include "mbot/mapping/random.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace mbot::mapping {
namespace {

TEST(CounterRngTest, ZigguratGivesAStandardNormal) {
  constexpr int kDraws = 400000;
  std::vector<double> x;
  x.reserve(kDraws);
  // One short stream per key, as the particle filter draws them (three normals per particle).
  for (int i = 0; x.size() < kDraws; ++i) {
    CounterRng rng(StreamKey(7, 1, i));
    for (int k = 0; k < 3; ++k) x.push_back(rng.Normal());
  }
  double m1 = 0, m2 = 0, m4 = 0;
  int beyond2 = 0, beyond3 = 0, beyond_r = 0;
  for (double v : x) {
    m1 += v, m2 += v * v, m4 += v * v * v * v;
    beyond2 += std::abs(v) > 2.0;
    beyond3 += std::abs(v) > 3.0;
    beyond_r += std::abs(v) > NormalZiggurat::kTailStart;  // drawn by the tail sampler
  }
  const double n = static_cast<double>(x.size());
  m1 /= n, m2 /= n, m4 /= n;
  EXPECT_NEAR(m1, 0.0, 5.0 / std::sqrt(n));
  EXPECT_NEAR(m2, 1.0, 5.0 * std::sqrt(2.0 / n));
  EXPECT_NEAR(m4, 3.0, 5.0 * std::sqrt(96.0 / n));
  // P(|X| > 2) = 0.0455, P(|X| > 3) = 0.0027, P(|X| > 3.4426) = 0.000576.
  EXPECT_NEAR(beyond2 / n, 0.0455, 5.0 * std::sqrt(0.0455 / n));
  EXPECT_NEAR(beyond3 / n, 0.0027, 5.0 * std::sqrt(0.0027 / n));
  EXPECT_NEAR(beyond_r / n, 0.000576, 5.0 * std::sqrt(0.000576 / n));
  // Kolmogorov–Smirnov against Φ: the 0.1 % critical value is 1.95 / √n.
  std::sort(x.begin(), x.end());
  double d = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double cdf = 0.5 * std::erfc(-x[i] / std::sqrt(2.0));
    d = std::max({d, std::abs(cdf - i / n), std::abs(cdf - (i + 1) / n)});
  }
  EXPECT_LT(d, 1.95 / std::sqrt(n)) << "KS distance " << d;
}

TEST(CounterRngTest, AStreamIsAFunctionOfItsKey) {
  CounterRng a(StreamKey(1, 2, 3)), b(StreamKey(1, 2, 3)), c(StreamKey(1, 2, 4));
  for (int k = 0; k < 100; ++k) {
    const double va = a.Normal();
    EXPECT_EQ(va, b.Normal());
    EXPECT_NE(va, c.Normal());
  }
}

}  // namespace
}  // namespace mbot::mapping
