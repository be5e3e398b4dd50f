// The robot's view of the autonomy's loop latency: from a scan going out to the first velocity
// command coming back after it (what a robot waits between seeing and being told), on the wall
// clock. The simulated robots' transport stages (lcm_bridge, ros2_bridge) measure it the same way,
// so the transports compare; the summary (count, median, p99, max) goes to the log and to
// <output.dir>/loop_latency.json.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace mbot::msgs {

class LoopLatency {
 public:
  void ScanSent(int64_t wall_us) {
    if (pending_us_ == 0) pending_us_ = wall_us;  // the oldest scan not yet answered
  }
  // `wall_us`: when the transport received it (a command that arrived before the scan went out
  // answers an earlier one).
  void CommandReceived(int64_t wall_us) {
    if (pending_us_ == 0 || wall_us < pending_us_) return;
    if (samples_ms_.size() < kMaxSamples) samples_ms_.push_back((wall_us - pending_us_) * 1e-3);
    pending_us_ = 0;
  }
  // "n 412, median 2.31 ms, p99 9.80 ms, max 12.00 ms"; "" before the first sample.
  std::string Summary() {
    if (samples_ms_.empty()) return "";
    Sort();
    char text[160];
    std::snprintf(text, sizeof text, "n %zu, median %.2f ms, p99 %.2f ms, max %.2f ms", samples_ms_.size(),
                  Quantile(0.5), Quantile(0.99), samples_ms_.back());
    return text;
  }
  // {"transport": …, "n": …, "median_ms": …, "p99_ms": …, "max_ms": …}, written whole or not at all.
  void WriteJson(const std::string& path, const std::string& transport) {
    if (samples_ms_.empty()) return;
    Sort();
    {
      std::ofstream out(path + ".tmp", std::ios::trunc);
      out << "{\"transport\": \"" << transport << "\", \"n\": " << samples_ms_.size()
          << ", \"median_ms\": " << Quantile(0.5) << ", \"p99_ms\": " << Quantile(0.99)
          << ", \"max_ms\": " << samples_ms_.back() << "}\n";
      if (!out) return;
    }
    std::rename((path + ".tmp").c_str(), path.c_str());
  }

 private:
  static constexpr size_t kMaxSamples = 1 << 20;
  void Sort() { std::sort(samples_ms_.begin(), samples_ms_.end()); }
  double Quantile(double q) const {
    const size_t i = std::min(samples_ms_.size() - 1, static_cast<size_t>(q * double(samples_ms_.size())));
    return samples_ms_[i];
  }
  int64_t pending_us_ = 0;
  std::vector<double> samples_ms_;
};

}  // namespace mbot::msgs
