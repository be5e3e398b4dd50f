// What a stage file of the app includes: the pipeline's contract (libs/msgs) under the app's names.
// A stage file registers its type itself (const RegisterStage k...{...}); a new stage is that file
// plus its line in CMakeLists.txt.
#pragma once

#include "mbot/msgs/stage.hpp"

namespace mbot::app {

using msgs::Bus;
using msgs::EventResult;
using msgs::RegisterStage;
using msgs::RunContext;
using msgs::Stage;
using msgs::StageType;

// Calls every library's registration function (source, stage and output types), in the order of
// the build (generated from mbot_register() in CMake). Idempotent.
void RegisterAll();

}  // namespace mbot::app
