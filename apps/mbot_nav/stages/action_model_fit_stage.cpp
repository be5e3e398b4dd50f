// `action_model_fit`: maximum-likelihood fit of the particle filter's odometry noise (k1, k2:
// σ_rot = sqrt(k1·|rot|), σ_trans = sqrt(k2·|trans|)) from a log's odometry against its ground
// truth. Each odometry sample is paired with the ground truth interpolated at its event time; the
// samples are cut into windows of `window_steps` (one filter update each). Writes action_model.ini
// (an INI snippet with k1, k2 for the slam section), action_model_fit.json (values, 1σ, 95 %
// intervals, windows, the reports' values for comparison) and prints the same. A fit that did not
// converge fails the run after the report is written.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/motion/action_model_fit.hpp"
#include "mbot/motion/wheel_odometry.hpp"
#include "mbot/motion/motion_config.hpp"
#include "mbot/reports/json.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using motion::Pose2D;
using motion::TimedPose;
using msgs::EventKind;

struct ActionModelFitStageOptions {
  motion::ActionModelFitOptions fit;
  bool encoder_odometry = false;
  motion::WheelOdometryOptions wheels;
  std::string odometry_channel;  // "" = the first odometry channel seen
  double max_truth_gap_s = 0.1;
  bool odometry_on_stamps = false;  // place odometry by its own stamps (mapped to the log clock)
  std::string snippet_section = "slam";
};

// What the botlab reports used (the seed report; the second report).
constexpr double kReportK[2][2] = {{0.001, 0.001}, {0.0025, 0.0005}};

class ActionModelFitStage : public Stage {
 public:
  explicit ActionModelFitStage(ActionModelFitStageOptions o) : o_(std::move(o)) {}

  void Start(const RunContext&) override {
    if (o_.encoder_odometry) wheel_ = std::make_unique<motion::WheelOdometry>(o_.wheels);
  }

  void OnEvent(const msgs::Event& ev) override {
    if (ev.kind == EventKind::kGroundTruth) {
      truth_.push_back({ev.t_us, std::get<Pose2D>(ev.payload)});
    } else if (ev.kind == EventKind::kOdometry && !o_.encoder_odometry) {
      if (o_.odometry_channel.empty()) o_.odometry_channel = ev.channel;
      if (ev.channel == o_.odometry_channel) Add(ev, std::get<Pose2D>(ev.payload));
    } else if (ev.kind == EventKind::kEncoders && wheel_) {
      const auto& e = std::get<msgs::EncoderTicks>(ev.payload);
      Add(ev, wheel_->Update(e.left_ticks, e.right_ticks));
    }
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    if (odometry_.empty()) {
      throw std::runtime_error(std::string("action_model_fit: the source has no ") +
                               (o_.encoder_odometry ? "encoder" : "odometry") + " messages");
    }
    if (truth_.empty()) throw std::runtime_error("action_model_fit: the source has no ground truth (e.g. TRUE_POSE)");
    // Pair each odometry sample with the truth at its time; samples in truth gaps are dropped (a
    // window across a gap still compares the same interval on both sides).
    std::vector<Pose2D> odo, truth;
    const int64_t gap = static_cast<int64_t>(o_.max_truth_gap_s * 1e6);
    PlaceOnLogClock();
    for (const TimedPose& p : odometry_) {
      Pose2D t;
      if (!motion::InterpolateAt(truth_, p.t_us, gap, &t)) continue;
      odo.push_back(p.pose);
      truth.push_back(t);
    }
    const motion::ActionModelFit fit = motion::FitActionModel(odo, truth, o_.fit);
    const double z = 1.959964;
    std::ostringstream t;
    t << "action model fit: " << odo.size() << " paired samples (" << odometry_.size() - odo.size()
      << " without ground truth), windows of " << o_.fit.window_steps << " samples: " << fit.windows_used << " used, "
      << fit.windows_skipped << " skipped\n";
    t << std::setprecision(3);
    t << "  k1 (rotation)    " << std::setw(10) << fit.k1 << "  +- " << fit.k1_std << " (1 sigma)   rad^2/rad\n";
    t << "  k2 (translation) " << std::setw(10) << fit.k2 << "  +- " << fit.k2_std << " (1 sigma)   m^2/m\n";
    t << "  reports: k1 " << kReportK[0][0] << ", k2 " << kReportK[0][1] << " (seed report); k1 " << kReportK[1][0]
      << ", k2 " << kReportK[1][1] << " (second report)\n";
    t << "  converged: " << (fit.converged ? "yes" : "no") << (fit.message.empty() ? "" : " - " + fit.message) << "\n";
    std::cout << t.str() << std::flush;

    using reports::Number;
    const reports::Json j = {
        {"source", ctx.source_path},
        {"interrupted", interrupted},
        {"odometry", o_.encoder_odometry ? "encoders" : o_.odometry_channel},
        {"paired_samples", odo.size()},
        {"unpaired_samples", odometry_.size() - odo.size()},
        {"window_steps", o_.fit.window_steps},
        {"windows_used", fit.windows_used},
        {"windows_skipped", fit.windows_skipped},
        {"converged", fit.converged},
        {"message", fit.message},
        {"nll", Number(fit.nll)},
        {"k1", Number(fit.k1)},
        {"k1_std", Number(fit.k1_std)},
        {"k1_95", {Number(std::max(0.0, fit.k1 - z * fit.k1_std)), Number(fit.k1 + z * fit.k1_std)}},
        {"k2", Number(fit.k2)},
        {"k2_std", Number(fit.k2_std)},
        {"k2_95", {Number(std::max(0.0, fit.k2 - z * fit.k2_std)), Number(fit.k2 + z * fit.k2_std)}},
        {"reports",
         {{{"k1", Number(kReportK[0][0])}, {"k2", Number(kReportK[0][1])}, {"from", "seed report"}},
          {{"k1", Number(kReportK[1][0])}, {"k2", Number(kReportK[1][1])}, {"from", "second report"}}}}};
    reports::WriteJson(ctx.output_dir + "/action_model_fit.json", j);
    if (!fit.converged) {
      if (interrupted) return;
      throw std::runtime_error("action_model_fit: the fit did not converge: " + fit.message + " (report in " +
                               ctx.output_dir + "/action_model_fit.json)");
    }
    WriteFileAtomically(ctx.output_dir + "/action_model.ini", [&](std::ostream& out) {
      out << "# Action-model noise fitted by mbot_nav (action_model_fit stage) from\n# " << ctx.source_path << "\n# "
          << fit.windows_used << " windows of " << o_.fit.window_steps << " odometry samples; 1 sigma: k1 +- "
          << fit.k1_std << ", k2 +- " << fit.k2_std << "\n[" << o_.snippet_section << "]\n"
          << std::setprecision(6) << "k1 = " << fit.k1 << "\nk2 = " << fit.k2 << "\n";
    });
    mbot::log::Info("action_model_fit: wrote action_model.ini and action_model_fit.json in " + ctx.output_dir);
  }

