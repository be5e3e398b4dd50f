// Where the stack's outputs go. The source's own sink (the simulator, a live bus) takes the events
// the stages emit, in order, synchronously: it drives the robot. Outputs ([pipeline] outputs: a
// transport publishing to a viewer, a recorder) take every event of the run through a bounded queue
// on their own thread (msgs/outputs.hpp), so a slow one never stalls the autonomy.
#pragma once

#include <string>

#include "mbot/msgs/events.hpp"

namespace mbot::msgs {

class Sink {
 public:
  virtual ~Sink() = default;
  // Called in time order with events the stages emitted; a sink ignores the kinds it has no use for.
  virtual void Send(const Event& event) = 0;
};

}  // namespace mbot::msgs
