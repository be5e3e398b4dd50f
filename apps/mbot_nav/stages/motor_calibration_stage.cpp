// `motor_calibration`: fits the motor model (duty = slope·ω + punch per wheel and direction) from a
// calibration run and says whether it is acceptable (polarity right, both encoders counting,
// |slope|, |punch| within 0.10). Samples come from a calibration CSV (`channel,duty,speed`, one
// steady-state sample per row) or from a log's PWM channel paired with its measured wheel speeds
// (MBOT_MOTOR_PWM + MBOT_MOTOR_VEL) or, without those, with speeds derived from its encoder ticks;
// a log sample is taken only once the duty has held for `settle_s`.
// Writes motor_calibration.ini (an INI snippet other configs include; only when acceptable),
// motor_calibration.csv (`CHANNEL,DIRECTION,M,B`, the older firmware's file), motor_calibration.png
// (samples and fitted lines) and motor_calibration.json. An unacceptable calibration fails the run
// after the report is written.
#include <cmath>
#include <tuple>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/plot.hpp"
#include "mbot/motion/motor_model.hpp"
#include "mbot/motion/robot_geometry.hpp"
#include "motor_calibration_report.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using motion::MotorSample;
using msgs::EventKind;

class MotorCalibrationStage : public Stage {
 public:
  explicit MotorCalibrationStage(MotorCalibrationStageOptions o)
      : o_(std::move(o)), log_samples_(o_.settle_s, o_.duty_tolerance, o_.geometry.RadPerTick()) {}

  void OnEvent(const msgs::Event& ev) override {
    const int64_t t = ev.t_us;
    if (ev.kind == EventKind::kMotorSample) {
      const auto& s = std::get<msgs::WheelSample>(ev.payload);
      if (s.channel == o_.left_channel) {
        csv_[0].push_back({s.duty, s.speed_rad_s});
      } else if (s.channel == o_.right_channel) {
        csv_[1].push_back({s.duty, s.speed_rad_s});
      } else {
        ++unmapped_channel_samples_;
      }
    } else if (ev.kind == EventKind::kMotorCommand) {
      const auto& c = std::get<msgs::MotorCommand>(ev.payload);
      if (c.kind == msgs::MotorCommand::Kind::kPwm) log_samples_.OnDuty(t, c.left_duty, c.right_duty);
    } else if (ev.kind == EventKind::kWheelSpeed) {
      const auto& w = std::get<msgs::WheelSpeeds>(ev.payload);
      log_samples_.OnWheelSpeeds(t, w.left_rad_s, w.right_rad_s);
    } else if (ev.kind == EventKind::kEncoders) {
      const auto& e = std::get<msgs::EncoderTicks>(ev.payload);
      log_samples_.OnEncoderTicks(t, e.left_ticks, e.right_ticks, e.delta_time_us);
    }
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const std::vector<MotorSample>* samples = nullptr;
    std::string origin;
    if (!csv_[0].empty() || !csv_[1].empty()) {
      samples = csv_, origin = "calibration samples";
    } else if (const auto* m = log_samples_.measured();
               o_.speed_from != "encoders" && (!m[0].empty() || !m[1].empty())) {
      samples = m, origin = "PWM + measured wheel speeds";
    } else if (const auto* e = log_samples_.from_encoders();
               o_.speed_from != "wheel_speed" && (!e[0].empty() || !e[1].empty())) {
      samples = e, origin = "PWM + encoder ticks";
    }
    if (unmapped_channel_samples_ > 0) {
      mbot::log::Warn("motor_calibration: " + std::to_string(unmapped_channel_samples_) +
                      " samples on channels other than left_channel " + std::to_string(o_.left_channel) +
                      " / right_channel " + std::to_string(o_.right_channel) + " were ignored");
    }
    if (!samples) {
      throw std::runtime_error(
          "motor_calibration: the source has no calibration samples (no channel,duty,speed rows, and no PWM "
          "messages with settled duty paired with wheel speeds" +
          std::string(o_.speed_from == "wheel_speed" ? "" : " or encoder ticks") + ")");
    }
    const motion::MotorFitReport r = motion::FitMotorCalibration(samples[0], samples[1], o_.fit);
    PrintMotorFit(r, origin, samples);
    const std::string dir = ctx.output_dir;
    WriteMotorFitJson(o_, dir + "/motor_calibration.json", r, origin, samples, ctx, interrupted);
    WriteMotorPlot(dir + "/motor_calibration.png", r, samples);
    if (AllLinesFitted(r)) WriteMotorCsv(o_, dir + "/motor_calibration.csv", r);
    if (r.acceptable) {
      WriteMotorSnippet(o_, dir + "/motor_calibration.ini", r, origin, ctx);
      mbot::log::Info("motor_calibration: acceptable; wrote motor_calibration.{ini,csv,png,json} in " + dir);
      return;
    }
    std::string why;
    for (const auto& p : r.problems) why += "\n  " + p;
    if (interrupted) {
      mbot::log::Warn("motor_calibration: interrupted before the calibration was acceptable:" + why);
      return;
    }
    throw std::runtime_error("motor_calibration: not acceptable (report in " + dir + "/motor_calibration.json):" + why);
  }

