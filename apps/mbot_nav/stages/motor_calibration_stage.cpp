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
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using drivers::EventKind;
using motion::MotorSample;

struct MotorCalibrationStageOptions {
  motion::MotorFitOptions fit;
  motion::RobotGeometry geometry;   // encoder-derived speeds
  std::string speed_from = "auto";  // auto | wheel_speed | encoders
  double settle_s = 0.3;
  double duty_tolerance = 0.005;
  int left_channel = 1, right_channel = 2;  // CSV channel numbers (and the CSV written)
  std::string snippet_section = "motors";
};

class MotorCalibrationStage : public Stage {
 public:
  explicit MotorCalibrationStage(MotorCalibrationStageOptions o) : o_(std::move(o)) {}

  void OnEvent(const drivers::Event& ev) override {
    const int64_t t = ev.t_us;
    if (ev.kind == EventKind::kMotorSample) {
      const auto& s = std::get<drivers::WheelSample>(ev.payload);
      if (s.channel == o_.left_channel) {
        csv_[0].push_back({s.duty, s.speed_rad_s});
      } else if (s.channel == o_.right_channel) {
        csv_[1].push_back({s.duty, s.speed_rad_s});
      } else {
        ++unmapped_channel_samples_;
      }
    } else if (ev.kind == EventKind::kMotorCommand) {
      const auto& c = std::get<drivers::MotorCommand>(ev.payload);
      if (c.kind != drivers::MotorCommand::Kind::kPwm) return;
      const double d[2] = {c.left_duty, c.right_duty};
      for (int w = 0; w < 2; ++w) {
        if (!duty_known_[w] || std::abs(d[w] - duty_[w]) > o_.duty_tolerance) duty_since_[w] = t;
        duty_[w] = d[w];
        duty_known_[w] = true;
      }
    } else if (ev.kind == EventKind::kWheelSpeed) {
      const auto& w = std::get<drivers::WheelSpeeds>(ev.payload);
      AddLogSample(t, w.left_rad_s, w.right_rad_s, measured_);
    } else if (ev.kind == EventKind::kEncoders) {
      const auto& e = std::get<drivers::EncoderTicks>(ev.payload);
      if (have_ticks_) {
        double dt = e.delta_time_us > 0 ? e.delta_time_us * 1e-6 : (t - ticks_t_) * 1e-6;
        if (dt > 0) {
          const double k = o_.geometry.RadPerTick() / dt;
          AddLogSample(t, k * (e.left_ticks - left_ticks_), k * (e.right_ticks - right_ticks_), from_encoders_);
        }
      }
      have_ticks_ = true;
      ticks_t_ = t, left_ticks_ = e.left_ticks, right_ticks_ = e.right_ticks;
    }
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const std::vector<MotorSample>* samples = nullptr;
    std::string origin;
    if (!csv_[0].empty() || !csv_[1].empty()) {
      samples = csv_, origin = "calibration samples";
    } else if (o_.speed_from != "encoders" && (!measured_[0].empty() || !measured_[1].empty())) {
      samples = measured_, origin = "PWM + measured wheel speeds";
    } else if (o_.speed_from != "wheel_speed" && (!from_encoders_[0].empty() || !from_encoders_[1].empty())) {
      samples = from_encoders_, origin = "PWM + encoder ticks";
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
    PrintTable(r, origin, samples);
    const std::string dir = ctx.output_dir;
    WriteJson(dir + "/motor_calibration.json", r, origin, samples, ctx, interrupted);
    WritePlot(dir + "/motor_calibration.png", r, samples);
    if (AllLinesFitted(r)) WriteCsv(dir + "/motor_calibration.csv", r);
    if (r.acceptable) {
      WriteSnippet(dir + "/motor_calibration.ini", r, origin, ctx);
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
  void AddLogSample(int64_t t, double left_speed, double right_speed, std::vector<MotorSample>* out) {
    const double s[2] = {left_speed, right_speed};
    for (int w = 0; w < 2; ++w) {
      if (!duty_known_[w] || !std::isfinite(s[w])) continue;
      if ((t - duty_since_[w]) * 1e-6 < o_.settle_s) continue;
      out[w].push_back({duty_[w], s[w]});
    }
  }

  static bool AllLinesFitted(const motion::MotorFitReport& r) {
    return r.left.forward.fitted && r.left.backward.fitted && r.right.forward.fitted && r.right.backward.fitted;
  }

  void PrintTable(const motion::MotorFitReport& r, const std::string& origin, const std::vector<MotorSample>* s) const {
    std::ostringstream t;
    t << "motor calibration from " << origin << " (" << s[0].size() << " left, " << s[1].size() << " right samples)\n";
    t << "wheel  direction   slope [duty/(rad/s)]   punch [duty]   samples   residual RMS\n";
    const auto row = [&](const char* wheel, const char* dir, const motion::LineFit& f) {
      t << std::left << std::setw(7) << wheel << std::setw(12) << dir << std::right;
      if (f.fitted) {
        t << std::setw(14) << std::fixed << std::setprecision(5) << f.line.slope << std::setw(20) << f.line.punch
          << std::setw(10) << f.samples << std::setw(15) << std::setprecision(4) << f.residual_rms << "\n";
      } else {
        t << std::setw(14) << "-" << std::setw(20) << "-" << std::setw(10) << f.samples << std::setw(15) << "-"
          << "\n";
      }
    };
    row("left", "forward", r.left.forward);
    row("left", "backward", r.left.backward);
    row("right", "forward", r.right.forward);
    row("right", "backward", r.right.backward);
    t << "acceptable: " << (r.acceptable ? "yes" : "no") << "\n";
    for (const auto& p : r.problems) t << "  " << p << "\n";
    std::cout << t.str() << std::flush;
  }

  static std::string LineJson(const motion::LineFit& f) {
    return "{\"fitted\": " + std::string(f.fitted ? "true" : "false") + ", \"slope\": " + Num(f.line.slope) +
           ", \"punch\": " + Num(f.line.punch) + ", \"samples\": " + std::to_string(f.samples) +
           ", \"residual_rms\": " + Num(f.residual_rms) + "}";
  }

  void WriteJson(const std::string& path, const motion::MotorFitReport& r, const std::string& origin,
                 const std::vector<MotorSample>* s, const RunContext& ctx, bool interrupted) const {
    std::ostringstream j;
    j << "{\n  \"source\": " << JsonString(ctx.source_path) << ",\n  \"samples_from\": " << JsonString(origin)
      << ",\n  \"interrupted\": " << (interrupted ? "true" : "false")
      << ",\n  \"acceptable\": " << (r.acceptable ? "true" : "false") << ",\n  \"problems\": [";
    for (size_t i = 0; i < r.problems.size(); ++i) j << (i ? ", " : "") << JsonString(r.problems[i]);
    j << "],\n  \"limits\": {\"max_abs_slope\": " << Num(o_.fit.max_abs_slope)
      << ", \"max_abs_punch\": " << Num(o_.fit.max_abs_punch) << "}";
    const auto wheel = [&](const char* name, const motion::WheelFit& w, const motion::WheelCalibration& c, size_t n) {
      j << ",\n  \"" << name << "\": {\"samples\": " << n << ", \"moving_samples\": " << w.moving_samples
        << ", \"disagreeing_samples\": " << w.disagreeing_samples
        << ", \"encoder_counting\": " << (w.encoder_counting ? "true" : "false")
        << ", \"polarity_ok\": " << (w.polarity_ok ? "true" : "false") << ", \"motor_polarity\": " << c.motor_polarity
        << ", \"encoder_polarity\": " << c.encoder_polarity << ",\n    \"forward\": " << LineJson(w.forward)
        << ",\n    \"backward\": " << LineJson(w.backward) << "}";
    };
    wheel("left", r.left, r.calibration.left, s[0].size());
    wheel("right", r.right, r.calibration.right, s[1].size());
    j << "\n}\n";
    WriteFileAtomically(path, [&](std::ostream& out) { out << j.str(); });
  }

  void WriteSnippet(const std::string& path, const motion::MotorFitReport& r, const std::string& origin,
                    const RunContext& ctx) const {
    WriteFileAtomically(path, [&](std::ostream& out) {
      out << "# Motor calibration fitted by mbot_nav (motor_calibration stage) from " << origin << " of\n# "
          << ctx.source_path
          << "\n# duty = slope * wheel_speed[rad/s] + punch, per wheel and direction, in the wheel's\n"
          << "# forward frame; include it from a config whose [" << o_.snippet_section << "] reads these keys.\n"
          << "[" << o_.snippet_section << "]\n";
      const auto wheel = [&](const char* name, const motion::WheelCalibration& c) {
        out << name << "_motor_polarity = " << c.motor_polarity << "\n"
            << name << "_encoder_polarity = " << c.encoder_polarity << "\n"
            << std::setprecision(6) << name << "_forward_slope = " << c.forward.slope << "\n"
            << name << "_forward_punch = " << c.forward.punch << "\n"
            << name << "_backward_slope = " << c.backward.slope << "\n"
            << name << "_backward_punch = " << c.backward.punch << "\n";
      };
      wheel("left", r.calibration.left);
      wheel("right", r.calibration.right);
    });
  }

  void WriteCsv(const std::string& path, const motion::MotorFitReport& r) const {
    WriteFileAtomically(path, [&](std::ostream& out) {
      out << "CHANNEL,DIRECTION,M,B\n" << std::setprecision(6);
      const auto wheel = [&](int channel, const motion::WheelCalibration& c) {
        out << channel << ",1," << c.forward.slope << "," << c.forward.punch << "\n";
        out << channel << ",-1," << c.backward.slope << "," << c.backward.punch << "\n";
      };
      wheel(o_.left_channel, r.calibration.left);
      wheel(o_.right_channel, r.calibration.right);
    });
  }

  void WritePlot(const std::string& path, const motion::MotorFitReport& r, const std::vector<MotorSample>* s) const {
    std::vector<drivers::PlotSeries> series;
    const uint8_t colours[2][3] = {{31, 119, 180}, {214, 39, 40}};
    const char* names[2] = {"left", "right"};
    const motion::WheelCalibration* cal[2] = {&r.calibration.left, &r.calibration.right};
    const motion::WheelFit* fits[2] = {&r.left, &r.right};
    for (int w = 0; w < 2; ++w) {
      drivers::PlotSeries pts{
          {}, {}, colours[w][0], colours[w][1], colours[w][2], true, std::string(names[w]) + " samples"};
      double lo = 0, hi = 0;
      for (const MotorSample& m : s[w]) {
        const double speed = cal[w]->encoder_polarity * m.speed_rad_s, duty = cal[w]->motor_polarity * m.duty;
        pts.x.push_back(speed), pts.y.push_back(duty);
        if (std::isfinite(speed)) lo = std::min(lo, speed), hi = std::max(hi, speed);
      }
      series.push_back(std::move(pts));
      for (const auto& [f, a, b] : {std::tuple{&fits[w]->forward, 0.0, hi}, std::tuple{&fits[w]->backward, lo, 0.0}}) {
        if (!f->fitted || a == b) continue;
        series.push_back({{a, b},
                          {f->line.slope * a + f->line.punch, f->line.slope * b + f->line.punch},
                          colours[w][0],
                          colours[w][1],
                          colours[w][2],
                          false,
                          ""});
      }
    }
    series[0].label += " (lines: fit)";
    drivers::WritePlotPng(
        series,
        {"motor calibration: duty = slope * speed + punch", "wheel speed [rad/s], forward frame", "duty", 900, 600},
        path);
  }

  MotorCalibrationStageOptions o_;
  std::vector<MotorSample> csv_[2], measured_[2], from_encoders_[2];
  long long unmapped_channel_samples_ = 0;
  double duty_[2] = {0, 0};
  bool duty_known_[2] = {false, false};
  int64_t duty_since_[2] = {0, 0};
  bool have_ticks_ = false;
  int64_t ticks_t_ = 0, left_ticks_ = 0, right_ticks_ = 0;
};

int Polarity(config::Section& s, const std::string& key, const std::string& doc) {
  return std::stoi(s.GetChoice(key, "1", {"1", "-1"}, doc));
}

}  // namespace

StageType MotorCalibrationStageType() {
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

}  // namespace mbot::app
