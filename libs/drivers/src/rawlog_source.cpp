#include "rawlog_source.hpp"

#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "mbot/common/log.hpp"
#include "mrpt_scan.hpp"

namespace mbot::drivers {
namespace {

// The line of an MRPT exception that says what happened (its text after "Message:"), else its first.
std::string MrptMessage(const std::string& what) {
  const size_t m = what.find("Message:");
  const size_t b = m == std::string::npos ? 0 : what.find_first_not_of(' ', m + 8);
  const std::string line = what.substr(b == std::string::npos ? 0 : b);
  return line.substr(0, line.find('\n'));
}

// The rawlog's entries, as MRPT's CRawlog::loadFromRawLogFile reads them (one CRawlog object, or a
// sequence of sensory frames, action collections and observations) — except that a record cut short
// is reported in *cut instead of ending the read quietly. False when the file cannot be opened.
bool LoadRawlog(const std::string& path, mrpt::obs::CRawlog* rawlog, std::string* cut) {
  mrpt::io::CFileGZInputStream fs;
  if (!fs.open(path)) return false;
  auto arch = mrpt::serialization::archiveFrom(fs);
  for (;;) {
    mrpt::serialization::CSerializable::Ptr obj;
    try {
      obj = arch.ReadObject();
    } catch (const mrpt::serialization::CExceptionEOF&) {
      return true;  // the end, at a record boundary
    } catch (const std::exception& e) {
      *cut = "a record it could not read (" + MrptMessage(e.what()) + ")";
      return true;
    }
    if (auto whole = std::dynamic_pointer_cast<mrpt::obs::CRawlog>(obj)) {
      *rawlog = std::move(*whole);
    } else if (std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj) ||
               std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(obj) ||
               std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj)) {
      rawlog->insert(obj);
    } else {
      *cut = std::string("an object of class ") + (obj ? obj->GetRuntimeClass()->className : "null") +
             ", which a rawlog does not hold";
      return true;
    }
  }
}

int64_t ToMicros(mrpt::Clock::time_point t) {
  if (t == mrpt::Clock::time_point()) return INT64_MIN;
  return static_cast<int64_t>(std::llround(mrpt::Clock::toDouble(t) * 1e6));
}

std::string ClassName(const mrpt::rtti::CObject& o) {
  const std::string name = o.GetRuntimeClass()->className;
  const auto colon = name.rfind("::");
  return colon == std::string::npos ? name : name.substr(colon + 2);
}

std::string Label(const mrpt::obs::CObservation& obs) {
  return obs.sensorLabel.empty() ? ClassName(obs) : obs.sensorLabel;
}

}  // namespace

