#include <algorithm>

#include "mbot/sim/sim_source.hpp"
#include "mbot/sweep/sweep_source.hpp"
#include "stages.hpp"

namespace mbot::app {

const std::vector<StageType>& StageTypes() {
  static const std::vector<StageType> types = [] {
    std::vector<StageType> t = {InspectStageType(),
                                TrajectoryWriterStageType(),
                                MapWriterStageType(),
                                AStarTestStageType(),
                                MovingAiBenchmarkStageType(),
                                ExplorationStageType(),
                                SlamStageType(),
                                OdometryStageType(),
                                MotorCalibrationStageType(),
                                ActionModelFitStageType(),
                                MissionStageType(),
                                RefereeStageType(),
                                RecorderStageType(),
                                LcmBridgeStageType(),
                                MazeGeneratorStageType(),
                                CameraCalibrationStageType(),
                                TagDetectionStageType(),
                                TagSightingsStageType(),
                                MergeSweepStageType()};
    std::sort(t.begin(), t.end(), [](const StageType& a, const StageType& b) { return a.name < b.name; });
    return t;
  }();
  return types;
}

void RegisterSources() {
  sim::RegisterSimSource();
  sweep::RegisterSweepSource();
}

const StageType* FindStageType(const std::string& name) {
  for (const auto& t : StageTypes()) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

}  // namespace mbot::app
