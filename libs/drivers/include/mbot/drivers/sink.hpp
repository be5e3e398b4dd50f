// Where the stack's outputs go: velocity commands, poses, maps, paths, statuses. The simulator is a
// sink (it drives its robot with the commands), live LCM is one (it publishes them), a recorder is one.
#pragma once

#include "mbot/drivers/events.hpp"

namespace mbot::drivers {

class Sink {
 public:
  virtual ~Sink() = default;
  // Called in time order with events the stages emitted; a sink ignores the kinds it has no use for.
  virtual void Send(const Event& event) = 0;
};

}  // namespace mbot::drivers
