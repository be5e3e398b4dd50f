// The mission stage on a synthetic event stream (no simulator): what it commands and reports.
#include <gtest/gtest.h>

#include "mbot/common/config.hpp"
#include "stages/stages.hpp"

namespace mbot::app {
namespace {

class CaptureBus : public Bus {
 public:
  void Emit(const Stage*, const msgs::Event& e) override { events.push_back(e); }
  void RequestStop(const std::string&) override {}
  std::vector<msgs::Event> events;
};

// task = follow (the botlab's motion controller behaviour, live): stand still until a GUI sends a
// path on CONTROLLER_PATH, then drive it; the path is not published back.
TEST(MissionFollow, DrivesThePathAGuiSendsAndStandsStillBefore) {
  auto c = config::Config::FromString("[mission]\ntype = mission\ntask = follow\nstart_delay_s = 0\n");
  config::Section section = c.GetSection("mission");
  std::unique_ptr<Stage> mission = msgs::FindStageType("mission")->create(section);
  CaptureBus bus;
  RunContext ctx{::testing::TempDir(), 1, nullptr, "", &bus};
  mission->Start(ctx);
  using msgs::Event;
  using msgs::EventKind;
  const msgs::Pose2D origin{0, 0, 0};
  mission->OnEvent(Event{0, 0, "SLAM_POSE", EventKind::kPoseEstimate, origin});
  int64_t t = 0;
  auto odometry = [&](double seconds) {
    for (int i = 0; i < seconds * 50; ++i, t += 20'000)
      mission->OnEvent(Event{t, t, "MBOT_ODOMETRY", EventKind::kOdometry, origin});
  };
  auto max_speed = [&] {
    double v = 0;
    for (const Event& e : bus.events) {
      if (e.kind == EventKind::kMotorCommand) v = std::max(v, std::get<msgs::MotorCommand>(e.payload).velocity.v_m_s);
    }
    return v;
  };
  odometry(0.5);
  EXPECT_EQ(max_speed(), 0.0);
  bool waiting = false;
  for (const Event& e : bus.events)
    waiting = waiting || (e.kind == EventKind::kMissionStatus &&
                          std::get<msgs::MissionStatus>(e.payload).state == msgs::MissionState::kWaiting);
  EXPECT_TRUE(waiting);
  bus.events.clear();
  mission->OnEvent(Event{t, t, "CONTROLLER_PATH", EventKind::kPath, msgs::Path{{{1.0, 0.0, 0.0}}}});
  odometry(0.5);
  EXPECT_GT(max_speed(), 0.05);
  for (const Event& e : bus.events) EXPECT_NE(e.kind, EventKind::kPath) << "the GUI's path was published back";
}

}  // namespace
}  // namespace mbot::app
