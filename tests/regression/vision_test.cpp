// Camera calibration on OpenCV's own sample views (datasets/camera/opencv_chessboard, 13 views of a
// 9 x 6 board, 25 mm squares) through the shipped config, against OpenCV's own result for them
// (left_intrinsics.yml, made with a fixed aspect ratio of 1).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "mbot/common/config.hpp"
#include "mbot/vision/camera_calibration.hpp"
#include "run_config.hpp"

namespace mbot::app {
namespace {

std::string Data(const std::string& rel) { return config::DatasetsDir() + "/" + rel; }

TEST(VisionRegression, CalibrationReproducesOpenCvsOwnResultWithin1Percent) {
  const std::string json = RunConfig("calibrate_camera.ini", "calibrate_camera", {}, "calibration.json");
  ASSERT_FALSE(json.empty());
  EXPECT_NE(json.find("\"accepted\": true"), std::string::npos) << json;
  const vision::CalibrationResult ours = vision::ReadCameraYaml(::testing::TempDir() + "/calibrate_camera/camera.yaml");
  const vision::CalibrationResult opencv = vision::ReadCameraYaml(Data("camera/opencv_chessboard/left_intrinsics.yml"));
  EXPECT_EQ(ours.image_width, 640);
  EXPECT_EQ(ours.image_height, 480);
  for (auto [r, c] : {std::pair{0, 0}, std::pair{1, 1}, std::pair{0, 2}, std::pair{1, 2}}) {
    const double a = ours.camera_matrix.at<double>(r, c), b = opencv.camera_matrix.at<double>(r, c);
    EXPECT_NEAR(a, b, 0.01 * b) << "camera_matrix(" << r << ", " << c << ")";
    RecordProperty("K" + std::to_string(r) + std::to_string(c), std::to_string(a));
  }
  EXPECT_LT(ours.avg_error_px, 0.5);
  EXPECT_NEAR(ours.avg_error_px, opencv.avg_error_px, 0.05);
  EXPECT_EQ(Get(json, {"used"}), 13);
}

TEST(VisionRegression, TooStrictAcceptanceFailsTheRunSayingWhy) {
  auto c = config::Config::Load(std::string(MBOT_SOURCE_DIR) + "/config/calibrate_camera.ini");
  c.Set("output.dir=" + ::testing::TempDir() + "/calibrate_camera_strict");
  c.Set("calibration.max_error_px=0.1");
  c.Set("pipeline.progress=off");
  auto plan = BuildPlan(c);
  std::atomic<bool> stop{false};
  try {
    RunPlan(plan, stop);
    FAIL() << "a calibration above max_error_px was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not accepted: mean reprojection error"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(::testing::TempDir() + "/calibrate_camera_strict/camera.yaml"));
  EXPECT_TRUE(std::filesystem::exists(::testing::TempDir() + "/calibrate_camera_strict/calibration.json"));
}

}  // namespace
}  // namespace mbot::app
