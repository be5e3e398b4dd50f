// The MCAP reader from the command line, for tests/ros2/mcap_interop.py (Foxglove's `mcap` writes):
//   mbot_mcap_tool <file.mcap>
// prints JSON: the profile, the channels (topic, encoding, schema name), every message (channel,
// times, size; a LaserScan's and an Odometry's main fields decoded with our CDR), the reader's
// statistics. Exit 1 with the reader's error on a bad file.
#include <iostream>

#include <nlohmann/json.hpp>

#include "mbot/ros2/mcap_reader.hpp"
#include "mbot/ros2/messages.hpp"

using nlohmann::json;
using namespace mbot::ros2;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: mbot_mcap_tool <file.mcap>\n";
    return 2;
  }
  try {
    McapReader r(argv[1]);
    json out = {{"profile", r.profile()}, {"messages", json::array()}};
    McapMessage m;
    while (r.Next(&m)) {
      const McapChannel& c = r.channels().at(m.channel_id);
      const auto s = r.schemas().find(c.schema_id);
      const std::string type = s == r.schemas().end() ? "" : s->second.name;
      json j = {{"topic", c.topic},
                {"log_time", m.log_time_ns},
                {"publish_time", m.publish_time_ns},
                {"sequence", m.sequence},
                {"size", m.data.size()}};
      if (type == kLaserScanType) {
        const LaserScan l = DecodeLaserScan(m.data.data(), m.data.size());
        j["frame_id"] = l.header.frame_id;
        j["ranges"] = l.ranges;
      } else if (type == kOdometryType) {
        const Odometry o = DecodeOdometry(m.data.data(), m.data.size());
        j["x"] = o.pose.position.x;
        j["yaw"] = Yaw(o.pose.orientation);
      }
      out["messages"].push_back(std::move(j));
    }
    json channels = json::array();
    for (const auto& [id, c] : r.channels()) {
      const auto s = r.schemas().find(c.schema_id);
      channels.push_back({{"id", id},
                          {"topic", c.topic},
                          {"message_encoding", c.message_encoding},
                          {"schema", s == r.schemas().end() ? "" : s->second.name},
                          {"schema_encoding", s == r.schemas().end() ? "" : s->second.encoding},
                          {"metadata", c.metadata}});
    }
    out["channels"] = channels;
    const McapStats& st = r.stats();
    out["stats"] = {{"chunks", st.chunks},
                    {"messages", st.messages},
                    {"crcs_checked", st.crcs_checked},
                    {"footer", st.footer},
                    {"truncated", st.truncated}};
    std::cout << out.dump() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "mbot_mcap_tool: " << e.what() << "\n";
    return 1;
  }
}
