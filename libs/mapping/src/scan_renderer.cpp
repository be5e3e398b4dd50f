// The scan renderer libs/drivers uses for MRPT simplemaps: each keyframe's scan inserted at its pose
// by the log-odds mapper (one pose per scan: no deskew).
#include "mbot/msgs/scan_renderer.hpp"

#include "mbot/mapping/log_odds_mapper.hpp"
#include "mbot/mapping/moving_scan.hpp"

namespace mbot::mapping {

void RegisterScanRenderer() {
  msgs::SetScanRenderer([](const std::vector<msgs::PosedScan>& scans, double resolution_m, const msgs::Pose2D& c) {
    MapperOptions options;
    options.resolution_m = resolution_m;
    options.center_x_m = c.x;
    options.center_y_m = c.y;
    LogOddsMapper mapper(options);
    const ScanOptions scan_options;
    for (const msgs::PosedScan& p : scans) {
      const std::vector<float> fractions(p.scan.ranges_m.size(), 1.0f);  // a keyframe's scan has one pose
      mapper.Insert(DeskewScan(p.scan.ranges_m, p.scan.angles_rad, fractions, {}, p.scan.sensor_pose,
                               p.scan.max_range_m, scan_options),
                    p.robot);
    }
    return msgs::RenderedGrid{mapper.map(), mapper.rejected_scans()};
  });
}

}  // namespace mbot::mapping