 private:
  void Add(const msgs::Event& ev, const Pose2D& pose) {
    odometry_.push_back({ev.t_us, pose});
    stamps_.push_back(ev.stamp_us);
  }

  // With odometry_on_stamps, each odometry sample goes to its own stamp on the log clock
  // (motion::PlaceOnStamps), which removes the delays of a burst of late messages.
  void PlaceOnLogClock() {
    if (!o_.odometry_on_stamps) return;
    const double max_delay = motion::PlaceOnStamps(&odometry_, stamps_);
    if (max_delay >= 0) {
      mbot::log::Info("action_model_fit: odometry placed by its stamps; the log delayed it by up to " +
                      Num(max_delay, 3) + " s");
    }
  }

  ActionModelFitStageOptions o_;
  std::vector<int64_t> stamps_;
  std::unique_ptr<motion::WheelOdometry> wheel_;
  std::vector<TimedPose> odometry_, truth_;
};

}  // namespace

static StageType ActionModelFitStageType() {
  return {
      "action_model_fit",
      "maximum-likelihood fit of the action model's k1, k2 from odometry against ground truth; writes an INI snippet "
      "and a report with confidence intervals",
      [](config::Section& s) -> std::unique_ptr<Stage> {
        ActionModelFitStageOptions o;
        auto& f = o.fit;
        f.window_steps = static_cast<int>(
            s.GetInt("window_steps", f.window_steps,
                     "odometry samples per window (one filter update; 10 at 50 Hz = one 5 Hz scan)", 1));
        f.min_sigma_rot_rad = s.GetDouble("min_sigma_rot_rad", f.min_sigma_rot_rad,
                                          "rotation noise floor of the model (fixed) [rad]", 0.0);
        f.min_sigma_trans_m = s.GetDouble("min_sigma_trans_m", f.min_sigma_trans_m,
                                          "translation noise floor of the model (fixed) [m]", 0.0);
        f.min_trans_m = s.GetDouble("min_trans_m", f.min_trans_m,
                                    "windows moving less (and turning less than min_rot_rad) are skipped [m]", 0.0);
        f.min_rot_rad = s.GetDouble("min_rot_rad", f.min_rot_rad, "see min_trans_m [rad]", 0.0);
        f.warn_below_windows = static_cast<int>(
            s.GetInt("warn_below_windows", f.warn_below_windows, "fewer windows are flagged as a rough fit", 1));
        o.encoder_odometry =
            s.GetChoice("odometry", "channel", {"channel", "encoders"},
                        "odometry from an odometry channel or integrated from encoder ticks") == "encoders";
        o.odometry_channel = s.GetString("odometry_channel", "", "odometry channel ('' = the first one seen)");
        o.wheels = motion::ParseWheelConstants(s);
        o.max_truth_gap_s = s.GetDouble("max_truth_gap_s", o.max_truth_gap_s,
                                        "ground truth is interpolated across gaps up to this [s]", 0.0);
        o.odometry_on_stamps = s.GetChoice("clock", "event", {"event", "stamp"},
                                           "place odometry by when it was logged (as the ground truth) or by its own "
                                           "stamps (offset to the log clock)") == "stamp";
        o.snippet_section =
            s.GetString("snippet_section", o.snippet_section, "section name written in action_model.ini");
        return std::make_unique<ActionModelFitStage>(o);
      }};
}

const RegisterStage kActionModelFitRegistered{ActionModelFitStageType()};

}  // namespace mbot::app
