// The simulator as a source and a sink: a SimRobot on a World, stepped in simulated time as events
// are asked for, driven by the velocity commands sent back to it. Time comes from the simulation, so
// a run goes as fast as the pipeline consumes it, or, with realtime_factor > 0, that many times the
// wall clock (the simulated robot on the LCM bus).
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mbot/sim/sim_robot.hpp"
#include "mbot/sim/world.hpp"
#include "mbot/msgs/sink.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/sim/sim_source_options.hpp"

namespace mbot::sim {

class SimSource : public msgs::Source, public msgs::Sink {
 public:
  msgs::Sink* sink() override { return this; }
  // Loads options.path as the world (World::Load) and places the robot at sim.start, or at the
  // world's `start` pose; options.seed seeds its noise. Throws std::runtime_error naming the path
  // (and [source] start when the world has no start pose) or std::invalid_argument when the start
  // collides.
  SimSource(const msgs::SourceOptions& options, const SimSourceOptions& sim);
  SimSource(const SimSource&) = delete;  // the robot holds a reference to world_
  SimSource& operator=(const SimSource&) = delete;

  // The robot's events in time order. The robot is simulated one physics step at a time, only as
  // far as needed to produce the next event, so a command sent in reaction to an event takes effect
  // at (at most one physics step after) that event's time. nullopt at duration_s or after RequestEnd().
  std::optional<Event> Next() override;
  // Simulated time / duration.
  double Progress() const override;
  std::string Format() const override { return "simulator"; }
  std::vector<std::pair<std::string, std::string>> Details() const override;

  // A kMotorCommand of Kind::kVelocity becomes the robot's command (held until the next one); every
  // other event is ignored.
  void Send(const Event& event) override;
  // Ends the stream: the next Next() returns nullopt (events simulated but not yet returned are dropped).
  void RequestEnd() { ended_ = true; }

  const SimRobot& robot() const { return *robot_; }
  const World& world() const { return world_; }
  const motion::Pose2D& start() const { return start_; }

 private:
  std::string path_;
  uint64_t seed_;
  int64_t duration_us_;
  World world_;
  motion::Pose2D start_;
  std::unique_ptr<SimRobot> robot_;
  double realtime_factor_ = 0;
  bool paced_ = false;
  std::chrono::steady_clock::time_point wall0_;  // wall time of simulated time 0
  std::vector<Event> buffer_;
  size_t next_ = 0;
  bool ended_ = false;
};

// Registers the source type `sim` (an `.arena` path is detected as one; its keys are
// SimSourceOptions'). Called once by the application before it parses a configuration; a second
// call does nothing.
void RegisterSimSource();

}  // namespace mbot::sim
