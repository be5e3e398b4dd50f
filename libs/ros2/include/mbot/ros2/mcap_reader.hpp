// A reader of MCAP files (https://mcap.dev/spec), the format of rosbag2 since Iron and of Foxglove:
// a linear scan in file order, record by record, so it reads a file without its summary and one
// cut short. Chunks may be uncompressed, zstd or lz4 (LZ4 frames; Debian's libzstd and liblz4);
// the CRCs present are checked (a chunk's records; the data section's at DataEnd). Every length is
// checked against what the file holds before anything is allocated: a bad file is an McapError
// naming the file, the record and its offset, never a crash.
#pragma once

#include <cstdint>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace mbot::ros2 {

class McapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct McapSchema {
  uint16_t id = 0;
  std::string name, encoding;  // "sensor_msgs/msg/LaserScan", "ros2msg"
  std::string data;            // the definition's text
};

struct McapChannel {
  uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;  // "/scan", "cdr"
  std::map<std::string, std::string> metadata;
};

struct McapMessage {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time_ns = 0, publish_time_ns = 0;
  std::vector<uint8_t> data;
  uint64_t offset = 0;  // of its record: in the file, or of the chunk that holds it
};

struct McapStats {
  long long records = 0, chunks = 0, messages = 0;
  long long crcs_checked = 0;  // chunk and data-section CRCs that were present and matched
  bool footer = false;         // the file ended as MCAP files end (DataEnd, Footer, magic)
  bool truncated = false;      // it did not: cut short (what was before the cut was read)
};

class McapReader {
 public:
  // Opens the file and checks its magic and Header (the profile: "ros2" for rosbag2).
  explicit McapReader(const std::string& path);

  // The next message in file order, false at the end. Schemas and channels met on the way are
  // kept (channels() and schemas()). Throws McapError on what is not MCAP.
  bool Next(McapMessage* message);

  const std::string& profile() const { return profile_; }
  const std::map<uint16_t, McapSchema>& schemas() const { return schemas_; }
  const std::map<uint16_t, McapChannel>& channels() const { return channels_; }
  const McapStats& stats() const { return stats_; }
  // Bytes of the file read so far, and its size (for a progress fraction).
  uint64_t position() const { return pos_; }
  uint64_t size() const { return size_; }

 private:
  [[noreturn]] void Fail(const std::string& what, uint64_t offset) const;
  // One record from `data` (a file record's content or a chunk's): true when it was a message.
  bool Handle(uint8_t op, const uint8_t* data, uint64_t size, uint64_t offset, bool in_chunk, McapMessage* message);
  void ReadChunk(const uint8_t* data, uint64_t size, uint64_t offset);
  std::vector<uint8_t> ReadFile(uint64_t n);

  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0, pos_ = 0;
  uint32_t data_crc_ = 0;  // running CRC of the data section, for DataEnd
  bool done_ = false;
  std::string profile_;
  std::map<uint16_t, McapSchema> schemas_;
  std::map<uint16_t, McapChannel> channels_;
  McapStats stats_;
  std::vector<uint8_t> chunk_;  // the current chunk's records, decompressed
  uint64_t chunk_pos_ = 0, chunk_offset_ = 0;
  bool in_chunk_ = false;
};

}  // namespace mbot::ros2
