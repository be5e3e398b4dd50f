// A robot on ROS 2 played by eProsima Fast DDS (the other DDS vendor; its types from fastddsgen on
// mbot_ros2.idl), against mbot_nav's Cyclone DDS transport: for a few seconds it publishes what the
// MBot publishes — /tf_static (base_footprint → lidar_link, the lidar turned 180° as on the MBot;
// reliable, transient local), /odom (25 Hz) and /scan (10 Hz) of a 3 m square room with a gap in
// its +x wall — and listens to /cmd_vel. Then a reader that joins late asks for /map (reliable,
// transient local). It exits 0 when the stack commanded a non-zero velocity and the late reader got
// a map in which the wall at −x is occupied and the gap at +x is not (the mount was applied), and
// the autonomy announced itself on ros_discovery_info as rmw_cyclonedds does: a node "/mbot_nav"
// whose writer GIDs hold the GUID of the writer its /cmd_vel came from, under that writer's
// participant (what `ros2 node list` and `ros2 node info` read). It also serves /reset_odometry
// (std_srvs/Trigger) as the MBot's micro-ROS agent does (Micro-XRCE-DDS-Agent's FastDDSReplier:
// the reply carries the request's sample identity as its related sample identity) and requires a
// request to have come and been answered.
//   mbot_fastdds_peer <domain id> <seconds> [listen]
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <thread>

#include "mbot_ros2PubSubTypes.h"

using namespace eprosima::fastdds::dds;
namespace geo = geometry_msgs::msg::dds_;

namespace {

using Clock = std::chrono::steady_clock;

builtin_interfaces::msg::dds_::Time_ Now() {
  const auto ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  builtin_interfaces::msg::dds_::Time_ t;
  t.sec(static_cast<int32_t>(ns / 1000000000));
  t.nanosec(static_cast<uint32_t>(ns % 1000000000));
  return t;
}

// The room: walls at x = ±1.5 and y = ±1.5 m, the +x wall open for |y| < 0.4 m. The distance from
// the centre along a robot-frame bearing, or infinity through the gap.
float Range(double bearing) {
  const double c = std::cos(bearing), s = std::sin(bearing);
  double t = 1e9;
  if (std::abs(c) > 1e-9) {
    const double tx = 1.5 / std::abs(c);
    const double y = s * tx;
    if (!(c > 0 && std::abs(y) < 0.4)) t = std::min(t, tx);
  }
  if (std::abs(s) > 1e-9) t = std::min(t, 1.5 / std::abs(s));
  return t < 12.0 ? static_cast<float>(t) : INFINITY;
}

template <typename T>
struct Endpoint {
  Topic* topic = nullptr;
};

}  // namespace

