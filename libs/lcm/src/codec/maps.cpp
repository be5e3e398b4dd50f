// The map family: occupancy_grid_t of every generation.
#include "codec.hpp"
#include "mbot_legacy/occupancy_grid_t.hpp"
#include "mbot_w23/occupancy_grid_t.hpp"

namespace mbot::lcmio::lcm_adapter {

namespace {

template <typename Grid>
bool DecodeGrid(const uint8_t* d, size_t n, size_t count_offset, Event* ev, std::string* err) {
  if (!CheckCount(d, n, count_offset, 1, "num_cells", err)) return false;
  Grid m{};
  if (!DecodeExact(d, n, &m, err)) return false;
  if (m.width < 0 || m.height < 0 || int64_t(m.width) * m.height != m.num_cells || !(m.meters_per_cell > 0.0f) ||
      !std::isfinite(m.origin_x) || !std::isfinite(m.origin_y)) {
    *err = "grid " + std::to_string(m.width) + "x" + std::to_string(m.height) + " does not match num_cells " +
           std::to_string(m.num_cells) + " or has a bad resolution/origin";
    return false;
  }
  auto grid = std::make_shared<msgs::OccupancyGrid>(m.width, m.height, m.meters_per_cell, m.origin_x, m.origin_y);
  std::copy(m.cells.begin(), m.cells.end(), grid->cells().begin());
  for (auto& c : grid->cells()) c = std::max<int8_t>(c, -127);  // -128 is outside the log-odds range
  ev->kind = EventKind::kMap;
  ev->stamp_us = m.utime;
  ev->payload = std::shared_ptr<const msgs::OccupancyGrid>(grid);
  return true;
}

}  // namespace

void AddMapTypes(TypeTable& t) {
  t.Add(mbot_legacy::occupancy_grid_t::getHash(), "occupancy_grid_t", kLegacy,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          return DecodeGrid<mbot_legacy::occupancy_grid_t>(d, n, 36, ev, err);
        });
  t.Add(mbot_legacy::occupancy_grid_t::getHash(), "occupancy_grid_t", kCurrent, nullptr);
  t.Add(mbot_w23::occupancy_grid_t::getHash(), "occupancy_grid_t", kW23,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          // num_cells is followed by slam_mode and a string before the cells: check against the rest.
          if (!CheckString(d, n, 44, "slam_map_location", err)) return false;
          return DecodeGrid<mbot_w23::occupancy_grid_t>(d, n, 36, ev, err);
        });
}

bool Encoder::Map(const Event& ev, const OccupancyGrid& grid) {
  mbot_legacy::occupancy_grid_t m{};  // the 2023+ occupancy_grid_t has the same layout and hash
  m.utime = ev.stamp_us;
  m.origin_x = static_cast<float>(grid.origin_x()), m.origin_y = static_cast<float>(grid.origin_y());
  m.meters_per_cell = static_cast<float>(grid.resolution());
  m.width = grid.width(), m.height = grid.height();
  m.num_cells = static_cast<int32_t>(grid.cells().size());
  m.cells.assign(grid.cells().begin(), grid.cells().end());
  return Put(m);
}

}  // namespace mbot::lcmio::lcm_adapter
