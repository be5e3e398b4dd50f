// A stage type and a transport added from this file alone, registered at run time, run in a
// pipeline with two outputs at once (the test's own wire and the LCM transport's log); and the
// outputs' queues: a slow output drops the oldest of a kind (counted), never stalls the run, and
// max_rate_hz thins a kind in data time.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "mbot/common/config.hpp"
#include "mbot/msgs/outputs.hpp"
#include "mbot/msgs/visitor.hpp"
#include "mbot/pipeline/pipeline.hpp"

namespace mbot::app {
namespace {

using msgs::Event;
using msgs::EventKind;

// The test's wire format: one line per pose, "<t_us> <channel> <kind> <x> <y> <theta>".
class WireWriter : public msgs::EventVisitor {
 public:
  explicit WireWriter(std::ostream& out) : out_(out) {}
  bool Pose(const Event& e, const msgs::Pose2D& p) override {
    out_ << e.t_us << ' ' << e.channel << ' ' << msgs::KeyName(e.kind) << ' ' << p.x << ' ' << p.y << ' ' << p.theta
         << '\n';
    return true;
  }

 private:
  std::ostream& out_;
};

// Source "test_wire": reads that format back.
class WireSource : public msgs::Source {
 public:
  explicit WireSource(const std::string& path) : in_(path) {}
  std::optional<Event> Next() override {
    Event e;
    std::string kind;
    msgs::Pose2D p;
    if (!(in_ >> e.t_us >> e.channel >> kind >> p.x >> p.y >> p.theta)) return std::nullopt;
    e.stamp_us = e.t_us;
    e.kind = msgs::KindFromKey(kind).value_or(EventKind::kOther);
    e.payload = p;
    return e;
  }
  double Progress() const override { return 0.5; }
  std::string Format() const override { return "test wire"; }

 private:
  std::ifstream in_;
};

// Output "test_wire": what it is sent, in that format, written whole at Close.
class WireOutput : public msgs::Output {
 public:
  explicit WireOutput(std::string file) : file_(std::move(file)) {}
  void Open(const msgs::RunContext& ctx) override { path_ = ctx.output_dir + "/" + file_; }
  void Send(const Event& e) override { msgs::Visit(e, writer_); }
  void Close(bool) override { std::ofstream(path_) << text_.str(); }

 private:
  std::string file_, path_;
  std::ostringstream text_;
  WireWriter writer_{text_};
};

// Output "test_slow": takes 2 ms per event, counts what it got.
std::atomic<int> g_slow_received{0};
class SlowOutput : public msgs::Output {
 public:
  void Send(const Event&) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ++g_slow_received;
  }
};

// Stage "test_double": a pose estimate at twice each odometry pose.
class DoubleStage : public msgs::Stage {
 public:
  void Start(const msgs::RunContext& ctx) override { bus_ = ctx.bus; }
  void OnEvent(const Event& e) override {
    if (e.kind != EventKind::kOdometry) return;
    const auto& p = std::get<msgs::Pose2D>(e.payload);
    bus_->Emit(this, Event{e.t_us, e.t_us, "SLAM_POSE", EventKind::kPoseEstimate, msgs::Pose2D{2 * p.x, 2 * p.y, 0}});
  }
  void Finish(const msgs::RunContext&, bool) override {}

 private:
  msgs::Bus* bus_ = nullptr;
};

void RegisterTestTypes() {
  if (msgs::FindStageType("test_double")) return;
  msgs::RegisterStageType({"test_double", "twice the odometry", [](config::Section&) -> std::unique_ptr<msgs::Stage> {
                             return std::make_unique<DoubleStage>();
                           }});
  msgs::RegisterSourceType({"test_wire", "the test's wire format", nullptr, 0, nullptr,
                            [](const msgs::SourceOptions& o) { return std::make_unique<WireSource>(o.path); }});
  msgs::RegisterOutputType({"test_wire", "the test's wire format",
                            [](config::Section& s) -> std::unique_ptr<msgs::Output> {
                              return std::make_unique<WireOutput>(s.GetString("file", "wire.txt", "file"));
                            },
                            true, ""});
  msgs::RegisterOutputType(
      {"test_slow", "a slow output",
       [](config::Section&) -> std::unique_ptr<msgs::Output> { return std::make_unique<SlowOutput>(); }, false, ""});
}

std::string Read(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string WriteOdometry(const std::string& name, int n) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream out(path);
  for (int i = 0; i < n; ++i) out << i * 20000 << " MBOT_ODOMETRY odometry " << i * 0.01 << " 0.5 0\n";
  return path;
}

TEST(Transport, AStageAndATransportFromATestFileRunWithTwoOutputs) {
  RegisterTestTypes();
  const std::string in = WriteOdometry("wire_in.txt", 50);
  const std::string out = ::testing::TempDir() + "/two_outputs";
  std::filesystem::remove_all(out);
  auto plan = pipeline::BuildPlan(
      config::Config::FromString("[pipeline]\nstages = twice\noutputs = wire, record\nprogress = off\n"
                                 "[source]\ntype = test_wire\npath = " +
                                     in + "\n[output]\ndir = " + out +
                                     "\n[twice]\ntype = test_double\n"
                                     "[wire]\ntype = test_wire\nfile = wire_out.txt\n"
                                     "[record]\ntype = lcm_log\nfile = run.log\n",
                                 "t.ini"));
  std::atomic<bool> stop{false};
  const pipeline::RunSummary summary = pipeline::RunPlan(plan, stop);
  EXPECT_EQ(summary.events, 50);
  ASSERT_EQ(summary.outputs.size(), 2u);
  for (const auto& [name, counts] : summary.outputs) {
    EXPECT_EQ(counts.sent, 100) << name;  // every source event and every emitted one
    EXPECT_EQ(counts.dropped_total(), 0) << name;
    EXPECT_TRUE(counts.error.empty()) << name << ": " << counts.error;
  }
  // The test's wire: each odometry pose, then the stage's answer to it, in the run's order.
  std::istringstream wire(Read(out + "/wire_out.txt"));
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(wire, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), 100u);
  EXPECT_EQ(lines[2], "20000 MBOT_ODOMETRY odometry 0.01 0.5 0");
  EXPECT_EQ(lines[3], "20000 SLAM_POSE pose_estimate 0.02 1 0");

