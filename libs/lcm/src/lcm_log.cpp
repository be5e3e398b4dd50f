#include "mbot/lcm/lcm_log.hpp"

#include <cstring>
#include <stdexcept>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/log.hpp"

namespace mbot::lcmio {
namespace {

uint32_t ReadU32(const uint8_t* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}
int64_t ReadI64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return static_cast<int64_t>(v);
}
void PutU32(std::vector<uint8_t>& o, uint32_t v) {
  for (int i = 3; i >= 0; --i) o.push_back(uint8_t(v >> (8 * i)));
}
void PutI64(std::vector<uint8_t>& o, int64_t v) {
  for (int i = 7; i >= 0; --i) o.push_back(uint8_t(uint64_t(v) >> (8 * i)));
}

constexpr int kHeaderSize = 28;

}  // namespace

LcmLogReader::LcmLogReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
  if (!in_) throw std::runtime_error(path + ": cannot open LCM log");
  in_.seekg(0, std::ios::end);
  size_ = in_.tellg();
  in_.seekg(0);
}

bool LcmLogReader::Resync(int64_t from) {
  // Scan forward for the next sync word, in chunks.
  ++resyncs_;
  std::vector<uint8_t> buf(1 << 16);
  int64_t pos = from + 1;  // `from` is the bad record's first byte; the next sync word lies after it
  while (pos + 4 <= size_) {
    in_.clear();
    in_.seekg(pos);
    const int64_t want = std::min<int64_t>(buf.size(), size_ - pos);
    in_.read(reinterpret_cast<char*>(buf.data()), want);
    const int64_t got = in_.gcount();
    for (int64_t i = 0; i + 4 <= got; ++i) {
      if (ReadU32(&buf[i]) == kSyncWord) {
        skipped_bytes_ += pos + i - from;
        mbot::log::Warn(path_ + ": resynchronised at byte " + std::to_string(pos + i) + " after skipping " +
                        std::to_string(pos + i - from) + " bytes");
        pos_ = pos + i;
        return true;
      }
    }
    if (got < 4) break;
    pos += got - 3;
  }
  skipped_bytes_ += size_ - from;
  mbot::log::Warn(path_ + ": no sync word after byte " + std::to_string(from) + "; " + std::to_string(size_ - from) +
                  " trailing bytes ignored");
  pos_ = size_;
  return false;
}

std::optional<LcmLogRecord> LcmLogReader::Next() {
  while (pos_ < size_) {
    if (size_ - pos_ < kHeaderSize) {
      truncated_ = true;
      mbot::log::Warn(path_ + ": truncated record header at byte " + std::to_string(pos_) + " (" +
                      std::to_string(size_ - pos_) + " bytes left); stopping there");
      pos_ = size_;
      return std::nullopt;
    }
    uint8_t h[kHeaderSize];
    in_.clear();
    in_.seekg(pos_);
    in_.read(reinterpret_cast<char*>(h), kHeaderSize);
    const uint32_t sync = ReadU32(h);
    const int64_t event = ReadI64(h + 4);
    const int64_t stamp = ReadI64(h + 12);
    const int32_t chan_len = static_cast<int32_t>(ReadU32(h + 20));
    const int32_t data_len = static_cast<int32_t>(ReadU32(h + 24));
    if (sync != kSyncWord || chan_len <= 0 || chan_len > kMaxChannelLength || data_len < 0 ||
        data_len > kMaxDataLength) {
      mbot::log::Warn(path_ + ": bad record header at byte " + std::to_string(pos_) +
                      (sync != kSyncWord ? " (no sync word)" : " (implausible lengths)"));
      if (!Resync(pos_)) return std::nullopt;
      continue;
    }
    const int64_t end = pos_ + kHeaderSize + chan_len + int64_t(data_len);
    if (end > size_) {
      truncated_ = true;
      mbot::log::Warn(path_ + ": record at byte " + std::to_string(pos_) + " (event " + std::to_string(event) +
                      ") is cut short by the end of the file; stopping there");
      pos_ = size_;
      return std::nullopt;
    }
    LcmLogRecord rec;
    rec.event_number = event;
    rec.timestamp_us = stamp;
    rec.file_offset = pos_;
    rec.channel.resize(chan_len);
    in_.read(rec.channel.data(), chan_len);
    rec.data.resize(data_len);
    if (data_len) in_.read(reinterpret_cast<char*>(rec.data.data()), data_len);
    // A channel name with control bytes means we are not at a real record.
    bool printable = true;
    for (char c : rec.channel) printable &= (c >= 0x20 && c < 0x7f);
    if (!printable) {
      mbot::log::Warn(path_ + ": record at byte " + std::to_string(pos_) + " has an unprintable channel name");
      if (!Resync(pos_)) return std::nullopt;
      continue;
    }
    pos_ = end;
    return rec;
  }
  return std::nullopt;
}

void AppendLcmRecord(std::vector<uint8_t>& out, int64_t event_number, int64_t timestamp_us, const std::string& channel,
                     const std::vector<uint8_t>& data) {
  PutU32(out, LcmLogReader::kSyncWord);
  PutI64(out, event_number);
  PutI64(out, timestamp_us);
  PutU32(out, static_cast<uint32_t>(channel.size()));
  PutU32(out, static_cast<uint32_t>(data.size()));
  out.insert(out.end(), channel.begin(), channel.end());
  out.insert(out.end(), data.begin(), data.end());
}

LcmLogWriter::LcmLogWriter(const std::string& path) : path_(path), tmp_(TempPathFor(path)) {
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw std::runtime_error(path + ": cannot create LCM log");
}

LcmLogWriter::~LcmLogWriter() {
  try {
    Close();
  } catch (const std::exception& e) {
    mbot::log::Error(e.what());
  }
}

void LcmLogWriter::Write(int64_t timestamp_us, const std::string& channel, const void* data, size_t size) {
  std::vector<uint8_t> rec;
  const auto* p = static_cast<const uint8_t*>(data);
  AppendLcmRecord(rec, next_event_++, timestamp_us, channel, std::vector<uint8_t>(p, p + size));
  out_.write(reinterpret_cast<const char*>(rec.data()), rec.size());
}

void LcmLogWriter::Close() {
  if (!out_.is_open()) return;
  out_.close();
  if (!out_) throw std::runtime_error(path_ + ": write failed");
  CommitFile(tmp_, path_);
}

}  // namespace mbot::lcmio
