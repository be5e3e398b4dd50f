// The stage types this application registers (one function per stage file).
#pragma once

#include "../stage.hpp"

namespace mbot::app {

StageType InspectStageType();
StageType TrajectoryWriterStageType();
StageType MapWriterStageType();
StageType AStarTestStageType();
StageType MovingAiBenchmarkStageType();
StageType ExplorationStageType();
StageType SlamStageType();
StageType OdometryStageType();
StageType MotorCalibrationStageType();
StageType ActionModelFitStageType();
StageType MissionStageType();
StageType RefereeStageType();
StageType RecorderStageType();
StageType LcmBridgeStageType();
StageType MazeGeneratorStageType();
StageType CameraCalibrationStageType();
StageType TagDetectionStageType();
StageType TagSightingsStageType();
StageType MergeSweepStageType();

}  // namespace mbot::app
