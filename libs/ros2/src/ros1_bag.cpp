#include "mbot/ros2/ros1_bag.hpp"

#include <bzlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>

#include "lz4_frame.hpp"

namespace mbot::ros2 {

namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr size_t kMagicSize = 13;
constexpr uint64_t kMaxRecordBytes = 1ull << 30;     // a record or a chunk of more than 1 GiB is refused
constexpr uint64_t kMaxPendingBytes = 256ull << 20;  // messages held back to be put in time order

enum Op : uint8_t {
  kMessageData = 0x02,
  kBagHeader = 0x03,
  kIndexData = 0x04,
  kChunk = 0x05,
  kChunkInfo = 0x06,
  kConnection = 0x07,
};

uint32_t U32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

const std::string& Field(const std::map<std::string, std::string>& h, const char* name, const char* record) {
  auto it = h.find(name);
  if (it == h.end()) throw std::runtime_error(std::string("a ") + record + " record without its '" + name + "' field");
  return it->second;
}

uint32_t FieldU32(const std::map<std::string, std::string>& h, const char* name, const char* record) {
  const std::string& v = Field(h, name, record);
  if (v.size() != 4)
    throw std::runtime_error(std::string("a ") + record + " record whose '" + name + "' is not 4 bytes");
  return U32(reinterpret_cast<const uint8_t*>(v.data()));
}

}  // namespace

std::map<std::string, std::string> ParseRos1Header(const uint8_t* data, uint64_t size) {
  std::map<std::string, std::string> fields;
  uint64_t pos = 0;
  while (pos < size) {
    if (size - pos < 4) throw std::runtime_error("a header field's length is cut short");
    const uint32_t n = U32(data + pos);
    pos += 4;
    if (n > size - pos)
      throw std::runtime_error("a header field of " + std::to_string(n) + " bytes runs past its header");
    const char* f = reinterpret_cast<const char*>(data + pos);
    const char* eq = static_cast<const char*>(std::memchr(f, '=', n));
    if (!eq) throw std::runtime_error("a header field without '='");
    fields[std::string(f, eq)] = std::string(eq + 1, f + n);
    pos += n;
  }
  return fields;
}

Ros1BagReader::Ros1BagReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
  if (!in_) throw Ros1BagError(path + ": cannot be read");
  std::error_code ec;
  size_ = std::filesystem::file_size(path, ec);
  char head[kMagicSize] = {};
  in_.read(head, kMagicSize);
  if (in_.gcount() != std::streamsize(kMagicSize) || std::memcmp(head, kMagic, kMagicSize) != 0) {
    throw Ros1BagError(path + ": not a ROS 1 bag (no '#ROSBAG V2.0' line)");
  }
  pos_ = kMagicSize;
}

void Ros1BagReader::Fail(const std::string& what, uint64_t offset) const {
  throw Ros1BagError(path_ + ": " + what + " (record at byte " + std::to_string(offset) + ")");
}

namespace {
// std::push_heap builds a max-heap: "later" is the lesser, so the earliest (time, order) is on top.
template <typename P>
bool Later(const P& a, const P& b) {
  if (a.message.log_time_ns != b.message.log_time_ns) return a.message.log_time_ns > b.message.log_time_ns;
  return a.order > b.order;
}
}  // namespace

bool Ros1BagReader::Next(McapMessage* message) {
  // What is no later than the newest chunk's earliest message cannot be preceded by anything still
  // in the file (chunks start in time order), so it goes out; otherwise read one more chunk.
  while (true) {
    // A bag whose chunks go back in time would be held whole: past kMaxPendingBytes the earliest
    // goes out anyway (and the source's reorder window sees what follows it late).
    if (!heap_.empty() &&
        (file_done_ || heap_.front().message.log_time_ns <= group_min_ns_ || pending_bytes_ > kMaxPendingBytes)) {
      std::pop_heap(heap_.begin(), heap_.end(), [](const Pending& a, const Pending& b) { return Later(a, b); });
      *message = std::move(heap_.back().message);
      heap_.pop_back();
      pending_bytes_ -= message->data.size();
      return true;
    }
    if (file_done_) {
      if (!error_.empty()) {
        const std::string what = std::move(error_);
        error_.clear();
        throw Ros1BagError(what);
      }
      return false;
    }
    // A bad record ends the bag, after what came before it has gone out.
    try {
      if (!LoadGroup()) file_done_ = true;
    } catch (const Ros1BagError& e) {
      error_ = e.what(), file_done_ = true;
    }
  }
}

