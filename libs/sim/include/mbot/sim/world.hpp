// The simulator's world: what the walls are, for the simulated lidar (ray casting), the collision
// check (the robot's footprint against the walls) and the competition's scoring (the true map).
// Loaded from the project's own arena description (wall segments in metres, `.arena`), a botlab
// `.map`, a ROS map_server `.yaml` + image or any other map format ReadAnyMap reads; in a grid world
// every cell that is not known free (occupied or unknown) is a wall, so real arena maps with gaps in
// their unknown border still enclose the robot.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::sim {

struct WallSegment {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [m]
};

// The arena file format (`.arena`, text, one statement per line, `#` starts a comment):
//   name <text>                      a human name for the arena
//   resolution <m>                   cell size of the true map used for scoring (default 0.025)
//   thickness <m>                    thickness of the walls that follow (default 0.02; botlab panels)
//   wall <x0> <y0> <x1> <y1>         a wall segment [m]
//   box <x0> <y0> <x1> <y1>          the four walls of an axis-aligned rectangle
//   pose <label> <x> <y> <theta>     a named pose (theta in degrees); labels used by the competition:
//                                    start, waypoint (in order, the speed-run circuit), target,
//                                    dropoff (in order, warehouse levels); any label may repeat
//   crate <id> <x> <y> <theta> [<width> <depth> <height>]
//                                    a crate (Heavy Lift): a box standing on the floor, centred at
//                                    (x, y), turned theta degrees, its sides in metres (default
//                                    0.10 × 0.10 × 0.08), a tag36h11 tag `id` on each vertical face
//   crates_at_random <count> <x> <y> [<side> <first_id>]
//                                    `count` crates (ids first_id, first_id + 1, …; default 1) of the
//                                    default size at random poses inside the side × side square
//                                    (default 1 m) centred at (x, y), drawn from the run's seed,
//                                    each at least 0.3 m from any other crate
//   stack <id> <on_id>               Heavy Lift: crate `id` is to be stacked on crate `on_id`, in
//                                    the order of the lines (the day's assignments)
// Errors name the file and the line. Walls are capsules: the segment thickened by thickness/2 on
// every side, ends rounded (so walls meeting at a corner leave no notch); Raycast, Collides and
// ClearanceAt all use that one shape. One thickness per arena: a `thickness` statement after the
// first wall must repeat the value already in force.
struct ArenaPose {
  std::string label;
  motion::Pose2D pose;
};

// A request for crates at random (arena statement crates_at_random), resolved with a run's seed.
struct CrateArea {
  int count = 1;
  double x = 0.0, y = 0.0;  // the square's centre
  double side_m = 1.0;
  int first_id = 1;
  double min_gap_m = 0.3;  // between a crate's footprint and any other's
};

// A crate: a box on the floor that the lidar sees and the robot's body must not touch. Not part of
// the true map (crates move; the maps scored are the walls'). The defaults are botlab-like: a
// 10 cm cube-ish box a little lower than wide, so the MBot's fork (about 5 cm up) meets its faces.
struct Crate {
  int id = 0;             // the tag36h11 id printed on each vertical face
  motion::Pose2D pose;    // centre on the floor, heading of its x side
  double width_m = 0.10;  // along its own x
  double depth_m = 0.10;  // along its own y
  double height_m = 0.08;
  // Where it is now (the forklift moves crates, libs/sim/forklift.hpp): its underside's height
  // above the floor, on the fork or not, the crate it was set down on (-1: none), whether it fell
  // (set down off-centre on another and tipped off), and whether it was ever lifted clear.
  double z_m = 0.0;
  bool carried = false;
  int on_id = -1;
  bool fell = false;
  bool lifted = false;
  // On the floor and not on the fork: what the lidar and the robot's body meet.
  bool OnFloor() const { return !carried && z_m <= 1e-9; }
  double top_m() const { return z_m + height_m; }
  // Distance from (x, y) to the box's footprint (0 inside or on it).
  double DistanceTo(double x, double y) const;
  // Distance along the ray from (x, y) at `angle_rad` to the footprint's boundary, 0 when (x, y) is
  // inside, +inf when the ray misses it.
  double RayDistance(double x, double y, double angle_rad) const;
  // Points every `step_m` (at most) round the footprint's edge, and its centre (overlap tests).
  std::vector<std::pair<double, double>> Outline(double step_m) const;
  // True when the two footprints overlap or touch.
  bool Overlaps(const Crate& other) const;
};

