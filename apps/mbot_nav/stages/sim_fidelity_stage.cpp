// `sim_fidelity`: the adapter between a real log's event stream and sim::SimFidelity (libs/sim: the
// simulated robot driven by the log's own commands, compared with what the real robot did). Writes
// fidelity.json, the paths on the arena map (fidelity_paths.png) and the lidar's range residuals
// (fidelity_residuals.csv and .png).
#include <cmath>
#include <filesystem>
#include <optional>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/drivers/plot.hpp"
#include "mbot/reports/json.hpp"
#include "mbot/sim/sim_fidelity.hpp"
#include "mbot/sim/sim_source_options.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using reports::Number;

struct FidelityStageOptions {
  sim::SimFidelityOptions fidelity;
  std::string arena_map;  // "": no lidar comparison
};

class SimFidelityStage : public Stage {
 public:
  explicit SimFidelityStage(FidelityStageOptions o) : o_(std::move(o)) {}

  void Start(const RunContext& ctx) override {
    std::optional<sim::World> arena;
    if (o_.arena_map == "auto") {
      // The botlab layout: a log's map is maps/<the log's name>.map beside it.
      const std::filesystem::path log(ctx.source_path);
      const std::filesystem::path map = log.parent_path() / "maps" / (log.stem().string() + ".map");
      std::error_code ec;
      o_.arena_map = std::filesystem::is_regular_file(map, ec) ? map.string() : "";
      if (o_.arena_map.empty())
        mbot::log::Info("sim_fidelity: no arena map beside the log (" + map.string() +
                        "): the lidar is not compared (set arena_map)");
    }
    if (!o_.arena_map.empty()) {
      arena = sim::World::Load(o_.arena_map);
      map_ = drivers::ReadAnyMap(o_.arena_map);
    }
    fidelity_.emplace(o_.fidelity, std::move(arena), ctx.seed);
  }

  void OnEvent(const msgs::Event& ev) override { fidelity_->Add(ev); }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const sim::SimFidelityResult r = fidelity_->Finish();
    const std::string dir = ctx.output_dir + "/";
    reports::Json j = {
        {"source", ctx.source_path},
        {"interrupted", interrupted},
        {"arena_map", o_.arena_map},
        {"seed", ctx.seed},
        {"duration_s", Number(r.duration_s)},
        {"true_path_m", Number(r.true_path_m)},
        {"true_turn_deg", Number(r.true_turn_deg)},
        {"commands", r.commands},
        {"commands_refused", r.commands_refused},
        {"path_drift_m_per_m", Number(r.path_drift_m_per_m)},
        {"odometry_drift_m_per_m", Number(r.odometry_drift_m_per_m)},
        {"heading_drift_deg_per_turn", Number(r.heading_drift_deg_per_turn)},
        {"odometry_heading_drift_deg_per_turn", Number(r.odometry_heading_drift_deg_per_turn)},
        {"path_final_error_m", Number(r.path_final_error_m)},
        {"odometry_final_error_m", Number(r.odometry_final_error_m)},
        {"path_rmse_m", Number(r.path_rmse_m)},
        {"odometry_rmse_m", Number(r.odometry_rmse_m)},
        {"wheel_speed_rmse_m_s", Number(r.wheel_speed_rmse_m_s)},
        {"wheel_speed_bias_m_s", Number(r.wheel_speed_bias_m_s)},
        {"encoder_samples", r.encoder_samples},
        {"yaw_rate_rmse_rad_s", Number(r.yaw_rate_rmse_rad_s)},
        {"yaw_rate_bias_rad_s", Number(r.yaw_rate_bias_rad_s)},
        {"gyro_samples", r.gyro_samples},
        {"scans", r.scans},
        {"beams", r.beams},
        {"beams_compared", r.beams_compared},
        {"scan_range_residual_median_m", Number(r.scan_range_residual_median_m)},
        {"scan_range_residual_p95_m", Number(r.scan_range_residual_p95_m)},
        {"scan_range_residual_signed_median_m", Number(r.scan_range_residual_signed_median_m)},
        {"no_return_rate_real", Number(r.no_return_rate_real)},
        {"no_return_rate_sim", Number(r.no_return_rate_sim)},
        {"beam_time_spread_real_s", Number(r.beam_time_spread_real_s)},
        {"beam_time_spread_sim_s", Number(1.0 / o_.fidelity.robot.lidar.rate_hz * (o_.fidelity.robot.lidar.beams - 1) /
                                          o_.fidelity.robot.lidar.beams)}};
    reports::WriteJson(dir + "fidelity.json", j);

