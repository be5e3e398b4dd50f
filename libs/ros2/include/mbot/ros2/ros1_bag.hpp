// A reader of ROS 1 bags (format 2.0, http://wiki.ros.org/Bags/Format/2.0), the way most public 2D
// SLAM data ships: a linear scan of the records in file order (so a bag without its index, or cut
// short, still reads), chunks uncompressed, bz2 (libbz2) or lz4 (LZ4 frames, liblz4). Messages come
// out in time order, as `rosbag play` and rosbags give them: a chunk's messages need not be sorted
// (a recorder writes them as they arrive, per topic), so each chunk is sorted and merged with the
// next, the way rosbag writes them (a chunk starts no earlier than the one before). Every length
// is checked against what the file holds before anything is allocated; a bad file is a
// Ros1BagError naming the file, the record and its offset, never a crash.
#pragma once

#include <cstdint>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbot/ros2/mcap_reader.hpp"

namespace mbot::ros2 {

class Ros1BagError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Ros1Connection {
  uint32_t id = 0;
  std::string topic, type;  // "sensor_msgs/LaserScan"
  std::string md5sum, definition;
};

class Ros1BagReader {
 public:
  // Opens the file and checks its "#ROSBAG V2.0" line.
  explicit Ros1BagReader(const std::string& path);

  // The next message in time order (ties in file order; channel_id: the connection id; sequence:
  // 0), false at the end. Connections met on the way are kept. Throws Ros1BagError on what is not
  // a bag, once every message before the bad record has been given out.
  bool Next(McapMessage* message);

  const std::map<uint32_t, Ros1Connection>& connections() const { return connections_; }
  uint64_t position() const { return pos_; }
  uint64_t size() const { return size_; }
  long long chunks() const { return chunks_; }
  long long messages() const { return messages_; }
  bool truncated() const { return truncated_; }

 private:
  // The next message in file order and the chunk it came from (a message outside any chunk is a
  // group of its own).
  bool NextInFileOrder(McapMessage* message, long long* group);
  // Reads the next chunk's messages into the heap; false at the end of the file.
  bool LoadGroup();
  [[noreturn]] void Fail(const std::string& what, uint64_t offset) const;
  // One record (its header fields and data) from the file or a chunk: true when it was a message.
  bool Handle(const std::map<std::string, std::string>& header, const uint8_t* data, uint64_t size, uint64_t offset,
              McapMessage* message);
  void ReadChunk(const std::map<std::string, std::string>& header, const uint8_t* data, uint64_t size, uint64_t offset);

  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0, pos_ = 0;
  bool done_ = false, truncated_ = false;
  std::map<uint32_t, Ros1Connection> connections_;
  std::vector<uint8_t> chunk_;
  uint64_t chunk_pos_ = 0, chunk_offset_ = 0;
  bool in_chunk_ = false;
  long long chunks_ = 0, messages_ = 0, bare_ = 0;
  // Time order: messages read but not yet given out, a min-heap on (time, file order).
  struct Pending {
    uint64_t order = 0;
    McapMessage message;
  };
  std::vector<Pending> heap_;
  uint64_t read_order_ = 0, pending_bytes_ = 0;
  uint64_t group_min_ns_ = 0;  // the earliest message of the last chunk read: what is earlier goes out
  bool carry_valid_ = false, file_done_ = false;
  McapMessage carry_;  // the first message of the next chunk, read while looking for the end of one
  long long carry_group_ = 0;
  std::string error_;  // a bad record met while reading ahead: thrown once what preceded it is out
};

// A record's header: "name=value" fields, each after its uint32 length. Throws std::runtime_error
// naming what does not fit.
std::map<std::string, std::string> ParseRos1Header(const uint8_t* data, uint64_t size);

}  // namespace mbot::ros2
