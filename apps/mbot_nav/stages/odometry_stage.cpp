// `odometry`: recomputes a log's dead reckoning from its encoder and IMU channels in every heading
// mode (encoders alone, gyrodometry, complementary, IMU yaw) and scores each against the ground
// truth: TUM trajectories, a picture of the paths, and odometry.json (ATE aligned and anchored at
// the first pose, final-pose error).
#include <cmath>
#include <map>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/motion/gyrodometry.hpp"
#include "mbot/motion/trajectory_error.hpp"
#include "mbot/motion/motion_config.hpp"
#include "mbot/reports/json.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using motion::HeadingSource;
using motion::Pose2D;
using motion::TimedPose;
using msgs::EventKind;

const std::map<std::string, HeadingSource> kHeadings = {{"encoders", HeadingSource::kEncoders},
                                                        {"gyrodometry", HeadingSource::kGyrodometry},
                                                        {"complementary", HeadingSource::kComplementary},
                                                        {"imu_yaw", HeadingSource::kImuYaw}};

struct OdometryStageOptions {
  motion::WheelOdometryOptions wheels;
  motion::GyrodometryOptions fusion;
  std::vector<std::string> headings = {"encoders", "gyrodometry", "complementary", "imu_yaw"};
  double max_pose_gap_s = 0.2;
  int png_pixels_per_m = 300;
  bool use_stamps = true;
};

class OdometryStage : public Stage {
 public:
  explicit OdometryStage(OdometryStageOptions o) : options_(std::move(o)) {}

  // Built here rather than in the constructor: `--list-stages` constructs every stage with its
  // defaults, which hold no wheel constants.
  void Start(const RunContext& /*ctx*/) override {
    for (const auto& h : options_.headings) {
      motion::GyrodometryOptions f = options_.fusion;
      f.heading = kHeadings.at(h);
      variants_.push_back({h, motion::Gyrodometry(options_.wheels, f), {}});
    }
  }

  void OnEvent(const msgs::Event& ev) override {
    // Rates are integrated on the robot's own clock (message stamps): logged events can arrive in
    // bursts, and a burst would stretch or squeeze the integration.
    const int64_t t = options_.use_stamps && ev.stamp_us > 0 ? ev.stamp_us : ev.t_us;
    if (ev.kind == EventKind::kImu) {
      const auto& imu = std::get<msgs::Imu>(ev.payload);
      for (auto& v : variants_) v.odometry.AddImu(t, imu.gyro_rad_s[2], imu.angles_rpy_rad[2], imu.has_angles);
      ++imu_count_;
    } else if (ev.kind == EventKind::kEncoders) {
      const auto& e = std::get<msgs::EncoderTicks>(ev.payload);
      for (auto& v : variants_) v.track.push_back({ev.t_us, v.odometry.AddEncoders(t, e.left_ticks, e.right_ticks)});
    } else if (ev.kind == EventKind::kGroundTruth) {
      truth_.push_back({ev.t_us, std::get<Pose2D>(ev.payload)});
    }
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    if (variants_.empty() || variants_[0].track.empty()) {
      mbot::log::Warn("odometry: the source has no encoder messages; nothing to write");
      return;
    }
    if (imu_count_ == 0)
      mbot::log::Warn("odometry: the source has no IMU messages; every heading mode equals encoders");
    const int64_t gap = static_cast<int64_t>(options_.max_pose_gap_s * 1e6);
    reports::Json j = {{"source", ctx.source_path},
                       {"interrupted", interrupted},
                       {"imu_messages", imu_count_},
                       {"ground_truth", !truth_.empty()},
                       {"variants", reports::Json::object()}};
    std::vector<drivers::MapOverlay> overlays;
    const uint8_t colours[][3] = {{220, 40, 40}, {40, 90, 230}, {0, 160, 120}, {200, 120, 0}};
    std::vector<Pose2D> truth_paired_first;
    for (size_t k = 0; k < variants_.size(); ++k) {
      Variant& v = variants_[k];
      std::string tum = "# odometry (" + v.name + ") from encoders + IMU: t x y z qx qy qz qw\n";
      for (const auto& p : v.track) tum += TumLine(p.t_us * 1e-6, p.pose.x, p.pose.y, p.pose.theta);
      WriteFileAtomically(ctx.output_dir + "/odometry_" + v.name + ".tum", [&](std::ostream& o) { o << tum; });
      std::vector<Pose2D> est, truth;
      for (const auto& p : v.track) {
        Pose2D t;
        if (motion::InterpolateAt(truth_, p.t_us, gap, &t)) {
          est.push_back(p.pose);
          truth.push_back(t);
        }
      }
      reports::Json& vj = j["variants"][v.name];
      vj = {{"gyro_steps", v.odometry.gyro_steps()},
            {"gyro_bias_rad_s", reports::Number(v.odometry.gyro_bias_rad_s())}};
      drivers::MapOverlay path{{}, colours[k % 4][0], colours[k % 4][1], colours[k % 4][2], false, v.name};
      if (!est.empty()) {
        const motion::TrajectoryErrors errors = motion::EvaluateTrajectory(est, truth);
        const motion::AteResult& aligned = errors.aligned;
        const motion::AteResult& anchored = errors.anchored;
        vj["aligned"] = reports::AteJson(aligned);
        vj["anchored"] = reports::AteJson(anchored);
        mbot::log::Info("odometry: " + v.name + ": aligned xy RMSE " + Num(aligned.xy.rmse, 3) + " m, theta RMSE " +
                        Num(aligned.theta.rmse * 180 / M_PI, 3) + " deg; anchored final heading error " +
                        Num(anchored.final_error.theta * 180 / M_PI, 3) + " deg");
        for (const Pose2D& p : est) path.poses.push_back(anchored.alignment.Compose(p));
        if (truth_paired_first.empty()) truth_paired_first = truth;
      } else {
        for (const auto& p : v.track) path.poses.push_back(p.pose);
      }
      overlays.push_back(std::move(path));
    }
    if (!truth_paired_first.empty())
      overlays.push_back({truth_paired_first, 0, 0, 0, false, "ground truth (anchored frame)"});
    reports::WriteJson(ctx.output_dir + "/odometry.json", j);
    WritePicture(overlays, ctx.output_dir + "/odometry_comparison.png");
    mbot::log::Info("odometry: wrote odometry_*.tum, odometry.json and odometry_comparison.png in " + ctx.output_dir);
  }