bool Ros1BagReader::LoadGroup() {
  McapMessage m;
  long long group = 0;
  if (carry_valid_) {
    m = std::move(carry_), group = carry_group_, carry_valid_ = false;
  } else if (!NextInFileOrder(&m, &group)) {
    return false;
  }
  const long long this_group = group;
  uint64_t min_ns = m.log_time_ns;
  auto push = [&](McapMessage&& msg) {
    pending_bytes_ += msg.data.size();
    heap_.push_back({read_order_++, std::move(msg)});
    std::push_heap(heap_.begin(), heap_.end(), [](const Pending& a, const Pending& b) { return Later(a, b); });
  };
  push(std::move(m));
  while (true) {
    McapMessage next;
    if (!NextInFileOrder(&next, &group)) break;
    if (group != this_group) {
      carry_ = std::move(next), carry_group_ = group, carry_valid_ = true;
      break;
    }
    min_ns = std::min(min_ns, next.log_time_ns);
    push(std::move(next));
  }
  group_min_ns_ = min_ns;
  return true;
}

bool Ros1BagReader::NextInFileOrder(McapMessage* message, long long* group) {
  while (true) {
    if (in_chunk_) {
      while (chunk_pos_ < chunk_.size()) {
        // Records inside a chunk: header length, header, data length, data.
        const uint64_t left = chunk_.size() - chunk_pos_;
        const uint8_t* p = chunk_.data() + chunk_pos_;
        if (left < 4) Fail("a chunk's records end inside a record's header length", chunk_offset_);
        const uint32_t hlen = U32(p);
        if (hlen > left - 4 || left - 4 - hlen < 4) Fail("a record in a chunk runs past the chunk", chunk_offset_);
        const uint32_t dlen = U32(p + 4 + hlen);
        if (dlen > left - 8 - hlen) Fail("a record's data in a chunk runs past the chunk", chunk_offset_);
        chunk_pos_ += 8 + uint64_t(hlen) + dlen;
        try {
          if (Handle(ParseRos1Header(p + 4, hlen), p + 8 + hlen, dlen, chunk_offset_, message)) {
            *group = chunks_;
            return true;
          }
        } catch (const Ros1BagError&) {
          throw;
        } catch (const std::exception& e) {
          Fail(std::string(e.what()) + ", in a chunk", chunk_offset_);
        }
      }
      in_chunk_ = false;
    }
    if (done_) return false;
    const uint64_t at = pos_;
    if (size_ - pos_ == 0) {
      done_ = true;
      return false;
    }
    // A record of the file: what is cut short ends the bag, and says so.
    auto read = [&](uint64_t n, std::vector<uint8_t>* out) {
      if (n > size_ - pos_) return false;
      out->resize(n);
      if (n && !in_.read(reinterpret_cast<char*>(out->data()), std::streamsize(n))) return false;
      pos_ += n;
      return true;
    };
    std::vector<uint8_t> len, header, data;
    if (!read(4, &len)) break;
    const uint32_t hlen = U32(len.data());
    if (hlen > kMaxRecordBytes) Fail("a record header of " + std::to_string(hlen) + " bytes", at);
    if (!read(hlen, &header) || !read(4, &len)) break;
    const uint32_t dlen = U32(len.data());
    if (dlen > kMaxRecordBytes) Fail("a record of " + std::to_string(dlen) + " bytes (at most 1 GiB)", at);
    if (!read(dlen, &data)) break;
    std::map<std::string, std::string> fields;
    try {
      fields = ParseRos1Header(header.data(), header.size());
    } catch (const std::exception& e) {
      Fail(e.what(), at);
    }
    try {
      if (Field(fields, "op", "bag") == std::string(1, char(kChunk))) {
        ReadChunk(fields, data.data(), data.size(), at);
        continue;
      }
      if (Handle(fields, data.data(), data.size(), at, message)) {
        *group = -(++bare_);  // a message outside a chunk
        return true;
      }
    } catch (const Ros1BagError&) {
      throw;
    } catch (const std::exception& e) {
      Fail(e.what(), at);
    }
  }
  truncated_ = true;  // cut inside a record
  done_ = true;
  return false;
}