struct WorldIndex;

class World {
 public:
  World() = default;

  // Reads any world file (see above) by its extension / content. Throws std::runtime_error naming
  // the file (and line for `.arena`).
  static World Load(const std::string& path);
  // Parses an arena description held in a string (`origin` names it in errors, e.g. a file path).
  static World ParseArena(const std::string& text, const std::string& origin);
  // A world of wall segments; the true map is rasterised at `resolution_m` with a margin around.
  static World FromSegments(std::vector<WallSegment> walls, double thickness_m, double resolution_m);
  // A world whose walls are the grid's cells that are not known free (> 0 or unknown).
  static World FromGrid(const mapping::OccupancyGrid& grid);

  const std::string& name() const { return name_; }
  // Distance from (x, y) along `angle_rad` to the first wall surface, or `max_range_m` when no wall
  // is nearer; 0 when (x, y) is inside a wall. Exact against segments (walls as capsules, see
  // above) in an arena world, where leaving the true map's extent means no wall; cell-exact (DDA
  // over the true map, to the first wall cell's boundary) in a grid world, where everything outside
  // the grid is wall. Thread-safe (no mutable state).
  double Raycast(double x, double y, double angle_rad, double max_range_m) const;
  // The same against the walls only (crates left out).
  double RaycastWalls(double x, double y, double angle_rad, double max_range_m) const;
  // True when a disc of `radius_m` centred at (x, y) overlaps or touches a wall
  // (ClearanceAt(x, y) <= radius_m), or leaves the true map's extent.
  bool Collides(double x, double y, double radius_m) const;
  // The distance from (x, y) to the nearest wall surface [m] (0 inside a wall). Grid world: exact
  // distance to the nearest wall cell's square, the outside of the grid counting as wall.
  double ClearanceAt(double x, double y) const;
  // The true map: walls +127, everything else -127 (free), at the world's resolution.
  const mapping::OccupancyGrid& truth() const { return truth_; }
  // Named poses of an arena file, in file order (empty for grid worlds).
  const std::vector<ArenaPose>& poses() const { return poses_; }
  std::vector<motion::Pose2D> PosesLabelled(const std::string& label) const;
  const std::vector<WallSegment>& walls() const { return walls_; }
  // Crates (Heavy Lift): Raycast, Collides and ClearanceAt see those on the floor (Crate::OnFloor)
  // as well as the walls; `ignore_crate` (an index into crates()) leaves one out — the crate on
  // the robot's fork tines.
  const std::vector<Crate>& crates() const { return crates_; }
  // Moves crate `index` (the forklift): no overlap check, the caller has made it.
  void SetCrate(size_t index, const Crate& crate) { crates_.at(index) = crate; }
  bool Collides(double x, double y, double radius_m, int ignore_crate) const;
  double ClearanceAt(double x, double y, int ignore_crate) const;
  // The distance from (x, y) to the nearest wall surface, crates left out (0 inside a wall).
  double WallsClearanceAt(double x, double y) const;
  // Adds a crate; throws std::invalid_argument when its sides are not positive or it overlaps a wall
  // or another crate (naming its id).
  void AddCrate(const Crate& crate);
  // The arena's crates_at_random request, if any (PlaceCratesAtRandom resolves it).
  const std::optional<CrateArea>& crate_area() const { return crate_area_; }
  // Heavy Lift's assignments (stack statements): (crate, crate it goes on), in order.
  const std::vector<std::pair<int, int>>& stacks() const { return stacks_; }
  double wall_thickness() const { return thickness_; }  // 0 for a grid world
  bool is_grid_world() const { return walls_.empty(); }

