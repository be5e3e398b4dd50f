// The motor_calibration stage's options and its report: the printed table, motor_calibration.json,
// the INI snippet, the CHANNEL,DIRECTION,M,B CSV and the plot of the samples and fitted lines.
#pragma once

#include <string>
#include <vector>

#include "stages.hpp"
#include "mbot/motion/motor_model.hpp"
#include "mbot/motion/robot_geometry.hpp"

namespace mbot::app {

struct MotorCalibrationStageOptions {
  motion::MotorFitOptions fit;
  motion::RobotGeometry geometry;   // encoder-derived speeds
  std::string speed_from = "auto";  // auto | wheel_speed | encoders
  double settle_s = 0.3;
  double duty_tolerance = 0.005;
  int left_channel = 1, right_channel = 2;  // CSV channel numbers (and the CSV written)
  std::string snippet_section = "motors";
};

bool AllLinesFitted(const motion::MotorFitReport& r);
void PrintMotorFit(const motion::MotorFitReport& r, const std::string& origin,
                   const std::vector<motion::MotorSample>* s);
void WriteMotorFitJson(const MotorCalibrationStageOptions& o, const std::string& path, const motion::MotorFitReport& r,
                       const std::string& origin, const std::vector<motion::MotorSample>* s, const RunContext& ctx,
                       bool interrupted);
void WriteMotorSnippet(const MotorCalibrationStageOptions& o, const std::string& path, const motion::MotorFitReport& r,
                       const std::string& origin, const RunContext& ctx);
void WriteMotorCsv(const MotorCalibrationStageOptions& o, const std::string& path, const motion::MotorFitReport& r);
void WriteMotorPlot(const std::string& path, const motion::MotorFitReport& r,
                    const std::vector<motion::MotorSample>* s);

}  // namespace mbot::app
