#include "mbot/ros2/mcap_writer.hpp"

#include <zlib.h>
#include <zstd.h>

#include <cstdio>
#include <stdexcept>

namespace mbot::ros2 {

namespace {

enum Op : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// Little-endian fields, as the spec has them.
struct Bytes {
  std::vector<uint8_t> b;
  template <typename T>
  void Int(T v) {
    for (size_t i = 0; i < sizeof(T); ++i) b.push_back(static_cast<uint8_t>(uint64_t(v) >> (8 * i)));
  }
  void Raw(const void* p, size_t n) {
    const auto* c = static_cast<const uint8_t*>(p);
    b.insert(b.end(), c, c + n);
  }
  void Str(const std::string& s) {
    Int<uint32_t>(static_cast<uint32_t>(s.size()));
    Raw(s.data(), s.size());
  }
  void Map(const std::map<std::string, std::string>& m) {
    Bytes body;
    for (const auto& [k, v] : m) body.Str(k), body.Str(v);
    Int<uint32_t>(static_cast<uint32_t>(body.b.size()));
    Raw(body.b.data(), body.b.size());
  }
};

std::vector<uint8_t> Record(uint8_t op, const std::vector<uint8_t>& content) {
  Bytes r;
  r.Int<uint8_t>(op);
  r.Int<uint64_t>(content.size());
  r.Raw(content.data(), content.size());
  return r.b;
}

uint32_t Crc(uint32_t crc, const std::vector<uint8_t>& b) {
  return static_cast<uint32_t>(crc32(crc, b.data(), static_cast<uInt>(b.size())));
}

const char kMagic[] = "\x89MCAP0\r\n";

}  // namespace

McapWriter::McapWriter(std::string path, McapWriterOptions options)
    : path_(std::move(path)), tmp_(path_ + ".tmp"), options_(std::move(options)) {
  if (options_.compression != "zstd" && !options_.compression.empty()) {
    throw std::runtime_error(path_ + ": MCAP compression '" + options_.compression + "' is not zstd or none");
  }
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw std::runtime_error(tmp_ + ": cannot be written");
  Put(std::vector<uint8_t>(kMagic, kMagic + 8));
  Bytes h;
  h.Str(options_.profile);
  h.Str(options_.library);
  Put(Record(kHeader, h.b));
}

McapWriter::~McapWriter() {
  if (!closed_) {
    out_.close();
    std::remove(tmp_.c_str());
  }
}

void McapWriter::Put(const std::vector<uint8_t>& bytes) {
  out_.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  data_crc_ = Crc(data_crc_, bytes);
  offset_ += bytes.size();
}

uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  const uint16_t id = static_cast<uint16_t>(schemas_.size() + 1);
  Bytes s;
  s.Int<uint16_t>(id);
  s.Str(name);
  s.Str(encoding);
  s.Str(data);
  schemas_.push_back(Record(kSchema, s.b));
  // In the chunk, before the channels that use it, as readers of the data section expect.
  chunk_.insert(chunk_.end(), schemas_.back().begin(), schemas_.back().end());
  return id;
}

uint16_t McapWriter::AddChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                                const std::map<std::string, std::string>& metadata) {
  const uint16_t id = static_cast<uint16_t>(channels_.size() + 1);
  Bytes c;
  c.Int<uint16_t>(id);
  c.Int<uint16_t>(schema_id);
  c.Str(topic);
  c.Str(message_encoding);
  c.Map(metadata);
  channels_.push_back(Record(kChannel, c.b));
  chunk_.insert(chunk_.end(), channels_.back().begin(), channels_.back().end());
  channel_counts_[id] = 0;
  return id;
}

void McapWriter::Write(uint16_t channel_id, uint64_t log_time_ns, uint64_t publish_time_ns,
                       const std::vector<uint8_t>& data) {
  Bytes m;
  m.Int<uint16_t>(channel_id);
  m.Int<uint32_t>(sequence_[channel_id]++);
  m.Int<uint64_t>(log_time_ns);
  m.Int<uint64_t>(publish_time_ns);
  m.Raw(data.data(), data.size());
  chunk_index_[channel_id].push_back({log_time_ns, chunk_.size()});
  const std::vector<uint8_t> r = Record(kMessage, m.b);
  chunk_.insert(chunk_.end(), r.begin(), r.end());
  chunk_start_ = std::min(chunk_start_, log_time_ns);
  chunk_end_ = std::max(chunk_end_, log_time_ns);
  start_ = std::min(start_, log_time_ns);
  end_ = std::max(end_, log_time_ns);
  ++message_count_;
  ++channel_counts_[channel_id];
  if (chunk_.size() >= options_.chunk_size) FlushChunk();
}

