// The offline fits through their shipped configs: motor calibration from the calibration CSV and
// from an LCM log (PWM + measured wheel speeds, with transients), and the failure paths.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <tuple>

#include "../regression/run_config.hpp"
#include "mbot/lcm/lcm_log.hpp"
#include "mbot_lcm_msgs/mbot_encoders_t.hpp"
#include "mbot_lcm_msgs/mbot_motor_pwm_t.hpp"
#include "mbot_lcm_msgs/mbot_motor_vel_t.hpp"

namespace mbot::app {
namespace {

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The lines of the shipped fixture (its header says so; scripts/make_motor_calibration_fixture.py).
struct Line {
  double slope, punch;
};
const Line kLeftFwd{0.0620, 0.0700}, kLeftBwd{0.0640, -0.0720}, kRightFwd{0.0700, 0.0650}, kRightBwd{0.0690, -0.0660};

// Slope within 2 %; punch within `punch_tol` duty.
void ExpectLine(const std::string& json, const std::string& wheel, const std::string& dir, const Line& truth,
                double punch_tol) {
  const double slope = Get(json, {wheel, dir, "slope"}), punch = Get(json, {wheel, dir, "punch"});
  EXPECT_NEAR(slope, truth.slope, 0.02 * truth.slope) << wheel << " " << dir;
  EXPECT_NEAR(punch, truth.punch, punch_tol) << wheel << " " << dir;
}

// The fixture's 0.05 rad/s speed noise over ~50 samples per line leaves the punch a standard error
// of about 0.001 duty: asserted within 0.002 (3 % of it), the slope within 2 %.
TEST(MotorCalibrationConfig, ShippedCsvFitsTheKnownLines) {
  const std::string json = RunConfig("calibrate_motors.ini", "calib_csv", {}, "motor_calibration.json");
  ASSERT_FALSE(json.empty());
  EXPECT_NE(json.find("\"acceptable\": true"), std::string::npos) << json;
  ExpectLine(json, "left", "forward", kLeftFwd, 0.002);
  ExpectLine(json, "left", "backward", kLeftBwd, 0.002);
  ExpectLine(json, "right", "forward", kRightFwd, 0.002);
  ExpectLine(json, "right", "backward", kRightBwd, 0.002);
  const std::string out = ::testing::TempDir() + "/calib_csv";
  EXPECT_TRUE(std::filesystem::exists(out + "/motor_calibration.png"));
  const std::string csv = Read(out + "/motor_calibration.csv");
  EXPECT_EQ(csv.rfind("CHANNEL,DIRECTION,M,B\n1,1,0.06", 0), 0u) << csv;
  // The snippet is a valid include: a config that includes it reads the fitted keys.
  const std::string snippet = out + "/motor_calibration.ini";
  std::ofstream(out + "/uses.ini") << "include = motor_calibration.ini\n";
  const auto c = config::Config::Load(out + "/uses.ini");
  config::Section s = c.GetSection("motors");
  EXPECT_NEAR(s.GetDouble("left_forward_slope", 0, ""), Get(json, {"left", "forward", "slope"}), 1e-5);
  EXPECT_EQ(s.GetInt("right_motor_polarity", 0, ""), 1);
}

// A calibration run as an MBot logs it: the duty steps every second through ±0.1 … ±0.5 on both
// wheels; the wheels follow with a 0.05 s lag (transients the settle time must drop); 50 Hz.
void WriteCalibrationLog(const std::string& path, double right_encoder_sign) {
  lcmio::LcmLogWriter log(path);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  const auto steady = [](double duty, const Line& f, const Line& b) {
    if (duty > f.punch) return (duty - f.punch) / f.slope;
    if (duty < b.punch) return (duty - b.punch) / b.slope;
    return 0.0;
  };
  std::vector<double> duties;
  for (double d = 0.1; d <= 0.501; d += 0.05) duties.push_back(d), duties.push_back(-d);
  double wl = 0, wr = 0;
  int64_t t = 1'000'000;
  for (double d : duties) {
    for (int k = 0; k < 50; ++k, t += 20'000) {
      wl += (steady(d, kLeftFwd, kLeftBwd) - wl) * 0.02 / 0.05;
      wr += (steady(0.9 * d, kRightFwd, kRightBwd) - wr) * 0.02 / 0.05;  // the right duty is 90 % of the left
      mbot_lcm_msgs::mbot_motor_pwm_t pwm{};
      pwm.utime = t;
      pwm.pwm[0] = static_cast<float>(d);
      pwm.pwm[1] = static_cast<float>(0.9 * d);
      mbot_lcm_msgs::mbot_motor_vel_t vel{};
      vel.utime = t;
      vel.velocity[0] = static_cast<float>(wl + noise(rng));
      vel.velocity[1] = static_cast<float>(right_encoder_sign * (wr + noise(rng)));
      std::vector<uint8_t> buf(pwm.getEncodedSize());
      pwm.encode(buf.data(), 0, static_cast<int>(buf.size()));
      log.Write(t, "MBOT_MOTOR_PWM", buf.data(), buf.size());
      buf.resize(vel.getEncodedSize());
      vel.encode(buf.data(), 0, static_cast<int>(buf.size()));
      log.Write(t + 500, "MBOT_MOTOR_VEL", buf.data(), buf.size());
    }
  }
  log.Close();
}

TEST(MotorCalibrationConfig, LcmLogWithPwmAndWheelSpeedsFitsWithin2Percent) {
  const std::string log = ::testing::TempDir() + "/calibration_run.log";
  WriteCalibrationLog(log, 1.0);
  const std::string json =
      RunConfig("calibrate_motors.ini", "calib_lcm", {"source.path=" + log}, "motor_calibration.json");
  ASSERT_FALSE(json.empty());
  EXPECT_NE(json.find("\"samples_from\": \"PWM + measured wheel speeds\""), std::string::npos);
  EXPECT_NE(json.find("\"acceptable\": true"), std::string::npos) << json;
  for (const auto& [wheel, dir, line] :
       {std::tuple{"left", "forward", kLeftFwd}, std::tuple{"left", "backward", kLeftBwd},
        std::tuple{"right", "forward", kRightFwd}, std::tuple{"right", "backward", kRightBwd}}) {
    ExpectLine(json, wheel, dir, line, 0.02 * std::abs(line.punch));  // within 2 % on both
  }
}

TEST(MotorCalibrationConfig, ReversedEncoderIsReportedAndNoSnippetIsWritten) {
  const std::string log = ::testing::TempDir() + "/calibration_reversed.log";
  WriteCalibrationLog(log, -1.0);
  try {
    RunConfig("calibrate_motors.ini", "calib_reversed", {"source.path=" + log}, "motor_calibration.json");
    FAIL() << "an unacceptable calibration must fail the run";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("right wheel: polarity reversed"), std::string::npos) << e.what();
  }
  const std::string out = ::testing::TempDir() + "/calib_reversed";
  EXPECT_TRUE(std::filesystem::exists(out + "/motor_calibration.json"));
  EXPECT_FALSE(std::filesystem::exists(out + "/motor_calibration.ini"));
  // With the polarity set as the report advises, the same log is acceptable.
  const std::string json =
      RunConfig("calibrate_motors.ini", "calib_fixed", {"source.path=" + log, "calibration.right_encoder_polarity=-1"},
                "motor_calibration.json");
  EXPECT_NE(json.find("\"acceptable\": true"), std::string::npos) << json;
}

TEST(MotorCalibrationConfig, MalformedCsvNamesFileAndLine) {
  const std::string csv = ::testing::TempDir() + "/bad_samples.csv";
  std::ofstream(csv) << "channel,duty,speed\n1,0.2,3.1\n1,0.3\n";
  try {
    RunConfig("calibrate_motors.ini", "calib_bad", {"source.path=" + csv}, "motor_calibration.json");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad_samples.csv:3: expected 3 fields 'channel,duty,speed', got 2"),
              std::string::npos)
        << e.what();
  }
  std::ofstream(csv) << "1,1.5,3.1\n";
  try {
    RunConfig("calibrate_motors.ini", "calib_bad", {"source.path=" + csv, "source.type=motor_csv"}, "x");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad_samples.csv:1: duty '1.5' is not a number in [-1, 1]"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mbot::app
