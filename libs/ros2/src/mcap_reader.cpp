#include "mbot/ros2/mcap_reader.hpp"

#include <zlib.h>
#include <zstd.h>

#include <cstring>

#include "lz4_frame.hpp"

namespace mbot::ros2 {

namespace {

constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 30;  // a chunk decompresses to at most 1 GiB

const char* RecordName(uint8_t op) {
  switch (op) {
    case 0x01: return "Header";
    case 0x02: return "Footer";
    case 0x03: return "Schema";
    case 0x04: return "Channel";
    case 0x05: return "Message";
    case 0x06: return "Chunk";
    case 0x0F: return "DataEnd";
    default: return "record";
  }
}

uint32_t Crc(uint32_t crc, const uint8_t* p, uint64_t n) {
  while (n > 0) {  // zlib takes a uInt at a time
    const uInt step = static_cast<uInt>(std::min<uint64_t>(n, 1u << 30));
    crc = static_cast<uint32_t>(crc32(crc, p, step));
    p += step, n -= step;
  }
  return crc;
}

// A field that does not fit its record (the reader adds the file and offset).
struct FieldError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Fields of one record's content, each checked against its end.
class Fields {
 public:
  Fields(const uint8_t* data, uint64_t size, const char* record) : d_(data), n_(size), record_(record) {}
  template <typename T>
  T Int(const char* field) {
    T v;
    std::memcpy(&v, Take(sizeof v, field), sizeof v);
    return v;
  }
  std::string Str(const char* field) {
    const uint32_t len = Int<uint32_t>(field);
    const uint8_t* p = Take(len, field);
    return std::string(reinterpret_cast<const char*>(p), len);
  }
  const uint8_t* Take(uint64_t len, const char* field) {
    if (len > n_ - pos_) {
      throw FieldError(std::string(record_) + "." + field + " needs " + std::to_string(len) + " bytes, " +
                       std::to_string(n_ - pos_) + " left in the record");
    }
    const uint8_t* p = d_ + pos_;
    pos_ += len;
    return p;
  }
  uint64_t left() const { return n_ - pos_; }

 private:
  const uint8_t* d_;
  uint64_t n_, pos_ = 0;
  const char* record_;
};

}  // namespace

McapReader::McapReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
  if (!in_) throw McapError(path + ": cannot open");
  in_.seekg(0, std::ios::end);
  size_ = static_cast<uint64_t>(in_.tellg());
  in_.seekg(0);
  if (size_ < 8) Fail("shorter than MCAP's magic", 0);
  const std::vector<uint8_t> magic = ReadFile(8);
  if (std::memcmp(magic.data(), kMagic, 8) != 0) Fail("not an MCAP file (no magic)", 0);
  data_crc_ = Crc(0, magic.data(), 8);
  if (size_ - pos_ < 9) Fail("no Header record after the magic", 8);
  const std::vector<uint8_t> head = ReadFile(9);
  uint64_t len;
  std::memcpy(&len, &head[1], 8);
  if (head[0] != 0x01) Fail("the first record is a " + std::string(RecordName(head[0])) + ", not the Header", 8);
  if (len > size_ - pos_) Fail("the Header runs past the end of the file", 8);
  const std::vector<uint8_t> content = ReadFile(len);
  data_crc_ = Crc(Crc(data_crc_, head.data(), 9), content.data(), len);
  ++stats_.records;
  try {
    Fields f(content.data(), len, "Header");
    profile_ = f.Str("profile");
  } catch (const FieldError& e) {
    Fail(e.what(), 8);
  }
}

void McapReader::Fail(const std::string& what, uint64_t offset) const {
  throw McapError(path_ + ": " + what + " (at byte " + std::to_string(offset) + ")");
}

std::vector<uint8_t> McapReader::ReadFile(uint64_t n) {
  std::vector<uint8_t> b(n);
  if (n && !in_.read(reinterpret_cast<char*>(b.data()), static_cast<std::streamsize>(n))) Fail("read failed", pos_);
  pos_ += n;
  return b;
}