 private:
  MotorCalibrationStageOptions o_;
  std::vector<MotorSample> csv_[2];
  motion::SettledMotorSamples log_samples_;
  long long unmapped_channel_samples_ = 0;
};

int Polarity(config::Section& s, const std::string& key, const std::string& doc) {
  return std::stoi(s.GetChoice(key, "1", {"1", "-1"}, doc));
}

}  // namespace

static StageType MotorCalibrationStageType() {
  return {
      "motor_calibration",
      "fits the motor model (slope, punch per wheel and direction) from calibration samples or a log's PWM and "
      "wheel speeds; writes an INI snippet, the CHANNEL,DIRECTION,M,B CSV, a plot and a report",
      [](config::Section& s) -> std::unique_ptr<Stage> {
        MotorCalibrationStageOptions o;
        auto& f = o.fit;
        f.left_motor_polarity =
            Polarity(s, "left_motor_polarity", "1 if a positive duty turns the left wheel forward, else -1");
        f.left_encoder_polarity =
            Polarity(s, "left_encoder_polarity", "1 if the left encoder counts up going forward, else -1");
        f.right_motor_polarity =
            Polarity(s, "right_motor_polarity", "1 if a positive duty turns the right wheel forward, else -1");
        f.right_encoder_polarity =
            Polarity(s, "right_encoder_polarity", "1 if the right encoder counts up going forward, else -1");
        f.min_speed_rad_s =
            s.GetDouble("min_speed_rad_s", f.min_speed_rad_s, "slower samples are stalls, not fitted [rad/s]", 0.0);
        f.min_duty = s.GetDouble("min_duty", f.min_duty, "samples with a smaller |duty| are not fitted", 0.0, 1.0);
        f.loss_scale =
            s.GetDouble("loss_scale", f.loss_scale,
                        "Cauchy loss scale [duty]: residuals well beyond it (slips, stalls) barely count", 1e-6, 1.0);
        f.max_abs_slope =
            s.GetDouble("max_abs_slope", f.max_abs_slope, "acceptance: |slope| at most this (the reports' 0.10)", 0.0);
        f.max_abs_punch =
            s.GetDouble("max_abs_punch", f.max_abs_punch, "acceptance: |punch| at most this (the reports' 0.10)", 0.0);
        f.min_samples =
            static_cast<int>(s.GetInt("min_samples", f.min_samples, "samples needed per wheel and direction", 2));
        o.speed_from = s.GetChoice("speed_from", o.speed_from, {"auto", "wheel_speed", "encoders"},
                                   "logs: measured wheel speeds (MBOT_MOTOR_VEL), speeds from encoder ticks, or auto "
                                   "(the former when present)");
        o.settle_s = s.GetDouble("settle_s", o.settle_s,
                                 "logs: a duty must hold this long before its samples count [s]", 0.0, 60.0);
        o.duty_tolerance = s.GetDouble("duty_tolerance", o.duty_tolerance,
                                       "logs: duty changes up to this still count as holding", 0.0, 1.0);
        o.left_channel = static_cast<int>(
            s.GetInt("left_channel", o.left_channel, "motor channel number of the left wheel (CSV in and out)", 0, 16));
        o.right_channel = static_cast<int>(s.GetInt("right_channel", o.right_channel,
                                                    "motor channel number of the right wheel (CSV in and out)", 0, 16));
        if (!s.describing() && o.left_channel == o.right_channel)
          s.Fail("right_channel", "must differ from left_channel");
        o.snippet_section =
            s.GetString("snippet_section", o.snippet_section, "section name written in motor_calibration.ini");
        o.geometry.gear_ratio = s.GetDouble("gear_ratio", o.geometry.gear_ratio,
                                            "logs without wheel speeds: motor turns per wheel turn", 1e-3, 1e4);
        o.geometry.encoder_resolution =
            s.GetDouble("encoder_resolution", o.geometry.encoder_resolution,
                        "logs without wheel speeds: encoder counts per motor turn", 1.0, 1e6);
        return std::make_unique<MotorCalibrationStage>(o);
      }};
}

const RegisterStage kMotorCalibrationRegistered{MotorCalibrationStageType()};

}  // namespace mbot::app
