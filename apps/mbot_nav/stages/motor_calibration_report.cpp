#include "motor_calibration_report.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <tuple>

#include "mbot/common/atomic_file.hpp"
#include "mbot/drivers/plot.hpp"
#include "mbot/reports/json.hpp"
#include "report.hpp"

namespace mbot::app {

using motion::MotorSample;

bool AllLinesFitted(const motion::MotorFitReport& r) {
  return r.left.forward.fitted && r.left.backward.fitted && r.right.forward.fitted && r.right.backward.fitted;
}

void PrintMotorFit(const motion::MotorFitReport& r, const std::string& origin, const std::vector<MotorSample>* s) {
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

reports::Json LineJson(const motion::LineFit& f) {
  return {{"fitted", f.fitted},
          {"slope", reports::Number(f.line.slope)},
          {"punch", reports::Number(f.line.punch)},
          {"samples", f.samples},
          {"residual_rms", reports::Number(f.residual_rms)}};
}

void WriteMotorFitJson(const MotorCalibrationStageOptions& o, const std::string& path, const motion::MotorFitReport& r,
                       const std::string& origin, const std::vector<MotorSample>* s, const RunContext& ctx,
                       bool interrupted) {
  reports::Json j = {{"source", ctx.source_path},
                     {"samples_from", origin},
                     {"interrupted", interrupted},
                     {"acceptable", r.acceptable},
                     {"problems", r.problems},
                     {"limits",
                      {{"max_abs_slope", reports::Number(o.fit.max_abs_slope)},
                       {"max_abs_punch", reports::Number(o.fit.max_abs_punch)}}}};
  const auto wheel = [&](const char* name, const motion::WheelFit& w, const motion::WheelCalibration& c, size_t n) {
    j[name] = {{"samples", n},
               {"moving_samples", w.moving_samples},
               {"disagreeing_samples", w.disagreeing_samples},
               {"encoder_counting", w.encoder_counting},
               {"polarity_ok", w.polarity_ok},
               {"motor_polarity", c.motor_polarity},
               {"encoder_polarity", c.encoder_polarity},
               {"forward", LineJson(w.forward)},
               {"backward", LineJson(w.backward)}};
  };
  wheel("left", r.left, r.calibration.left, s[0].size());
  wheel("right", r.right, r.calibration.right, s[1].size());
  reports::WriteJson(path, j);
}

void WriteMotorSnippet(const MotorCalibrationStageOptions& o, const std::string& path, const motion::MotorFitReport& r,
                       const std::string& origin, const RunContext& ctx) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "# Motor calibration fitted by mbot_nav (motor_calibration stage) from " << origin << " of\n# "
        << ctx.source_path << "\n# duty = slope * wheel_speed[rad/s] + punch, per wheel and direction, in the wheel's\n"
        << "# forward frame; include it from a config whose [" << o.snippet_section << "] reads these keys.\n"
        << "[" << o.snippet_section << "]\n";
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

void WriteMotorCsv(const MotorCalibrationStageOptions& o, const std::string& path, const motion::MotorFitReport& r) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "CHANNEL,DIRECTION,M,B\n" << std::setprecision(6);
    const auto wheel = [&](int channel, const motion::WheelCalibration& c) {
      out << channel << ",1," << c.forward.slope << "," << c.forward.punch << "\n";
      out << channel << ",-1," << c.backward.slope << "," << c.backward.punch << "\n";
    };
    wheel(o.left_channel, r.calibration.left);
    wheel(o.right_channel, r.calibration.right);
  });
}

void WriteMotorPlot(const std::string& path, const motion::MotorFitReport& r, const std::vector<MotorSample>* s) {
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

}  // namespace mbot::app