// `listen`: RViz's side of a replay published over DDS (mbot_nav's `ros2` output). For `seconds`
// it reads /scan and /tf (best effort, as RViz does), then a late reader asks for /map and
// /tf_static (reliable, transient local). Exits 0 when scans of 100+ beams and odom → base_footprint
// transforms came, the late reader got a map with occupied and free cells, and /tf_static holds the
// lidar's mount through base_link.
int Listen(DomainParticipant* pp, double seconds) {
  TypeSupport scan_t(new sensor_msgs::msg::dds_::LaserScan_PubSubType());
  TypeSupport tf_t(new tf2_msgs::msg::dds_::TFMessage_PubSubType());
  TypeSupport map_t(new nav_msgs::msg::dds_::OccupancyGrid_PubSubType());
  for (TypeSupport* t : {&scan_t, &tf_t, &map_t}) t->register_type(pp);
  Subscriber* sub = pp->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  DataReaderQos sensor = DATAREADER_QOS_DEFAULT;
  sensor.reliability().kind = BEST_EFFORT_RELIABILITY_QOS;
  DataReaderQos latched = DATAREADER_QOS_DEFAULT;
  latched.reliability().kind = RELIABLE_RELIABILITY_QOS;
  latched.durability().kind = TRANSIENT_LOCAL_DURABILITY_QOS;
  DataReader* scan_r =
      sub->create_datareader(pp->create_topic("rt/scan", scan_t.get_type_name(), TOPIC_QOS_DEFAULT), sensor);
  DataReader* tf_r = sub->create_datareader(pp->create_topic("rt/tf", tf_t.get_type_name(), TOPIC_QOS_DEFAULT), sensor);
  if (!scan_r || !tf_r) return std::fprintf(stderr, "peer: readers not created\n"), 2;
  long scans = 0, wide = 0, odom_tf = 0;
  const auto start = Clock::now();
  while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
    sensor_msgs::msg::dds_::LaserScan_ scan;
    SampleInfo info;
    while (scan_r->take_next_sample(&scan, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      ++scans;
      if (scan.ranges().size() >= 100 && scan.header().frame_id() == "lidar_link") ++wide;
    }
    tf2_msgs::msg::dds_::TFMessage_ tf;
    while (tf_r->take_next_sample(&tf, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      for (const auto& t : tf.transforms()) {
        if (t.header().frame_id() == "odom" && t.child_frame_id() == "base_footprint") ++odom_tf;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::printf("peer: %ld /scan (%ld of 100+ beams in lidar_link), %ld odom -> base_footprint on /tf\n", scans, wide,
              odom_tf);
  DataReader* map_r =
      sub->create_datareader(pp->create_topic("rt/map", map_t.get_type_name(), TOPIC_QOS_DEFAULT), latched);
  DataReader* static_r =
      sub->create_datareader(pp->create_topic("rt/tf_static", tf_t.get_type_name(), TOPIC_QOS_DEFAULT), latched);
  bool map_ok = false, mount_ok = false;
  const auto wait_end = Clock::now() + std::chrono::seconds(5);
  while ((!map_ok || !mount_ok) && Clock::now() < wait_end) {
    nav_msgs::msg::dds_::OccupancyGrid_ g;
    SampleInfo info;
    while (map_r && map_r->take_next_sample(&g, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      long occupied = 0, free_cells = 0;
      for (int8_t v : g.data()) occupied += v == 100, free_cells += v == 0;
      map_ok = g.info().width() > 0 && occupied > 0 && free_cells > 0;
      std::printf("peer: late reader got /map %ux%u (%ld occupied, %ld free)\n", g.info().width(), g.info().height(),
                  occupied, free_cells);
    }
    tf2_msgs::msg::dds_::TFMessage_ tf;
    while (static_r && static_r->take_next_sample(&tf, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      bool base = false, lidar = false;
      for (const auto& t : tf.transforms()) {
        base = base || (t.header().frame_id() == "base_footprint" && t.child_frame_id() == "base_link");
        lidar = lidar || (t.header().frame_id() == "base_link" && t.child_frame_id() == "lidar_link");
      }
      mount_ok = base && lidar;
      std::printf("peer: late reader got /tf_static (%zu transforms%s)\n", tf.transforms().size(),
                  mount_ok ? ": base_footprint -> base_link -> lidar_link" : "");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  pp->delete_contained_entities();
  DomainParticipantFactory::get_instance()->delete_participant(pp);
  const bool ok = wide > 0 && odom_tf > 0 && map_ok && mount_ok;
  std::printf("%s\n", ok ? "PASS" : "FAIL: no scans, no odom transforms, no map or no mount for the late reader");
  return ok ? 0 : 1;
}

int main(int argc, char** argv) {
  const int domain = argc > 1 ? std::atoi(argv[1]) : 0;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 8.0;
  DomainParticipant* pp = DomainParticipantFactory::get_instance()->create_participant(domain, PARTICIPANT_QOS_DEFAULT);
  if (!pp) return std::fprintf(stderr, "peer: no participant\n"), 2;
  if (argc > 3 && std::string(argv[3]) == "listen") return Listen(pp, seconds);
  TypeSupport scan_t(new sensor_msgs::msg::dds_::LaserScan_PubSubType());
  TypeSupport odom_t(new nav_msgs::msg::dds_::Odometry_PubSubType());
  TypeSupport tf_t(new tf2_msgs::msg::dds_::TFMessage_PubSubType());
  TypeSupport twist_t(new geo::Twist_PubSubType());
  TypeSupport map_t(new nav_msgs::msg::dds_::OccupancyGrid_PubSubType());
  TypeSupport info_t(new rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_PubSubType());
  TypeSupport req_t(new std_srvs::srv::dds_::Trigger_Request_PubSubType());
  TypeSupport rep_t(new std_srvs::srv::dds_::Trigger_Response_PubSubType());
  for (TypeSupport* t : {&scan_t, &odom_t, &tf_t, &twist_t, &map_t, &info_t, &req_t, &rep_t}) t->register_type(pp);
  Topic* req_topic = pp->create_topic("rq/reset_odometryRequest", req_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Topic* rep_topic = pp->create_topic("rr/reset_odometryReply", rep_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Topic* info_topic = pp->create_topic("ros_discovery_info", info_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Topic* scan_topic = pp->create_topic("rt/scan", scan_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Topic* odom_topic = pp->create_topic("rt/odom", odom_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Topic* tf_topic = pp->create_topic("rt/tf_static", tf_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Topic* cmd_topic = pp->create_topic("rt/cmd_vel", twist_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Topic* map_topic = pp->create_topic("rt/map", map_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Publisher* pub = pp->create_publisher(PUBLISHER_QOS_DEFAULT);
  Subscriber* sub = pp->create_subscriber(SUBSCRIBER_QOS_DEFAULT);

  DataWriterQos reliable = DATAWRITER_QOS_DEFAULT;
  reliable.reliability().kind = RELIABLE_RELIABILITY_QOS;
  reliable.history().depth = 10;
  DataWriterQos latched = reliable;
  latched.durability().kind = TRANSIENT_LOCAL_DURABILITY_QOS;
  latched.history().depth = 1;
  DataWriter* scan_w = pub->create_datawriter(scan_topic, reliable);
  DataWriter* odom_w = pub->create_datawriter(odom_topic, reliable);
  DataWriter* tf_w = pub->create_datawriter(tf_topic, latched);
  DataReaderQos cmd_q = DATAREADER_QOS_DEFAULT;
  cmd_q.reliability().kind = RELIABLE_RELIABILITY_QOS;
  DataReader* cmd_r = sub->create_datareader(cmd_topic, cmd_q);
  DataReaderQos info_q = DATAREADER_QOS_DEFAULT;  // as rmw's: reliable, transient local, all kept
  info_q.reliability().kind = RELIABLE_RELIABILITY_QOS;
  info_q.durability().kind = TRANSIENT_LOCAL_DURABILITY_QOS;
  info_q.history().kind = KEEP_ALL_HISTORY_QOS;
  DataReader* info_r = sub->create_datareader(info_topic, info_q);
  // The service's endpoints as rmw makes them: reliable, volatile, keep last 10.
  DataReaderQos req_q = DATAREADER_QOS_DEFAULT;
  req_q.reliability().kind = RELIABLE_RELIABILITY_QOS;
  req_q.history().depth = 10;
  DataReader* req_r = sub->create_datareader(req_topic, req_q);
  DataWriter* rep_w = pub->create_datawriter(rep_topic, reliable);
  if (!scan_w || !odom_w || !tf_w || !cmd_r || !info_r || !req_r || !rep_w)
    return std::fprintf(stderr, "peer: endpoints not created\n"), 2;
  long resets = 0, reset_replies = 0;
  std::set<std::string> cmd_writers;  // the 16-byte GUIDs /cmd_vel came from

  // The lidar's mount, as robot_state_publisher says it: z 0.142 m, yaw 180° (z axis up).
  tf2_msgs::msg::dds_::TFMessage_ tf;
  geo::TransformStamped_ mount;
  mount.header().stamp(Now());
  mount.header().frame_id("base_footprint");
  mount.child_frame_id("lidar_link");
  mount.transform().translation().z(0.142);
  mount.transform().rotation().z(1.0);
  mount.transform().rotation().w(0.0);
  tf.transforms().push_back(mount);
  tf_w->write(&tf);

  const auto start = Clock::now();
  auto next_scan = start, next_odom = start;
  long scans = 0, odoms = 0, commands = 0, moving = 0;
  while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
    const auto now = Clock::now();
    if (now >= next_odom) {
      nav_msgs::msg::dds_::Odometry_ o;
      o.header().stamp(Now());
      o.header().frame_id("odom");
      o.child_frame_id("base_footprint");
      o.pose().pose().orientation().w(1.0);
      odom_w->write(&o);
      ++odoms;
      next_odom += std::chrono::milliseconds(40);
    }
    if (now >= next_scan) {
      sensor_msgs::msg::dds_::LaserScan_ s;
      s.header().stamp(Now());
      s.header().frame_id("lidar_link");
      const int n = 360;
      s.angle_min(static_cast<float>(-M_PI));
      s.angle_increment(static_cast<float>(2 * M_PI / n));
      s.angle_max(static_cast<float>(-M_PI + 2 * M_PI / n * (n - 1)));
      s.scan_time(0.1f);
      s.range_min(0.15f);
      s.range_max(12.0f);
      for (int i = 0; i < n; ++i) s.ranges().push_back(Range(-M_PI + 2 * M_PI / n * i + M_PI));  // lidar → robot
      scan_w->write(&s);
      ++scans;
      next_scan += std::chrono::milliseconds(100);
    }
    std_srvs::srv::dds_::Trigger_Request_ request;
    SampleInfo req_info;
    while (req_r->take_next_sample(&request, &req_info) == ReturnCode_t::RETCODE_OK) {
      if (!req_info.valid_data) continue;
      ++resets;
      std_srvs::srv::dds_::Trigger_Response_ reply;
      reply.success(true);
      reply.message("Odometry reset to (0, 0, 0)");
      eprosima::fastrtps::rtps::WriteParams wp;
      wp.related_sample_identity(req_info.sample_identity);
      if (rep_w->write(&reply, wp)) ++reset_replies;
    }
    geo::Twist_ t;
    SampleInfo info;
    while (cmd_r->take_next_sample(&t, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const auto& g = info.sample_identity.writer_guid();
      std::string guid(16, '\0');
      std::memcpy(&guid[0], g.guidPrefix.value, 12);
      std::memcpy(&guid[12], g.entityId.value, 4);
      cmd_writers.insert(guid);
      ++commands;
      if (std::abs(t.linear().x()) > 1e-6 || std::abs(t.angular().z()) > 1e-6) ++moving;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::printf("peer: published %ld scans, %ld odometry; received %ld /cmd_vel (%ld non-zero)\n", scans, odoms, commands,
              moving);
  std::printf("peer: /reset_odometry: %ld requests, %ld replies\n", resets, reset_replies);

  // A reader that joins late: /map comes from the writer's history (transient local).
  DataReaderQos map_q = DATAREADER_QOS_DEFAULT;
  map_q.reliability().kind = RELIABLE_RELIABILITY_QOS;
  map_q.durability().kind = TRANSIENT_LOCAL_DURABILITY_QOS;
  DataReader* map_r = sub->create_datareader(map_topic, map_q);
  bool got_map = false, wall_seen = false, gap_open = false;
  const auto wait_end = Clock::now() + std::chrono::seconds(5);
  while (!got_map && Clock::now() < wait_end) {
    nav_msgs::msg::dds_::OccupancyGrid_ g;
    SampleInfo info;
    while (map_r && map_r->take_next_sample(&g, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      got_map = true;
      const auto& m = g.info();
      auto cell = [&](double x, double y) {
        const int cx = static_cast<int>(std::floor((x - m.origin().position().x()) / m.resolution()));
        const int cy = static_cast<int>(std::floor((y - m.origin().position().y()) / m.resolution()));
        if (cx < 0 || cy < 0 || cx >= static_cast<int>(m.width()) || cy >= static_cast<int>(m.height())) return -2;
        return static_cast<int>(g.data()[static_cast<size_t>(cy) * m.width() + cx]);
      };
      // Occupied somewhere on the −x wall near y = 0; nothing occupied in the +x gap.
      for (double y = -0.2; y <= 0.2; y += m.resolution()) {
        for (double x = -1.6; x <= -1.4; x += m.resolution()) wall_seen = wall_seen || cell(x, y) == 100;
      }
      gap_open = true;
      for (double y = -0.2; y <= 0.2; y += m.resolution()) {
        for (double x = 1.4; x <= 1.6; x += m.resolution()) gap_open = gap_open && cell(x, y) != 100;
      }
      std::printf("peer: late reader got /map %ux%u at %.3f m (wall at -x %s, gap at +x %s)\n", m.width(), m.height(),
                  m.resolution(), wall_seen ? "occupied" : "NOT occupied", gap_open ? "open" : "CLOSED");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  // ros_discovery_info: the latest announcement of the participant whose writer sent /cmd_vel.
  bool node_named = false, writer_listed = false;
  int announcements = 0;
  rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_ pinfo;
  SampleInfo pi;
  while (info_r->take_next_sample(&pinfo, &pi) == ReturnCode_t::RETCODE_OK) {
    if (!pi.valid_data) continue;
    ++announcements;
    const std::string ppgid(pinfo.gid().data().begin(), pinfo.gid().data().end());
    for (const auto& node : pinfo.node_entities_info_seq()) {
      bool mine = false;
      for (const auto& w : node.writer_gid_seq()) {
        const std::string gid(w.data().begin(), w.data().end());
        // The writer's GUID, under its participant's (the same prefix, entity 0x000001c1).
        if (cmd_writers.count(gid) && ppgid.compare(0, 12, gid, 0, 12) == 0 &&
            ppgid.substr(12) == std::string("\x00\x00\x01\xc1", 4))
          mine = true;
      }
      if (!mine) continue;
      writer_listed = true;
      const std::string ns = node.node_namespace().c_str(), name = node.node_name().c_str();
      node_named = ns == "/" && name == "mbot_nav";
      std::printf(
          "peer: ros_discovery_info names node '%s' in namespace '%s' (%zu readers, %zu writers), /cmd_vel's "
          "writer among them\n",
          name.c_str(), ns.c_str(), node.reader_gid_seq().size(), node.writer_gid_seq().size());
    }
  }
  std::printf("peer: %d ros_discovery_info samples\n", announcements);
  pp->delete_contained_entities();
  DomainParticipantFactory::get_instance()->delete_participant(pp);
  const bool ok =
      moving > 0 && got_map && wall_seen && gap_open && writer_listed && node_named && resets > 0 && reset_replies > 0;
  std::printf("%s\n", ok ? "PASS"
                         : "FAIL: no non-zero /cmd_vel, or no /map for the late reader, or a wrong map, or no node "
                           "/mbot_nav on ros_discovery_info listing /cmd_vel's writer, or no /reset_odometry call");
  return ok ? 0 : 1;
}