 private:
  std::string name_;
  std::vector<WallSegment> walls_;  // empty for a grid world
  double thickness_ = 0.02;
  std::vector<ArenaPose> poses_;
  std::vector<Crate> crates_;
  std::optional<CrateArea> crate_area_;
  std::vector<std::pair<int, int>> stacks_;
  bool WallsCollide(double x, double y, double radius_m) const;
  mapping::OccupancyGrid truth_;
  // Acceleration structures (bucket grid over the walls, or the grid's distance transform), built
  // once and shared by copies; defined in world.cpp.
  std::shared_ptr<const WorldIndex> index_;
};

// The free cells of the true map connected to `start`'s cell (4-connected flood fill over free
// cells), as a 0/1 mask in the truth's cell order: what "reachable free space" means when an
// exploration run is scored. Throws when the start is not in a free cell.
std::vector<uint8_t> ReachableFreeMask(const World& world, const motion::Pose2D& start);

// The free cells a round robot of `radius_m` starting at `start` can touch: its centre moves through
// free cells at least `radius_m` from every wall (4-connected, from the start's cell), and every free
// cell within `radius_m` of a cell its centre reaches is reached by its body. Unlike
// ReachableFreeMask this does not leak through a gap narrower than the robot.
std::vector<uint8_t> BodyReachableMask(const World& world, const motion::Pose2D& start, double radius_m);

// The world as a known map at `resolution_m` (a competition's given map, e.g. the Warehouse's):
// cells whose centre is within half a cell side of a wall are occupied (+127; what a mapped wall
// looks like, not every cell a wall grazes), cells of the reachable free space (from the world's
// `start` pose, or every free cell of a world without one) free (-127), everything else unknown.
// The map's frame is the world frame.
mapping::OccupancyGrid RenderKnownMap(const World& world, double resolution_m);

// What the organisers hand a team for an event in this world, which the autonomy gets through its
// own configuration keys (it never reads the world): the circuit (the `waypoint` poses in the frame
// of the `start` pose, where SLAM begins), and the Warehouse's `target` and `dropoff` poses in the
// world frame (the known map's frame, RenderKnownMap). Empty where the world has none.
struct EventInputs {
  std::vector<motion::Pose2D> waypoints;
  std::vector<motion::Pose2D> targets;
  std::vector<motion::Pose2D> dropoffs;
  std::vector<std::pair<int, int>> stacks;  // Heavy Lift: (crate, crate it goes on)
};
EventInputs EventInputsOf(const World& world);

// A pose drawn uniformly from the free space reachable from the world's `start` pose (any free
// space when it has none) that keeps `clearance_m` from every wall, heading uniform; the same seed
// gives the same pose. Throws when 10,000 draws find no such place.
motion::Pose2D RandomFreePose(const World& world, double clearance_m, uint64_t seed);

// Where a world without a start pose starts: the free cell of the true map farthest from any wall
// (the most room), ties within half a cell broken by `seed`, heading drawn from `seed`.
motion::Pose2D MostRoomPose(const World& world, uint64_t seed);

// Adds area.count crates of the default size at uniform random positions and headings inside the
// area's square, each clear of the walls, area.min_gap_m from the other crates and `keep_clear_m` from `keep_clear`
// (the robot's start, so the robot does not start touching one). The same seed gives the same
// crates. Throws std::runtime_error naming the world when 10,000 draws cannot place them all.
void PlaceCratesAtRandom(World* world, const CrateArea& area, uint64_t seed, const motion::Pose2D& keep_clear,
                         double keep_clear_m);

}  // namespace mbot::sim