  // The LCM log, read back by the LCM transport's own source: the same events.
  msgs::SourceOptions o;
  o.path = out + "/run.log";
  auto log = msgs::OpenSource(o);
  int odometry = 0, other = 0;
  while (auto e = log->Next()) {
    if (e->channel == "MBOT_ODOMETRY" && e->kind == EventKind::kOdometry) ++odometry;
    if (e->channel == "SLAM_POSE") ++other;
  }
  EXPECT_EQ(odometry, 50);
  EXPECT_EQ(other, 50);
}

TEST(Transport, ASlowOutputDropsTheOldestAndNeverStallsTheRun) {
  RegisterTestTypes();
  g_slow_received = 0;
  const std::string in = WriteOdometry("wire_slow.txt", 2000);
  auto plan = pipeline::BuildPlan(config::Config::FromString(
      "[pipeline]\nstages = twice\noutputs = slow, thin\nprogress = off\n[source]\ntype = test_wire\npath = " + in +
          "\n[output]\ndir = " + ::testing::TempDir() +
          "/slow_output\n[twice]\ntype = test_double\n"
          "[slow]\ntype = test_slow\nqueue_per_kind = 4\n"
          "[thin]\ntype = test_wire\nmax_rate_hz = odometry:5\nchannels = MBOT_ODOMETRY\n",
      "t.ini"));
  std::atomic<bool> stop{false};
  const pipeline::RunSummary summary = pipeline::RunPlan(plan, stop);
  ASSERT_EQ(summary.outputs.size(), 2u);
  const msgs::OutputCounts& slow = summary.outputs[0].second;
  // 4000 events at 2 ms each would take 8 s; the run did not wait for them.
  EXPECT_GT(slow.dropped_total(), 1000);
  EXPECT_EQ(slow.sent + slow.dropped_total(), 4000);
  EXPECT_EQ(slow.sent, g_slow_received.load());
  EXPECT_GT(slow.dropped.at(EventKind::kOdometry), 0);
  EXPECT_GT(slow.dropped.at(EventKind::kPoseEstimate), 0);
  EXPECT_NE(slow.ToString().find("dropped (odometry"), std::string::npos) << slow.ToString();
  // 2000 odometry events 20 ms apart (40 s of data) at most 5 per second: one in ten.
  const msgs::OutputCounts& thin = summary.outputs[1].second;
  EXPECT_EQ(thin.offered, 2000);  // SLAM_POSE is not on its channel list
  EXPECT_EQ(thin.sent, 200);
  EXPECT_EQ(thin.rate_limited, 1800);
}

TEST(Transport, OutputKeysAreChecked) {
  RegisterTestTypes();
  auto error = [](const std::string& extra) {
    try {
      pipeline::BuildPlan(
          config::Config::FromString("[pipeline]\nstages = twice\noutputs = o\n[source]\ntype = test_wire\n"
                                     "path = x\n[twice]\ntype = test_double\n[o]\n" +
                                         extra,
                                     "t.ini"));
    } catch (const config::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("type = nope\n").find("unknown output type 'nope' (known:"), std::string::npos);
  EXPECT_NE(error("type = test_wire\nmax_rate_hz = maps:1\n").find("[o] max_rate_hz: 'maps:1' is not kind:rate"),
            std::string::npos);
  EXPECT_NE(error("type = test_wire\nmax_rate_hz = map:0\n").find("the rate must be in (0, 1e6] Hz"),
            std::string::npos);
  EXPECT_NE(error("type = test_wire\nbogus = 1\n").find("[o] bogus: unknown key"), std::string::npos);
  // The ros2 output only publishes: the scan-mount keys of the ros2_live source are not its keys.
  EXPECT_NE(error("type = ros2\nrobot_frame = base_link\n").find("[o] robot_frame: unknown key"), std::string::npos);
  EXPECT_NE(error("type = ros2\nwait_for_mount_s = 1\n").find("[o] wait_for_mount_s: unknown key"), std::string::npos);
  EXPECT_NE(error("type = lcm\nrename = LIDAR:/scan, SLAM_POSE:/scan\n").find("'/scan' names two topics"),
            std::string::npos);
}

}  // namespace
}  // namespace mbot::app
