// `map_writer`: writes the last map of the stream (a map file read as a source, or a SLAM_MAP
// channel of a log) in every format the project writes: botlab .map, PGM + YAML, PNG.
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/mapping/occupancy_grid.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

struct MapWriterOptions {
  std::string channel;  // empty: any map channel
  std::string basename = "map";
  bool botlab = true;
  bool ros = true;
  bool png = true;
};

class MapWriterStage : public Stage {
 public:
  explicit MapWriterStage(MapWriterOptions o) : options_(std::move(o)) {}

  void OnEvent(const msgs::Event& ev) override {
    if (ev.kind != msgs::EventKind::kMap) return;
    if (!options_.channel.empty() && ev.channel != options_.channel) return;
    map_ = std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload);
  }

  void Finish(const RunContext& ctx, bool /*interrupted*/) override {
    if (!map_) {
      mbot::log::Warn("map_writer: the input had no map" +
                      (options_.channel.empty() ? std::string() : " on channel " + options_.channel) +
                      "; nothing written");
      return;
    }
    const std::string base = ctx.output_dir + "/" + options_.basename;
    if (options_.botlab) drivers::WriteBotlabMap(*map_, base + ".map");
    if (options_.ros) drivers::WriteRosMap(*map_, base + ".yaml");
    if (options_.png) drivers::WriteMapPng(*map_, base + ".png");
    mbot::log::Info("wrote " + base + ".{map,yaml,pgm,png}");
  }

 private:
  MapWriterOptions options_;
  std::shared_ptr<const mapping::OccupancyGrid> map_;
};

}  // namespace

static StageType MapWriterStageType() {
  return {"map_writer", "writes the last map of the input as botlab .map, ROS PGM + YAML and PNG",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            MapWriterOptions o;
            o.channel = s.GetString("channel", o.channel, "map channel to take ('' for any)");
            o.basename = s.GetString("basename", o.basename, "file name (without extension) in output.dir");
            if (o.basename.empty()) s.Fail("basename", "must not be empty");
            o.botlab = s.GetBool("botlab", o.botlab, "write <basename>.map");
            o.ros = s.GetBool("ros", o.ros, "write <basename>.yaml + .pgm");
            o.png = s.GetBool("png", o.png, "write <basename>.png");
            return std::make_unique<MapWriterStage>(o);
          }};
}

const RegisterStage kMapWriterRegistered{MapWriterStageType()};

}  // namespace mbot::app