bool Ros1BagReader::Handle(const std::map<std::string, std::string>& h, const uint8_t* data, uint64_t size,
                           uint64_t offset, McapMessage* message) {
  const std::string& op = Field(h, "op", "bag");
  if (op.size() != 1) throw std::runtime_error("a record whose op is not one byte");
  switch (uint8_t(op[0])) {
    case kConnection: {
      Ros1Connection c;
      c.id = FieldU32(h, "conn", "connection");
      c.topic = Field(h, "topic", "connection");
      const auto fields = ParseRos1Header(data, size);  // the connection header: type, md5sum, definition
      c.type = Field(fields, "type", "connection");
      if (auto it = fields.find("md5sum"); it != fields.end()) c.md5sum = it->second;
      if (auto it = fields.find("message_definition"); it != fields.end()) c.definition = it->second;
      connections_[c.id] = c;
      return false;
    }
    case kMessageData: {
      const uint32_t conn = FieldU32(h, "conn", "message data");
      const std::string& time = Field(h, "time", "message data");
      if (time.size() != 8) throw std::runtime_error("a message whose time is not 8 bytes");
      if (!connections_.count(conn)) {
        throw std::runtime_error("a message on connection " + std::to_string(conn) + ", which no record declared");
      }
      const auto* t = reinterpret_cast<const uint8_t*>(time.data());
      message->channel_id = static_cast<uint16_t>(conn);
      message->sequence = 0;
      message->log_time_ns = uint64_t(U32(t)) * 1'000'000'000ull + U32(t + 4);
      message->publish_time_ns = message->log_time_ns;
      message->data.assign(data, data + size);
      message->offset = offset;
      if (conn > 0xffff) throw std::runtime_error("connection id " + std::to_string(conn) + " beyond 65535");
      ++messages_;
      return true;
    }
    case kBagHeader:
    case kIndexData:
    case kChunkInfo: return false;  // the index: not needed for a linear read
    default: throw std::runtime_error("an unknown record op " + std::to_string(uint8_t(op[0])));
  }
}

void Ros1BagReader::ReadChunk(const std::map<std::string, std::string>& h, const uint8_t* data, uint64_t size,
                              uint64_t offset) {
  const std::string& compression = Field(h, "compression", "chunk");
  const uint32_t usize = FieldU32(h, "size", "chunk");
  // A compressed chunk holds at most this much: bz2 and lz4 do not reach 1000:1 on real data.
  if (usize > kMaxRecordBytes || (compression != "none" && usize > size * 1000 + (1 << 20))) {
    Fail("a chunk claiming " + std::to_string(usize) + " bytes from " + std::to_string(size), offset);
  }
  // The buffer grows with what really comes out (bz2 has no size of its own to check the claim
  // against), so a chunk lying about its size costs what it decompresses to, not what it claims.
  size_t out = 0;
  auto room = [&]() {
    if (out == chunk_.size() && chunk_.size() < usize) {
      chunk_.resize(std::min<size_t>(usize, std::max<size_t>(chunk_.size() * 2, size_t(1) << 20)));
    }
    return chunk_.size() - out;
  };
  chunk_.clear();
  if (compression == "none") {
    if (size != usize) Fail("an uncompressed chunk whose sizes differ", offset);
    chunk_.assign(data, data + size);
    out = size;
  } else if (compression == "bz2") {
    bz_stream bz{};
    if (BZ2_bzDecompressInit(&bz, 0, 0) != BZ_OK) Fail("bz2: no decompressor", offset);
    bz.next_in = const_cast<char*>(reinterpret_cast<const char*>(data));
    bz.avail_in = static_cast<unsigned int>(size);
    int r = BZ_OK;
    while (r == BZ_OK) {
      const size_t free = room();
      if (free == 0) break;  // more than it claims: refused below
      bz.next_out = reinterpret_cast<char*>(chunk_.data() + out);
      bz.avail_out = static_cast<unsigned int>(free);
      r = BZ2_bzDecompress(&bz);
      out += free - bz.avail_out;
      if (r == BZ_OK && bz.avail_in == 0 && bz.avail_out != 0) break;  // input ended mid-stream
    }
    BZ2_bzDecompressEnd(&bz);
    if (r != BZ_OK && r != BZ_STREAM_END)
      Fail("a bz2 chunk does not decompress (bzlib error " + std::to_string(r) + ")", offset);
    if (r != BZ_STREAM_END)
      Fail("a bz2 chunk cut short or longer than its " + std::to_string(usize) + " bytes", offset);
    if (out != usize)
      Fail("a bz2 chunk decompresses to " + std::to_string(out) + " bytes, not " + std::to_string(usize), offset);
  } else if (compression == "lz4") {
    const Lz4FrameResult r = DecompressLz4Frame(data, size, usize, &chunk_);
    if (!r.error.empty()) Fail("an lz4 chunk does not decompress: " + r.error, offset);
    out = r.size;
    if (out != usize)
      Fail("an lz4 chunk decompresses to " + std::to_string(out) + " bytes, not " + std::to_string(usize), offset);
  } else {
    Fail("a chunk compressed with '" + compression + "' (known: none, bz2, lz4)", offset);
  }
  chunk_.resize(out);
  ++chunks_;
  in_chunk_ = true;
  chunk_pos_ = 0;
  chunk_offset_ = offset;
}

}  // namespace mbot::ros2
