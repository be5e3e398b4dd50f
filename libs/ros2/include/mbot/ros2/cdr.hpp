// CDR as ROS 2 puts it on the wire and in rosbag2 files (XCDR1, plain CDR): a 4-byte
// encapsulation header (00 01 00 00: little-endian), then the fields in order, each aligned to its
// own size (8-byte values to 8) counted from the byte after the header; a string is a uint32 length
// that counts its NUL, the bytes and the NUL; a sequence a uint32 count and its elements.
//
// The reader never reads past the buffer and never allocates more than the buffer could hold: a
// length that does not fit is an error naming the field and its offset.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace mbot::ros2 {

// A message that is not what its type says: what, which field, at which offset of the payload.
class CdrError : public std::runtime_error {
 public:
  CdrError(const std::string& what, size_t offset)
      : std::runtime_error(what + " at offset " + std::to_string(offset)), offset_(offset) {}
  size_t offset() const { return offset_; }

 private:
  size_t offset_;
};

class CdrReader {
 public:
  // `data` starts with the encapsulation header; big-endian CDR is refused (ROS 2 writes little).
  CdrReader(const uint8_t* data, size_t size);
  // ROS 1's serialization instead (a ROS 1 bag's messages): the same fields, little-endian, with no
  // header, no alignment, and strings without their NUL.
  struct Ros1 {};
  CdrReader(Ros1, const uint8_t* data, size_t size) : data_(data), size_(size), pos_(0), start_(0), ros1_(true) {}
  bool ros1() const { return ros1_; }

  uint8_t U8(const char* field);
  bool Bool(const char* field);
  int8_t I8(const char* field) { return static_cast<int8_t>(U8(field)); }
  uint16_t U16(const char* field);
  int32_t I32(const char* field);
  uint32_t U32(const char* field);
  int64_t I64(const char* field);
  uint64_t U64(const char* field);
  float F32(const char* field);
  double F64(const char* field);
  std::string String(const char* field);
  // A sequence's count, checked against what is left (each element takes at least `min_bytes`).
  uint32_t Count(const char* field, size_t min_bytes);
  std::vector<float> F32s(const char* field);
  std::vector<int8_t> I8s(const char* field);
  void F64Array(const char* field, double* out, size_t n);  // a fixed array (float64[36] …)

  size_t offset() const { return pos_ - start_; }  // in the payload, after the header
  size_t remaining() const { return size_ - pos_; }

 private:
  void Align(size_t n);
  const uint8_t* Take(size_t n, const char* field);
  const uint8_t* data_;
  size_t size_, pos_ = 4, start_ = 4;
  bool ros1_ = false;
};

class CdrWriter {
 public:
  CdrWriter();  // writes the little-endian header
  void U8(uint8_t v);
  void Bool(bool v) { U8(v ? 1 : 0); }
  void U16(uint16_t v);
  void I32(int32_t v) { U32(static_cast<uint32_t>(v)); }
  void U32(uint32_t v);
  void I64(int64_t v) { U64(static_cast<uint64_t>(v)); }
  void U64(uint64_t v);
  void F32(float v);
  void F64(double v);
  void String(const std::string& s);
  void F32s(const std::vector<float>& v);
  void I8s(const std::vector<int8_t>& v);
  void F64Array(const double* v, size_t n);
  const std::vector<uint8_t>& bytes() const { return out_; }

 private:
  void Align(size_t n);
  void Put(const void* p, size_t n);
  std::vector<uint8_t> out_;
};

}  // namespace mbot::ros2