void McapWriter::FlushChunk() {
  if (chunk_.empty()) return;
  std::vector<uint8_t> stored = chunk_;
  if (options_.compression == "zstd") {
    stored.resize(ZSTD_compressBound(chunk_.size()));
    const size_t n = ZSTD_compress(stored.data(), stored.size(), chunk_.data(), chunk_.size(), 3);
    if (ZSTD_isError(n)) throw std::runtime_error(path_ + ": zstd: " + ZSTD_getErrorName(n));
    stored.resize(n);
  }
  const uint64_t start = chunk_index_.empty() ? 0 : chunk_start_, end = chunk_index_.empty() ? 0 : chunk_end_;
  Bytes c;
  c.Int<uint64_t>(start);
  c.Int<uint64_t>(end);
  c.Int<uint64_t>(chunk_.size());
  c.Int<uint32_t>(Crc(0, chunk_));
  c.Str(options_.compression);
  c.Int<uint64_t>(stored.size());
  c.Raw(stored.data(), stored.size());
  const uint64_t chunk_offset = offset_;
  Put(Record(kChunk, c.b));
  const uint64_t chunk_length = offset_ - chunk_offset;
  // One message index per channel in the chunk, after it.
  Bytes offsets;
  const uint64_t indexes_start = offset_;
  for (const auto& [channel, entries] : chunk_index_) {
    offsets.Int<uint16_t>(channel);
    offsets.Int<uint64_t>(offset_);
    Bytes mi;
    mi.Int<uint16_t>(channel);
    mi.Int<uint32_t>(static_cast<uint32_t>(entries.size() * 16));
    for (const auto& [t, off] : entries) mi.Int<uint64_t>(t), mi.Int<uint64_t>(off);
    Put(Record(kMessageIndex, mi.b));
  }
  Bytes ci;
  ci.Int<uint64_t>(start);
  ci.Int<uint64_t>(end);
  ci.Int<uint64_t>(chunk_offset);
  ci.Int<uint64_t>(chunk_length);
  ci.Int<uint32_t>(static_cast<uint32_t>(offsets.b.size()));
  ci.Raw(offsets.b.data(), offsets.b.size());
  ci.Int<uint64_t>(offset_ - indexes_start);
  ci.Str(options_.compression);
  ci.Int<uint64_t>(stored.size());
  ci.Int<uint64_t>(chunk_.size());
  chunk_indexes_.push_back(Record(kChunkIndex, ci.b));
  ++chunk_count_;
  chunk_.clear();
  chunk_index_.clear();
  chunk_start_ = UINT64_MAX, chunk_end_ = 0;
}

void McapWriter::AddMetadata(const std::string& name, const std::map<std::string, std::string>& entries) {
  FlushChunk();  // metadata records live outside chunks
  Bytes m;
  m.Str(name);
  m.Map(entries);
  const uint64_t at = offset_;
  Put(Record(kMetadata, m.b));
  Bytes mi;
  mi.Int<uint64_t>(at);
  mi.Int<uint64_t>(offset_ - at);
  mi.Str(name);
  metadata_indexes_.push_back(Record(kMetadataIndex, mi.b));
  ++metadata_count_;
}

void McapWriter::Close() {
  if (closed_) return;
  FlushChunk();
  Bytes de;
  de.Int<uint32_t>(data_crc_);
  Put(Record(kDataEnd, de.b));
  // The summary: groups of records, each found through a SummaryOffset.
  const uint64_t summary_start = offset_;
  uint32_t summary_crc = 0;
  auto put_summary = [&](const std::vector<uint8_t>& r) {
    Put(r);
    summary_crc = Crc(summary_crc, r);
  };
  std::vector<std::vector<uint8_t>> offsets;
  auto group = [&](uint8_t op, const std::vector<std::vector<uint8_t>>& records) {
    if (records.empty()) return;
    const uint64_t start = offset_;
    for (const auto& r : records) put_summary(r);
    Bytes so;
    so.Int<uint8_t>(op);
    so.Int<uint64_t>(start);
    so.Int<uint64_t>(offset_ - start);
    offsets.push_back(Record(kSummaryOffset, so.b));
  };
  group(kSchema, schemas_);
  group(kChannel, channels_);
  Bytes st;
  st.Int<uint64_t>(message_count_);
  st.Int<uint16_t>(static_cast<uint16_t>(schemas_.size()));
  st.Int<uint32_t>(static_cast<uint32_t>(channels_.size()));
  st.Int<uint32_t>(0);  // attachments
  st.Int<uint32_t>(metadata_count_);
  st.Int<uint32_t>(chunk_count_);
  st.Int<uint64_t>(start_time_ns());
  st.Int<uint64_t>(end_);
  Bytes counts;
  for (const auto& [channel, n] : channel_counts_) counts.Int<uint16_t>(channel), counts.Int<uint64_t>(n);
  st.Int<uint32_t>(static_cast<uint32_t>(counts.b.size()));
  st.Raw(counts.b.data(), counts.b.size());
  group(kStatistics, {Record(kStatistics, st.b)});
  group(kChunkIndex, chunk_indexes_);
  group(kMetadataIndex, metadata_indexes_);
  const uint64_t summary_offset_start = offset_;
  for (const auto& r : offsets) put_summary(r);
  // The footer; its CRC covers the summary through the footer's summary_offset_start field.
  Bytes f;
  f.Int<uint8_t>(kFooter);
  f.Int<uint64_t>(8 + 8 + 4);
  f.Int<uint64_t>(summary_start);
  f.Int<uint64_t>(summary_offset_start);
  summary_crc = Crc(summary_crc, f.b);
  f.Int<uint32_t>(summary_crc);
  Put(f.b);
  Put(std::vector<uint8_t>(kMagic, kMagic + 8));
  out_.close();
  if (!out_) throw std::runtime_error(tmp_ + ": writing failed (disk full?)");
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) throw std::runtime_error(path_ + ": cannot be renamed into place");
  closed_ = true;
}

}  // namespace mbot::ros2
