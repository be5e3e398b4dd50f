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

#include "mbot/common/files.hpp"
#include "mbot/common/log.hpp"
#include "mrpt_read.hpp"
#include "mrpt_scan.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

// The rawlog's entries, as MRPT's CRawlog::loadFromRawLogFile reads them (one CRawlog object, or a
// sequence of sensory frames, action collections and observations) — except that a record cut short
// is reported in *cut instead of ending the read quietly. Reads at most `max_records` records and
// counts them in *records. False when the file cannot be opened.
bool LoadRawlog(const std::string& path, mrpt::obs::CRawlog* rawlog, std::string* cut, uint64_t* records,
                uint64_t max_records) {
  mrpt::io::CFileGZInputStream fs;
  if (!fs.open(path)) return false;
  auto arch = mrpt::serialization::archiveFrom(fs);
  for (;; ++*records) {
    if (*records >= max_records) return true;
    mrpt::serialization::CSerializable::Ptr obj;
    try {
      obj = arch.ReadObject();
    } catch (const mrpt::serialization::CExceptionEOF&) {
      return true;  // the end, at a record boundary
    } catch (const std::bad_alloc&) {
      throw;  // the trial read reports it with the record's number
    } catch (const std::exception& e) {
      const std::string why = MrptReason(e.what());
      if (why.find("bad_alloc") != std::string::npos) throw std::bad_alloc();
      *cut = "a record it could not read (" + why + ")";
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
  mrpt::obs::CRawlog rawlog;
  std::string cut;
  bool ok = false;
  RequireReadableFile(options.path);
  // A record that crashes MRPT's reader or asks for more memory than the file could need is found in
  // a child first; the records before it are kept, like a file cut short.
  const MrptTrial trial = TrialReadMrpt(options.path, [&](uint64_t* records) {
    mrpt::obs::CRawlog scratch;
    std::string scratch_cut;
    LoadRawlog(options.path, &scratch, &scratch_cut, records, UINT64_MAX);
  });
  uint64_t records = 0;
  try {
    ok = LoadRawlog(options.path, &rawlog, &cut, &records, trial.ok ? UINT64_MAX : trial.records);
  } catch (const std::exception& e) {
    throw std::runtime_error(options.path + ": cannot read MRPT rawlog: " + MrptReason(e.what()));
  }
  if (!trial.ok) cut = "record " + std::to_string(trial.records + 1) + ": " + trial.reason;
  if (!ok) throw std::runtime_error(options.path + ": cannot read MRPT rawlog");
  if (!cut.empty()) {
    diagnostics_.truncated_tail = true;
    mbot::log::Warn(options.path + ": the rawlog stops after " + std::to_string(rawlog.size()) + " entries, at " + cut +
                    "; keeping what was read");
  }
  if (rawlog.size() == 0) mbot::log::Warn(options.path + ": the rawlog holds no entries");

  msgs::Pose2D odom;  // integrated from the actions of the Actions/SensoryFrame format
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
      ev.payload = msgs::Pose2D{od->odometry.x(), od->odometry.y(), od->odometry.phi()};
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
