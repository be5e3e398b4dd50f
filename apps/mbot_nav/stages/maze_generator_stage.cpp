// `maze_generator`: writes seeded botlab-style mazes (libs/sim) as arena files, with a PNG of each
// and an index (mazes.csv); the simulator and the Maze Explorer take them as source.path.
#include <climits>
#include <cstdio>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/sim/maze_generator.hpp"
#include "mbot/sim/world.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

struct MazeGeneratorOptions {
  sim::MazeStyle style;
  int count = 10;
  int first_seed = 1;
  std::string basename = "maze";
  bool png = true;
};

class MazeGeneratorStage : public Stage {
 public:
  explicit MazeGeneratorStage(MazeGeneratorOptions o) : o_(std::move(o)) {}
  void OnEvent(const msgs::Event&) override {}

  void Finish(const RunContext& ctx, bool /*interrupted*/) override {
    std::ostringstream index;
    index << "file,seed,cols,rows,straightness,rooms,openings,loops,dead_ends,longest_corridor_cells\n";
    for (int k = 0; k < o_.count; ++k) {
      const uint64_t seed = static_cast<uint64_t>(o_.first_seed) + k;
      const sim::Maze maze = sim::GenerateMaze(o_.style, seed);
      const std::string name = o_.basename + "_" + std::to_string(seed);
      const std::string text = maze.ToArena();
      WriteFileAtomically(ctx.output_dir + "/" + name + ".arena", [&](std::ostream& f) { f << text; });
      if (o_.png) {
        const sim::World world = sim::World::ParseArena(text, name + ".arena");
        drivers::WriteMapPng(world.truth(), ctx.output_dir + "/" + name + ".png");
      }
      char row[160];
      std::snprintf(row, sizeof row, "%s.arena,%llu,%d,%d,%.3f,%d,%d,%d,%d,%d\n", name.c_str(),
                    static_cast<unsigned long long>(seed), maze.cols, maze.rows, maze.straightness, maze.rooms,
                    maze.openings, maze.Loops(), maze.DeadEnds(), maze.LongestCorridor());
      index << row;
    }
    WriteFileAtomically(ctx.output_dir + "/mazes.csv", [&](std::ostream& f) { f << index.str(); });
    mbot::log::Info("maze_generator: wrote " + std::to_string(o_.count) + " arenas (" + o_.basename + "_" +
                    std::to_string(o_.first_seed) + ".arena …) and mazes.csv in " + ctx.output_dir);
  }

 private:
  MazeGeneratorOptions o_;
};

}  // namespace

static StageType MazeGeneratorStageType() {
  return {"maze_generator",
          "writes seeded botlab-style mazes (perfect maze + loops, long corridors, open rooms, dead ends) as arena "
          "files with a PNG each and mazes.csv",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            MazeGeneratorOptions o;
            sim::MazeStyle& st = o.style;
            o.count = s.GetInt("count", o.count, "how many mazes", 1, 100000);
            // Seeds are ints end to end (the sweep's seeds, the arena names): the last one must be one too.
            o.first_seed = static_cast<int>(
                s.GetInt("first_seed", o.first_seed, "seed of the first maze; the others count up", 0, INT_MAX));
            if (static_cast<long long>(o.first_seed) + o.count - 1 > INT_MAX)
              s.Fail("first_seed", "first_seed + count - 1 passes " + std::to_string(INT_MAX));
            o.basename = s.GetString("basename", o.basename, "files are <basename>_<seed>.arena/.png");
            if (o.basename.empty() || o.basename.find('/') != std::string::npos)
              s.Fail("basename", "must be a plain file name");
            o.png = s.GetBool("png", o.png, "write a PNG of each maze's true map");
            st.min_cols = s.GetInt("min_cols", st.min_cols, "fewest cells along x", 2, 32);
            st.max_cols = s.GetInt("max_cols", st.max_cols, "most cells along x", 2, 32);
            st.min_rows = s.GetInt("min_rows", st.min_rows, "fewest cells along y", 2, 32);
            st.max_rows = s.GetInt("max_rows", st.max_rows, "most cells along y", 2, 32);
            st.cell_m = s.GetDouble("cell_m", st.cell_m, "cell size (botlab wall panel length) [m]", 0.2, 5.0);
            st.thickness_m = s.GetDouble("thickness_m", st.thickness_m, "wall thickness [m]", 0.001, 0.5);
            st.resolution_m =
                s.GetDouble("resolution_m", st.resolution_m, "cell size of the arena's scoring grid [m]", 0.005, 0.2);
            st.min_straightness = s.GetDouble("min_straightness", st.min_straightness,
                                              "chance the carving keeps its direction (long corridors), lowest", 0, 1);
            st.max_straightness = s.GetDouble("max_straightness", st.max_straightness, "... highest", 0, 1);
            st.min_openings = s.GetDouble("min_openings", st.min_openings,
                                          "share of inner walls removed after carving (loops), lowest", 0, 1);
            st.max_openings = s.GetDouble("max_openings", st.max_openings, "... highest", 0, 1);
            st.min_rooms = s.GetInt("min_rooms", st.min_rooms, "open rooms (2x2 or 2x3 cells), fewest", 0, 16);
            st.max_rooms = s.GetInt("max_rooms", st.max_rooms, "... most", 0, 16);
            auto ordered = [&](const char* lo, double l, const char* hi, double h) {
              if (h < l) s.Fail(hi, std::string("is below ") + lo);
            };
            ordered("min_cols", st.min_cols, "max_cols", st.max_cols);
            ordered("min_rows", st.min_rows, "max_rows", st.max_rows);
            ordered("min_straightness", st.min_straightness, "max_straightness", st.max_straightness);
            ordered("min_openings", st.min_openings, "max_openings", st.max_openings);
            ordered("min_rooms", st.min_rooms, "max_rooms", st.max_rooms);
            if (st.thickness_m >= st.cell_m / 2) s.Fail("thickness_m", "must be below half of cell_m");
            return std::make_unique<MazeGeneratorStage>(o);
          }};
}

const RegisterStage kMazeGeneratorRegistered{MazeGeneratorStageType()};

}  // namespace mbot::app
