// Botlab-style mazes made to order: a grid of square cells (0.61 m, the botlab's wall panels) carved
// into a perfect maze by a randomised depth-first search, then opened up — extra openings (loops),
// open rooms (blocks of cells with their inner walls gone) — and written as the project's arena
// files. One seed, one maze: the same seed and style always give the same maze.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mbot::sim {

// What a generated maze may look like; each maze draws its own size and style from these ranges
// (set a minimum equal to its maximum to fix it).
struct MazeStyle {
  int min_cols = 4, max_cols = 8;  // cells along x
  int min_rows = 4, max_rows = 8;  // cells along y
  double cell_m = 0.61;            // botlab wall panels: 0.61 m long
  double thickness_m = 0.02;       // panel thickness (corridors cell_m - thickness_m wide)
  double resolution_m = 0.025;     // the arena's scoring grid
  // Chance that the carving keeps its direction where it can: 0 gives a twisty maze, near 1 long
  // straight corridors. Drawn uniformly from [min, max] per maze.
  double min_straightness = 0.0, max_straightness = 0.9;
  // Share of the perfect maze's inner walls taken out afterwards (each makes a loop).
  double min_openings = 0.0, max_openings = 0.15;
  // Open rooms: 2 × 2 blocks of cells (2 × 3 where the maze is large enough) without inner walls.
  int min_rooms = 0, max_rooms = 2;
};

// Throws std::invalid_argument naming the field when a range is empty or out of bounds
// (sizes 2..32 cells, shares in [0, 1], positive lengths).
void CheckMazeStyle(const MazeStyle& style);

struct Maze {
  uint64_t seed = 0;
  int cols = 0, rows = 0;
  double cell_m = 0.61, thickness_m = 0.02, resolution_m = 0.025;
  double straightness = 0.0;  // as drawn for this maze
  int openings = 0;           // inner walls removed after carving
  int rooms = 0;
  // Walls. Horizontal line j (0..rows) runs below cell row j; its piece i spans column i.
  // Vertical line i (0..cols) runs left of cell column i; its piece j spans row j.
  std::vector<uint8_t> horizontal;  // (rows + 1) × cols, row-major by line
  std::vector<uint8_t> vertical;    // (cols + 1) × rows, row-major by line
  double start_theta_deg = 0.0;     // the robot starts in cell (0, 0), facing its first opening

  bool HWall(int i, int j) const { return horizontal[static_cast<size_t>(j) * cols + i] != 0; }
  bool VWall(int i, int j) const { return vertical[static_cast<size_t>(i) * rows + j] != 0; }
  int DeadEnds() const;         // cells with three walls
  int LongestCorridor() const;  // most cells in a straight run without a wall across it
  int Loops() const;            // independent cycles: open passages - (cells - 1)
  std::string Drawing() const;  // ASCII art, north up, S at the start
  // The arena file: a header comment with the drawing and the style, straight walls merged from
  // panels, `pose start`. Cell (0, 0)'s centre is the origin, x along columns, y along rows.
  std::string ToArena() const;
};

Maze GenerateMaze(const MazeStyle& style, uint64_t seed);

}  // namespace mbot::sim
