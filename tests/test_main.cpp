// The tests' main: registers every library's source, stage and output types, as mbot_nav does, then
// runs the tests.
#include <gtest/gtest.h>

#include "stages/stages.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  mbot::app::RegisterAll();
  return RUN_ALL_TESTS();
}
