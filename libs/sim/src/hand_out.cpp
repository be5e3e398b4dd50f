#include "mbot/sim/hand_out.hpp"

#include <filesystem>
#include <stdexcept>

#include "mbot/common/config.hpp"
#include "mbot/drivers/map_io.hpp"

namespace mbot::sim {
namespace {

std::string Poses(const std::vector<motion::Pose2D>& poses) {
  std::vector<config::PoseValue> v;
  for (const motion::Pose2D& p : poses) v.push_back({p.x, p.y, p.theta});
  return config::FormatPoses(v);
}

}  // namespace

std::vector<std::string> HandOut(const World& world, const std::string& world_path, const EventSetup& setup,
                                 const std::string& map_path) {
  const EventInputs in = EventInputsOf(world);
  std::vector<std::string> sets;
  if (setup.task == "waypoints") {
    if (in.waypoints.empty() && !setup.waypoints_given) {
      throw std::invalid_argument(world_path +
                                  " has no 'pose start' and 'pose waypoint' lines: no circuit to hand out (give one "
                                  "with the event's waypoints = x, y, theta_deg; …, in the start's frame)");
    }
    if (!in.waypoints.empty()) sets.push_back("mission.waypoints=" + Poses(in.waypoints));
  }
  if (setup.task == "warehouse") {
    if (in.targets.empty() || in.dropoffs.empty()) {
      throw std::invalid_argument(world_path +
                                  " has no 'pose target' and 'pose dropoff' lines: no Warehouse to hand out");
    }
    sets.push_back("mission.targets=" + Poses(in.targets));
    sets.push_back("mission.dropoffs=" + Poses(in.dropoffs));
  }
  if (setup.task == "heavy_lift") {
    if (in.stacks.empty()) {
      throw std::invalid_argument(world_path + " has no 'stack' lines: no Heavy Lift to hand out");
    }
    std::string pairs;
    for (const auto& [a, b] : in.stacks)
      pairs += (pairs.empty() ? "" : ", ") + std::to_string(a) + ":" + std::to_string(b);
    sets.push_back("mission.stack=" + pairs);
  }
  if (setup.localization) {
    const std::filesystem::path dir = std::filesystem::path(map_path).parent_path();
    if (!dir.empty()) std::filesystem::create_directories(dir);
    drivers::WriteBotlabMap(RenderKnownMap(world, setup.resolution_m), map_path);
    sets.push_back("slam.map_file=" + map_path);
  }
  return sets;
}

}  // namespace mbot::sim