    WriteFileAtomically(dir + "fidelity_series.csv", [&](std::ostream& out) {
      out << "t_s,truth_x,truth_y,truth_theta,sim_x,sim_y,sim_theta,odometry_x,odometry_y,odometry_theta\n";
      for (size_t i = 0; i < r.path_t_s.size(); ++i) {
        const motion::Pose2D &t = r.truth_path[i], &p = r.sim_path[i], &o = r.odometry_path[i];
        out << Num(r.path_t_s[i], 6) << "," << Num(t.x, 5) << "," << Num(t.y, 5) << "," << Num(t.theta, 5) << ","
            << Num(p.x, 5) << "," << Num(p.y, 5) << "," << Num(p.theta, 5) << "," << Num(o.x, 5) << "," << Num(o.y, 5)
            << "," << Num(o.theta, 5) << "\n";
      }
    });
    // The paths on the arena map (or on an empty grid around them).
    const mapping::OccupancyGrid grid = map_ ? *map_ : EmptyAround(r.truth_path);
    std::vector<motion::Pose2D> odometry;
    for (const motion::Pose2D& o : r.odometry_path)
      if (std::isfinite(o.x)) odometry.push_back(o);
    std::vector<drivers::MapOverlay> overlays = {{r.truth_path, 0, 170, 0, false, "motion capture"},
                                                 {odometry, 220, 0, 0, false, "the log's odometry"},
                                                 {r.sim_path, 0, 60, 255, false, "simulated, from the log's commands"}};
    drivers::WriteMapPngWithOverlays(grid, overlays, 4, dir + "fidelity_paths.png");

    // The residual histogram, as a table and a chart.
    const double bin = o_.fidelity.residual_histogram_bin_m, lo = -o_.fidelity.residual_histogram_range_m;
    drivers::PlotSeries bars{{}, {}, 0, 60, 255, false, "real - simulated range"};
    WriteFileAtomically(dir + "fidelity_residuals.csv", [&](std::ostream& out) {
      out << "residual_from_m,residual_to_m,beams\n";
      for (size_t k = 0; k < r.residual_histogram.size(); ++k) {
        const double a = lo + k * bin, b = a + bin;
        out << Num(a, 4) << "," << Num(b, 4) << "," << r.residual_histogram[k] << "\n";
        // A step outline: the bar's left edge, its top, its right edge.
        bars.x.insert(bars.x.end(), {a, a, b, b});
        bars.y.insert(bars.y.end(), {0.0, double(r.residual_histogram[k]), double(r.residual_histogram[k]), 0.0});
      }
    });
    if (r.beams_compared > 0) {
      drivers::WritePlotPng(
          {bars},
          {"lidar: real range - simulated range at the true pose, " + std::to_string(r.beams_compared) + " beams",
           "residual [m]", "beams"},
          dir + "fidelity_residuals.png");
    }
    mbot::log::Info("sim_fidelity: path drift " + Num(r.path_drift_m_per_m, 3) + " m/m (the log's odometry " +
                    Num(r.odometry_drift_m_per_m, 3) + "), heading drift " + Num(r.heading_drift_deg_per_turn, 3) +
                    " deg/turn (odometry " + Num(r.odometry_heading_drift_deg_per_turn, 3) + "), wheel speed RMSE " +
                    Num(r.wheel_speed_rmse_m_s, 3) + " m/s, yaw rate RMSE " + Num(r.yaw_rate_rmse_rad_s, 3) +
                    " rad/s, scan range residual median " + Num(r.scan_range_residual_median_m, 3) + " m over " +
                    std::to_string(r.beams_compared) + " beams; outputs in " + ctx.output_dir);
  }

 private:
  static mapping::OccupancyGrid EmptyAround(const std::vector<motion::Pose2D>& path) {
    double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    for (const motion::Pose2D& p : path)
      x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
    const double res = 0.05, margin = 1.0;
    const int w = static_cast<int>(std::ceil((x1 - x0 + 2 * margin) / res));
    const int h = static_cast<int>(std::ceil((y1 - y0 + 2 * margin) / res));
    return mapping::OccupancyGrid(w, h, res, x0 - margin, y0 - margin, 0);
  }

  FidelityStageOptions o_;
  std::optional<sim::SimFidelity> fidelity_;
  std::optional<mapping::OccupancyGrid> map_;
};

}  // namespace

const RegisterStage kSimFidelityRegistered{
    {"sim_fidelity",
     "drives the simulated robot with a real log's own commands from its first motion-capture pose and compares "
     "wheel speeds, yaw rate, the path and the lidar with the log's (fidelity.json, plots)",
     [](config::Section& s) -> std::unique_ptr<Stage> {
       FidelityStageOptions o;
       sim::SimFidelityOptions& f = o.fidelity;
       f = sim::ParseSimFidelityOptions(s);
       f.residual_histogram_bin_m = s.GetDouble("residual_bin_m", f.residual_histogram_bin_m,
                                                "the residual histogram's bin width [m]", 1e-4, 1.0);
       f.residual_histogram_range_m = s.GetDouble("residual_range_m", f.residual_histogram_range_m,
                                                  "the residual histogram spans +- this [m]", 1e-3, 10.0);
       o.arena_map = s.GetPath("arena_map", "auto",
                               "a map of the logged arena in the motion-capture frame (any map format; unknown and "
                               "occupied cells are walls); auto: maps/<log name>.map beside the log; empty: no "
                               "lidar comparison");
       return std::make_unique<SimFidelityStage>(o);
     }}};

}  // namespace mbot::app
