// A writer of MCAP files (https://mcap.dev/spec): chunked (zstd, or none), a message index per
// chunk, the summary (schemas, channels, statistics, chunk and metadata indexes, summary offsets)
// and every CRC the format has (each chunk's records, the data section, the summary). The file is
// written under a temporary name and renamed when it is closed, so a reader never sees half a file.
#pragma once

#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace mbot::ros2 {

struct McapWriterOptions {
  std::string profile = "ros2";
  std::string library = "mbot_nav";
  std::string compression = "zstd";  // "zstd" or "" (none)
  size_t chunk_size = 1 << 20;       // a chunk is closed once its records pass this many bytes
};

class McapWriter {
 public:
  // Opens `path`.tmp for writing; throws std::runtime_error naming the path when it cannot.
  McapWriter(std::string path, McapWriterOptions options = {});
  ~McapWriter();  // an unclosed writer removes its temporary file
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  uint16_t AddSchema(const std::string& name, const std::string& encoding, const std::string& data);
  uint16_t AddChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                      const std::map<std::string, std::string>& metadata);
  void Write(uint16_t channel_id, uint64_t log_time_ns, uint64_t publish_time_ns, const std::vector<uint8_t>& data);
  // A Metadata record (rosbag2 writes one named "rosbag2"), in the data section and indexed.
  void AddMetadata(const std::string& name, const std::map<std::string, std::string>& entries);
  // Finishes the file (last chunk, DataEnd, summary, footer) and renames it to its name.
  void Close();

  uint64_t messages() const { return message_count_; }
  uint64_t start_time_ns() const { return message_count_ ? start_ : 0; }
  uint64_t end_time_ns() const { return end_; }
  const std::map<uint16_t, uint64_t>& channel_counts() const { return channel_counts_; }

 private:
  void Put(const std::vector<uint8_t>& bytes);  // to the file, into the data-section CRC
  void FlushChunk();

  std::string path_, tmp_;
  McapWriterOptions options_;
  std::ofstream out_;
  uint64_t offset_ = 0;
  uint32_t data_crc_ = 0;
  bool closed_ = false;
  std::vector<std::vector<uint8_t>> schemas_, channels_;  // their records, for the summary
  std::vector<std::vector<uint8_t>> chunk_indexes_, metadata_indexes_;
  std::vector<uint8_t> chunk_;  // the open chunk's records
  uint64_t chunk_start_ = UINT64_MAX, chunk_end_ = 0;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_index_;  // channel → (time, offset)
  std::map<uint16_t, uint64_t> channel_counts_;
  uint64_t message_count_ = 0, start_ = UINT64_MAX, end_ = 0;
  uint32_t chunk_count_ = 0, metadata_count_ = 0;
  std::map<uint16_t, uint32_t> sequence_;
};

}  // namespace mbot::ros2