 private:
  struct Variant {
    std::string name;
    motion::Gyrodometry odometry;
    std::vector<TimedPose> track;
  };

  void WritePicture(const std::vector<drivers::MapOverlay>& overlays, const std::string& path) const {
    double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
    for (const auto& o : overlays) {
      for (const Pose2D& p : o.poses)
        x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
    }
    if (x0 > x1) return;
    const double res = 1.0 / options_.png_pixels_per_m, margin = 0.3;
    const int w = static_cast<int>(std::ceil((x1 - x0 + 2 * margin) / res)),
              h = static_cast<int>(std::ceil((y1 - y0 + 2 * margin) / res));
    const mapping::OccupancyGrid blank(std::min(w, 4000), std::min(h, 4000), res, x0 - margin, y0 - margin, -60);
    drivers::WriteMapPngWithOverlays(blank, overlays, 1, path);
  }

  OdometryStageOptions options_;
  std::vector<Variant> variants_;
  std::vector<TimedPose> truth_;
  int imu_count_ = 0;
};

}  // namespace

static StageType OdometryStageType() {
  return {"odometry",
          "recomputes dead reckoning from encoders and IMU (encoders, gyrodometry, complementary, IMU yaw) and scores "
          "it against ground truth",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            OdometryStageOptions o;
            o.wheels = motion::ParseWheelConstants(s);
            o.headings = s.GetList("headings", o.headings,
                                   "heading modes to run: encoders, gyrodometry, complementary, imu_yaw");
            for (const auto& h : o.headings) {
              if (!kHeadings.count(h))
                s.Fail("headings", "unknown heading mode '" + h + "' (encoders, gyrodometry, complementary, imu_yaw)");
            }
            o.fusion.threshold_rad_s =
                s.GetDouble("threshold_rad_s", o.fusion.threshold_rad_s,
                            "gyrodometry: use the gyro when gyro and encoder turn rates differ by more than this", 0.0);
            o.fusion.gyro_weight = s.GetDouble("gyro_weight", o.fusion.gyro_weight,
                                               "complementary: share of the gyro's heading change", 0.0, 1.0);
            o.fusion.gyro_scale =
                s.GetDouble("gyro_scale", o.fusion.gyro_scale,
                            "multiplies the gyro's yaw rate (0.0174533 for a gyro reporting deg/s)", -100.0, 100.0);
            o.use_stamps =
                s.GetChoice("clock", "stamp", {"stamp", "event"},
                            "integrate on the messages' own stamps (the robot's clock) or on the log's event times") ==
                "stamp";
            o.fusion.estimate_bias = s.GetBool("estimate_bias", o.fusion.estimate_bias,
                                               "estimate the gyro bias while the wheels stand still at the start");
            o.max_pose_gap_s = s.GetDouble("max_pose_gap_s", o.max_pose_gap_s,
                                           "ground truth is interpolated across gaps up to this", 0.0, 3600.0);
            o.png_pixels_per_m = static_cast<int>(
                s.GetInt("png_pixels_per_m", o.png_pixels_per_m, "resolution of odometry_comparison.png", 1, 1000));
            return std::make_unique<OdometryStage>(o);
          }};
}

const RegisterStage kOdometryRegistered{OdometryStageType()};

}  // namespace mbot::app
