// The LCM log file format (what lcm-logger writes): records of sync word 0xEDA1DA01, int64 event
// number, int64 timestamp [µs], int32 channel length, int32 data length, channel, data; big-endian.
#pragma once

#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace mbot::lcmio {

struct LcmLogRecord {
  int64_t event_number = 0;
  int64_t timestamp_us = 0;
  std::string channel;
  std::vector<uint8_t> data;
  int64_t file_offset = 0;  // byte offset of the record's sync word
};

// Reads records one by one. A record whose header is implausible (wrong sync word, absurd lengths)
// makes the reader search for the next sync word, with a warning that gives the byte offset; a
// record cut short by the end of the file ends the stream with a warning. Never reads out of bounds.
class LcmLogReader {
 public:
  explicit LcmLogReader(const std::string& path);  // throws std::runtime_error naming the path
  std::optional<LcmLogRecord> Next();
  int64_t size() const { return size_; }
  int64_t position() const { return pos_; }
  int64_t resyncs() const { return resyncs_; }
  int64_t skipped_bytes() const { return skipped_bytes_; }
  bool truncated() const { return truncated_; }

  static constexpr uint32_t kSyncWord = 0xEDA1DA01;
  static constexpr int32_t kMaxChannelLength = 256;
  static constexpr int32_t kMaxDataLength = 256 << 20;

 private:
  bool Resync(int64_t from);

  std::string path_;
  std::ifstream in_;
  int64_t size_ = 0;
  int64_t pos_ = 0;
  int64_t resyncs_ = 0;
  int64_t skipped_bytes_ = 0;
  bool truncated_ = false;
};

// Writes records in the same format (the recorder, and test fixtures). Written to a temporary file
// and renamed on Close(), so an interrupted run never leaves half a log.
class LcmLogWriter {
 public:
  explicit LcmLogWriter(const std::string& path);
  ~LcmLogWriter();
  void Write(int64_t timestamp_us, const std::string& channel, const void* data, size_t size);
  void Close();

 private:
  std::string path_;
  std::string tmp_;
  std::ofstream out_;
  int64_t next_event_ = 0;
};

// Appends the big-endian encoding of an LCM record to `out` (exposed so tests can build corrupt
// logs byte by byte).
void AppendLcmRecord(std::vector<uint8_t>& out, int64_t event_number, int64_t timestamp_us, const std::string& channel,
                     const std::vector<uint8_t>& data);

}  // namespace mbot::lcmio