bool McapReader::Next(McapMessage* message) {
  while (true) {
    if (in_chunk_) {
      while (chunk_pos_ < chunk_.size()) {
        if (chunk_.size() - chunk_pos_ < 9)
          Fail("a chunk's records end inside a record's opcode and length", chunk_offset_);
        const uint8_t op = chunk_[chunk_pos_];
        uint64_t len;
        std::memcpy(&len, &chunk_[chunk_pos_ + 1], 8);
        if (len > chunk_.size() - chunk_pos_ - 9) {
          Fail(std::string("a ") + RecordName(op) + " in a chunk runs past the chunk's records", chunk_offset_);
        }
        const uint8_t* content = &chunk_[chunk_pos_ + 9];
        chunk_pos_ += 9 + len;
        try {
          if (Handle(op, content, len, chunk_offset_, true, message)) return true;
        } catch (const FieldError& e) {
          Fail(std::string(e.what()) + ", in a chunk", chunk_offset_);
        }
      }
      in_chunk_ = false;
    }
    if (done_) return false;
    if (size_ - pos_ < 9) {  // the end of the file, or a record cut short: what was read stands
      stats_.truncated = pos_ < size_ || !stats_.footer;
      done_ = true;
      return false;
    }
    const uint64_t offset = pos_;
    const std::vector<uint8_t> head = ReadFile(9);
    const uint8_t op = head[0];
    uint64_t len;
    std::memcpy(&len, &head[1], 8);
    if (len > size_ - pos_) {
      stats_.truncated = true;
      done_ = true;
      return false;
    }
    const uint32_t crc_before = data_crc_;
    const std::vector<uint8_t> content = ReadFile(len);
    data_crc_ = Crc(Crc(data_crc_, head.data(), 9), content.data(), len);
    ++stats_.records;
    try {
      if (op == 0x0F) {  // DataEnd: the CRC of everything before it
        Fields f(content.data(), len, "DataEnd");
        const uint32_t crc = f.Int<uint32_t>("data_section_crc");
        if (crc != 0 && crc != crc_before) Fail("the data section's CRC does not match", offset);
        if (crc != 0) ++stats_.crcs_checked;
        continue;
      }
      if (Handle(op, content.data(), len, offset, false, message)) return true;
    } catch (const FieldError& e) {
      Fail(e.what(), offset);
    }
  }
}

bool McapReader::Handle(uint8_t op, const uint8_t* data, uint64_t size, uint64_t offset, bool in_chunk,
                        McapMessage* message) {
  switch (op) {
    case 0x01: {
      Fields f(data, size, "Header");
      profile_ = f.Str("profile");
      return false;
    }
    case 0x02:  // Footer, then the closing magic
      stats_.footer = true;
      done_ = true;
      if (size_ - pos_ >= 8) {
        const std::vector<uint8_t> magic = ReadFile(8);
        if (std::memcmp(magic.data(), kMagic, 8) != 0) Fail("the Footer is not followed by MCAP's magic", pos_ - 8);
      }
      return false;
    case 0x03: {
      Fields f(data, size, "Schema");
      McapSchema s;
      s.id = f.Int<uint16_t>("id");
      if (s.id == 0) Fail("a Schema with id 0", offset);
      s.name = f.Str("name");
      s.encoding = f.Str("encoding");
      const uint32_t n = f.Int<uint32_t>("data");
      const uint8_t* p = f.Take(n, "data");
      s.data.assign(reinterpret_cast<const char*>(p), n);
      schemas_[s.id] = std::move(s);
      return false;
    }
    case 0x04: {
      Fields f(data, size, "Channel");
      McapChannel c;
      c.id = f.Int<uint16_t>("id");
      c.schema_id = f.Int<uint16_t>("schema_id");
      c.topic = f.Str("topic");
      c.message_encoding = f.Str("message_encoding");
      const uint32_t bytes = f.Int<uint32_t>("metadata");
      Fields m(f.Take(bytes, "metadata"), bytes, "Channel.metadata");
      while (m.left() > 0) {
        std::string k = m.Str("key");
        c.metadata[std::move(k)] = m.Str("value");
      }
      channels_[c.id] = std::move(c);
      return false;
    }
    case 0x05: {
      Fields f(data, size, "Message");
      message->channel_id = f.Int<uint16_t>("channel_id");
      message->sequence = f.Int<uint32_t>("sequence");
      message->log_time_ns = f.Int<uint64_t>("log_time");
      message->publish_time_ns = f.Int<uint64_t>("publish_time");
      if (!channels_.count(message->channel_id)) {
        Fail("a Message on channel " + std::to_string(message->channel_id) + ", which no Channel record named", offset);
      }
      const uint64_t n = f.left();
      const uint8_t* p = f.Take(n, "data");
      message->data.assign(p, p + n);
      message->offset = offset;
      ++stats_.messages;
      return true;
    }
    case 0x06:
      if (in_chunk) Fail("a Chunk inside a chunk", offset);
      ReadChunk(data, size, offset);
      return false;
    default: return false;  // indexes, statistics, attachments, metadata: not needed for a linear read
  }
}

