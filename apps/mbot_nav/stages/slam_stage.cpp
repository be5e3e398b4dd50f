// `slam`: the adapter between the event stream and a mapping::SlamSession (libs/mapping: the front
// end — channels, retiming, encoder odometry, deskew —, the policies and the back end in the mode the
// configuration picks: log-odds mapping, Monte-Carlo localization, full SLAM, graph SLAM) on a
// replayed log, the simulator or a live robot. It reads the known map, emits what the session
// publishes (pose, status, particles, map) to the later stages, writes the checkpoints, and at the
// end slam_outputs.cpp writes the map, the trajectories and metrics.json.
#include <chrono>
#include <filesystem>
#include <optional>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/mapping/slam_session.hpp"
#include "slam_config.hpp"
#include "slam_outputs.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

class SlamStage : public Stage {
 public:
  explicit SlamStage(SlamStageOptions o) : options_(std::move(o)) {}

  void Start(const RunContext& ctx) override {
    bus_ = ctx.bus;
    std::optional<mapping::OccupancyGrid> known;
    if (!options_.map_file.empty()) {
      std::string format;
      known = drivers::ReadAnyMap(options_.map_file, &format);
      mbot::log::Info("slam: known map " + options_.map_file + " (" + format + ", " + std::to_string(known->width()) +
                      "x" + std::to_string(known->height()) + ")");
    }
    session_.emplace(options_.session, ctx.seed, std::move(known));
    records_.emplace(ctx.output_dir, mapping::SlamRecordOptions{mapping::ToString(options_.session.slam.mode),
                                                                options_.tum_stamps, options_.truth_is_reference,
                                                                options_.score_from_us, options_.score_max_latency_us});
    session_->StreamRecords(
        [this](const mapping::ScanRecord& r) { records_->Add(r, session_->inputs().first_t_us()); });
    wall_start_ = std::chrono::steady_clock::now();
    if (!options_.resume_from.empty()) {
      mbot::log::Info("slam: resuming from checkpoint " + options_.resume_from + " at (" +
                      std::to_string(options_.session.initial_pose.x) + ", " +
                      std::to_string(options_.session.initial_pose.y) + ")");
    }
    if (options_.session.checkpoint_every_s > 0) {
      const std::string path = (std::filesystem::path(ctx.output_dir) / options_.checkpoint_file).string();
      session_->OnCheckpoint([path](const mapping::SlamCheckpointState& c, const mapping::OccupancyGrid& map) {
        try {
          drivers::WriteSlamCheckpoint(path, map, {"", c.pose, c.odometry, c.t_s, c.scans});
        } catch (const std::exception& e) {
          mbot::log::WarnOnce("slam:checkpoint", std::string("slam: cannot write the checkpoint: ") + e.what());
        }
      });
    }
  }

  void OnEvent(const msgs::Event& in) override {
    out_.clear();
    session_->Add(in, &out_);
    Emit();
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    out_.clear();
    session_->Finish(&out_);
    Emit();
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
    if (session_->scans_processed() == 0) {
      const std::string why = mapping::NoScanProcessedReason(*session_);
      // A run stopped before its first scan has nothing to say; one that read its whole input failed.
      if (interrupted) {
        mbot::log::Warn("slam: " + why + "; no outputs written");
        return;
      }
      throw std::runtime_error("slam: " + why);
    }
    WriteSlamOutputs(ctx, interrupted, options_, *session_, *records_, wall_s);
  }

 private:
  // The session's answers go to the later stages (planner, explorer, controller) and the sinks.
  void Emit() {
    if (!bus_) return;
    for (const msgs::Event& e : out_) bus_->Emit(this, e);
  }

  SlamStageOptions options_;
  std::optional<mapping::SlamSession> session_;
  std::optional<mapping::SlamRecordWriter> records_;  // the per-scan outputs, streamed to disk
  std::vector<msgs::Event> out_;
  Bus* bus_ = nullptr;
  std::chrono::steady_clock::time_point wall_start_;
};

}  // namespace

const RegisterStage kSlamRegistered{
    {"slam",
     "log-odds mapping, Monte-Carlo localization, full SLAM and graph SLAM (mode = full_slam | localization | "
     "mapping_only | action_only | graph_slam); writes the map, TUM trajectories and metrics.json",
     [](config::Section& s) -> std::unique_ptr<Stage> {
       return std::make_unique<SlamStage>(ParseSlamStageOptions(s));
     }}};

}  // namespace mbot::app
