#include "motor_samples_source.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "mbot/common/strings.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::vector<std::string> SplitCommas(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string field;
  while (std::getline(ss, field, ',')) out.push_back(Trim(field));
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

bool IsHeader(const std::string& line) {
  std::string compact;
  for (char c : Lower(line)) {
    if (!std::isspace(static_cast<unsigned char>(c))) compact += c;
  }
  return compact == "channel,duty,speed";
}

bool ParseNumber(const std::string& s, double* v) {
  if (s.empty()) return false;
  char* end = nullptr;
  *v = std::strtod(s.c_str(), &end);
  return end && *end == '\0' && std::isfinite(*v);
}

}  // namespace

bool IsMotorSamplesFile(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    line = Trim(line);
    if (line.empty() || line[0] == '#') continue;
    if (IsHeader(line)) return true;
    const auto f = SplitCommas(line);
    double v;
    return f.size() == 3 && ParseNumber(f[0], &v) && ParseNumber(f[1], &v) && ParseNumber(f[2], &v);
  }
  return false;
}

MotorSamplesSource::MotorSamplesSource(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  int lineno = 0;
  bool header_allowed = true;
  while (std::getline(in, line)) {
    ++lineno;
    line = Trim(line);
    if (line.empty() || line[0] == '#') continue;
    if (header_allowed && IsHeader(line)) {
      header_allowed = false;
      continue;
    }
    header_allowed = false;
    const std::string where = path + ":" + std::to_string(lineno) + ": ";
    const auto f = SplitCommas(line);
    if (f.size() != 3) {
      throw std::runtime_error(where + "expected 3 fields 'channel,duty,speed', got " + std::to_string(f.size()));
    }
    double channel, duty, speed;
    if (!ParseNumber(f[0], &channel) || channel != std::floor(channel) || channel < 0 || channel > 16) {
      throw std::runtime_error(where + "channel '" + f[0] + "' is not a motor channel number (0-16)");
    }
    if (!ParseNumber(f[1], &duty) || std::abs(duty) > 1.0) {
      throw std::runtime_error(where + "duty '" + f[1] + "' is not a number in [-1, 1]");
    }
    if (!ParseNumber(f[2], &speed))
      throw std::runtime_error(where + "speed '" + f[2] + "' is not a finite number [rad/s]");
    Event ev;
    ev.t_us = ev.stamp_us = static_cast<int64_t>(events_.size()) * 1000;
    ev.channel = "motor_samples";
    ev.kind = EventKind::kMotorSample;
    ev.payload = WheelSample{static_cast<int>(channel), duty, speed};
    events_.push_back(std::move(ev));
  }
  if (events_.empty()) throw std::runtime_error(path + ": no samples (expected lines 'channel,duty,speed')");
  channels_["motor_samples"] = ChannelInfo{"channel,duty,speed CSV", "", EventKind::kMotorSample, true};
}

std::optional<Event> MotorSamplesSource::Next() {
  if (next_ >= events_.size()) return std::nullopt;
  return events_[next_++];
}

double MotorSamplesSource::Progress() const { return events_.empty() ? 1.0 : double(next_) / events_.size(); }

}  // namespace mbot::drivers
