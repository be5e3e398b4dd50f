// `trajectory_writer`: the pose channels of a dataset as TUM trajectories (t x y z qx qy qz qw),
// one file per role: odometry, ground truth, reference (e.g. the staff SLAM pose in a log).
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using msgs::EventKind;

struct TrajectoryWriterOptions {
  std::string odometry_file = "odometry.tum";
  std::string ground_truth_file = "ground_truth.tum";
  std::string reference_file = "reference.tum";
};

class TrajectoryWriterStage : public Stage {
 public:
  explicit TrajectoryWriterStage(TrajectoryWriterOptions o) : options_(std::move(o)) {}

  void OnEvent(const msgs::Event& ev) override {
    if (ev.kind != EventKind::kOdometry && ev.kind != EventKind::kGroundTruth && ev.kind != EventKind::kReferencePose) {
      return;
    }
    const auto* pose = std::get_if<motion::Pose2D>(&ev.payload);
    if (!pose) return;
    Track& track = tracks_[ev.kind];
    if (track.channel.empty()) track.channel = ev.channel;
    if (track.channel != ev.channel) {
      mbot::log::WarnOnce("trajectory_writer:" + ev.channel,
                          "trajectory_writer: " + std::string(msgs::ToString(ev.kind)) + " channel " + ev.channel +
                              " ignored; writing " + track.channel);
      return;
    }
    track.text += TumLine(ev.t_us * 1e-6, pose->x, pose->y, pose->theta);
  }

  void Finish(const RunContext& ctx, bool /*interrupted*/) override {
    const std::map<EventKind, std::string> files = {{EventKind::kOdometry, options_.odometry_file},
                                                    {EventKind::kGroundTruth, options_.ground_truth_file},
                                                    {EventKind::kReferencePose, options_.reference_file}};
    for (const auto& [kind, track] : tracks_) {
      const std::string& name = files.at(kind);
      if (name.empty()) continue;
      const std::string path = ctx.output_dir + "/" + name;
      WriteFileAtomically(path, [&](std::ostream& o) {
        o << "# " << msgs::ToString(kind) << " from channel " << track.channel << ": t x y z qx qy qz qw\n"
          << track.text;
      });
      mbot::log::Info("wrote " + path);
    }
  }

 private:
  struct Track {
    std::string channel;
    std::string text;
  };
  TrajectoryWriterOptions options_;
  std::map<EventKind, Track> tracks_;
};

}  // namespace

static StageType TrajectoryWriterStageType() {
  return {"trajectory_writer", "writes the odometry, ground-truth and reference pose channels as TUM trajectories",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            TrajectoryWriterOptions o;
            o.odometry_file =
                s.GetString("odometry_file", o.odometry_file, "odometry trajectory in output.dir ('' for none)");
            o.ground_truth_file = s.GetString("ground_truth_file", o.ground_truth_file,
                                              "ground-truth trajectory in output.dir ('' for none)");
            o.reference_file = s.GetString("reference_file", o.reference_file,
                                           "reference-pose trajectory (e.g. staff SLAM) in output.dir ('' for none)");
            return std::make_unique<TrajectoryWriterStage>(o);
          }};
}

const RegisterStage kTrajectoryWriterRegistered{TrajectoryWriterStageType()};

}  // namespace mbot::app