void McapReader::ReadChunk(const uint8_t* data, uint64_t size, uint64_t offset) {
  Fields f(data, size, "Chunk");
  f.Int<uint64_t>("message_start_time");
  f.Int<uint64_t>("message_end_time");
  const uint64_t usize = f.Int<uint64_t>("uncompressed_size");
  const uint32_t ucrc = f.Int<uint32_t>("uncompressed_crc");
  const std::string compression = f.Str("compression");
  const uint64_t csize = f.Int<uint64_t>("records");
  const uint8_t* src = f.Take(csize, "records");
  if (usize > kMaxChunkBytes) Fail("a chunk of " + std::to_string(usize) + " bytes (at most 1 GiB)", offset);
  if (compression == "zstd") {
    // The frame says how much it holds: a chunk that claims more is refused before any allocation.
    const unsigned long long frame = ZSTD_getFrameContentSize(src, csize);
    if (frame == ZSTD_CONTENTSIZE_ERROR) Fail("a zstd chunk whose frame header is not zstd's", offset);
    if (frame != ZSTD_CONTENTSIZE_UNKNOWN && frame != usize)
      Fail("a zstd chunk whose frame holds " + std::to_string(frame) + " bytes, not its " + std::to_string(usize),
           offset);
  }
  // every byte is written below (or the chunk refused): no need to clear it; lz4 grows its own
  if (compression != "lz4") chunk_.resize(usize);
  if (compression.empty()) {
    if (csize != usize) Fail("an uncompressed chunk whose sizes differ", offset);
    if (usize) std::memcpy(chunk_.data(), src, usize);
  } else if (compression == "zstd") {
    const size_t r = ZSTD_decompress(chunk_.data(), usize, src, csize);
    if (ZSTD_isError(r)) Fail(std::string("a zstd chunk does not decompress: ") + ZSTD_getErrorName(r), offset);
    if (r != usize)
      Fail("a zstd chunk decompresses to " + std::to_string(r) + " bytes, not " + std::to_string(usize), offset);
  } else if (compression == "lz4") {  // an LZ4 frame
    const Lz4FrameResult r = DecompressLz4Frame(src, csize, usize, &chunk_);
    if (!r.error.empty()) Fail("an lz4 chunk does not decompress: " + r.error, offset);
    if (!r.ended || r.size != usize)
      Fail("an lz4 chunk decompresses to " + std::to_string(r.size) + " bytes, not " + std::to_string(usize), offset);
  } else {
    Fail("a chunk compressed with '" + compression + "' (known: none, zstd, lz4)", offset);
  }
  if (ucrc != 0) {
    if (Crc(0, chunk_.data(), usize) != ucrc) Fail("a chunk's CRC does not match its records", offset);
    ++stats_.crcs_checked;
  }
  ++stats_.chunks;
  in_chunk_ = true;
  chunk_pos_ = 0;
  chunk_offset_ = offset;
}

}  // namespace mbot::ros2
