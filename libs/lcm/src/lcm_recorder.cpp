#include "mbot/lcm/lcm_recorder.hpp"

#include "lcm_messages.hpp"
#include "mbot/lcm/lcm_log.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary

LcmRecorder::LcmRecorder(const std::string& path) : writer_(std::make_unique<LcmLogWriter>(path)) {}

LcmRecorder::~LcmRecorder() = default;

bool LcmRecorder::Record(const Event& event) {
  std::vector<uint8_t> data;
  if (!lcm_adapter::Encode(event, &data)) {
    ++skipped_[event.channel];
    return false;
  }
  writer_->Write(event.t_us, event.channel, data.data(), data.size());
  ++recorded_;
  return true;
}

void LcmRecorder::Close() { writer_->Close(); }

}  // namespace mbot::lcmio