RawlogSource::RawlogSource(const SourceOptions& options) {
  if (!std::filesystem::is_regular_file(options.path)) throw std::runtime_error(options.path + ": no such file");
  mrpt::obs::CRawlog rawlog;
  std::string cut;
  bool ok = false;
  try {
    ok = LoadRawlog(options.path, &rawlog, &cut);
  } catch (const std::exception& e) {
    throw std::runtime_error(options.path + ": cannot read MRPT rawlog: " + MrptMessage(e.what()));
  }
  if (!ok) throw std::runtime_error(options.path + ": cannot read MRPT rawlog");
  if (!cut.empty()) {
    diagnostics_.truncated_tail = true;
    mbot::log::Warn(options.path + ": the rawlog stops after " + std::to_string(rawlog.size()) + " entries, at " + cut +
                    "; keeping what was read");
  }
  if (rawlog.size() == 0) mbot::log::Warn(options.path + ": the rawlog holds no entries");

  motion::Pose2D odom;  // integrated from the actions of the Actions/SensoryFrame format
  // Entries without a timestamp are marked INT64_MIN and filled in below.
  auto stamp = [&](int64_t t) {
    if (t == INT64_MIN) ++invalid_stamps_;
    return t;
  };
  auto add_observation = [&](const mrpt::obs::CObservation::Ptr& obs) {
    Event ev;
    ev.t_us = stamp(ToMicros(obs->timestamp));
    ev.stamp_us = ev.t_us;
    ev.channel = Label(*obs);
    auto& info = channels_[ev.channel];
    info.type = ClassName(*obs);
    if (auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(obs)) {
      ev.kind = EventKind::kLidar;
      ev.payload = FromMrptScan(*scan);
    } else if (auto od = std::dynamic_pointer_cast<mrpt::obs::CObservationOdometry>(obs)) {
      ev.kind = EventKind::kOdometry;
      ev.payload = motion::Pose2D{od->odometry.x(), od->odometry.y(), od->odometry.phi()};
      if (od->hasEncodersInfo) {
        Event enc = ev;
        enc.kind = EventKind::kEncoders;
        enc.channel = ev.channel + ".encoders";
        enc.payload = EncoderTicks{0, 0, od->encoderLeftTicks, od->encoderRightTicks, 0};
        channels_[enc.channel] = ChannelInfo{"CObservationOdometry (encoders)", "", EventKind::kEncoders, true};
        events_.push_back(std::move(enc));
      }
    } else {
      ev.kind = EventKind::kOther;
    }
    info.kind = ev.kind;
    events_.push_back(std::move(ev));
  };

  for (size_t i = 0; i < rawlog.size(); ++i) {
    switch (rawlog.getType(i)) {
      case mrpt::obs::CRawlog::etActionCollection: {
        ++actions_;
        auto acts = rawlog.getAsAction(i);
        for (size_t k = 0; k < acts->size(); ++k) {
          auto act = acts->get(k);
          auto mov = std::dynamic_pointer_cast<mrpt::obs::CActionRobotMovement2D>(act);
          if (!mov) continue;
          const auto inc = mov->rawOdometryIncrementReading;
          odom = odom.Compose({inc.x(), inc.y(), inc.phi()});
          Event ev;
          ev.t_us = stamp(ToMicros(mov->timestamp));
          ev.stamp_us = ev.t_us;
          ev.channel = "ACTION_ODOMETRY";
          ev.kind = EventKind::kOdometry;
          ev.payload = odom;
          channels_[ev.channel] = ChannelInfo{"CActionRobotMovement2D (integrated)", "", EventKind::kOdometry, true};
          events_.push_back(std::move(ev));
        }
        break;
      }
      case mrpt::obs::CRawlog::etSensoryFrame: {
        ++sensory_frames_;
        auto sf = rawlog.getAsObservations(i);
        for (const auto& obs : *sf) add_observation(obs);
        break;
      }
      case mrpt::obs::CRawlog::etObservation:
        ++observations_;
        add_observation(rawlog.getAsObservation(i));
        break;
      default: break;
    }
  }
  // An entry without timestamp takes the time of the entry before it (or after it, at the start).
  int64_t last_t = INT64_MIN;
  for (auto& ev : events_) {
    if (ev.t_us == INT64_MIN)
      ev.t_us = ev.stamp_us = last_t;
    else
      last_t = ev.t_us;
  }
  last_t = INT64_MIN;
  for (auto it = events_.rbegin(); it != events_.rend(); ++it) {
    if (it->t_us == INT64_MIN)
      it->t_us = it->stamp_us = last_t;
    else
      last_t = it->t_us;
  }
  if (last_t == INT64_MIN) {
    for (auto& ev : events_) ev.t_us = ev.stamp_us = 0;
  }
  if (invalid_stamps_) {
    mbot::log::Warn(options.path + ": " + std::to_string(invalid_stamps_) +
                    " entries have no timestamp; they take the time of the entry before them");
  }
  std::stable_sort(events_.begin(), events_.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
}

std::optional<Event> RawlogSource::Next() {
  if (next_ >= events_.size()) return std::nullopt;
  return std::move(events_[next_++]);
}

double RawlogSource::Progress() const { return events_.empty() ? 1.0 : double(next_) / double(events_.size()); }

std::string RawlogSource::Format() const {
  return sensory_frames_ > 0 || actions_ > 0 ? "MRPT rawlog (actions / sensory frames)"
                                             : "MRPT rawlog (observations only)";
}

std::vector<std::pair<std::string, std::string>> RawlogSource::Details() const {
  std::vector<std::pair<std::string, std::string>> d;
  d.emplace_back("actions", std::to_string(actions_));
  d.emplace_back("sensory frames", std::to_string(sensory_frames_));
  d.emplace_back("stand-alone observations", std::to_string(observations_));
  if (invalid_stamps_) d.emplace_back("entries without timestamp", std::to_string(invalid_stamps_));
  return d;
}

}  // namespace mbot::drivers
