#include "mbot/ros2/cdr.hpp"

#include <cstring>

namespace mbot::ros2 {

CdrReader::CdrReader(const uint8_t* data, size_t size) : data_(data), size_(size) {
  if (size < 4) throw CdrError("CDR: " + std::to_string(size) + " bytes, shorter than the encapsulation header", 0);
  if (data[0] != 0x00 || data[1] != 0x01) {
    throw CdrError("CDR: encapsulation " + std::to_string(data[0]) + " " + std::to_string(data[1]) +
                       " is not little-endian plain CDR (00 01)",
                   0);
  }
}

void CdrReader::Align(size_t n) {
  if (ros1_) return;  // ROS 1 packs its fields
  const size_t rel = pos_ - 4;
  const size_t pad = (n - rel % n) % n;
  pos_ = pos_ + pad > size_ ? size_ : pos_ + pad;
}

const uint8_t* CdrReader::Take(size_t n, const char* field) {
  if (n > size_ - pos_) {
    throw CdrError(std::string("CDR: ") + field + " needs " + std::to_string(n) + " bytes, " +
                       std::to_string(size_ - pos_) + " left",
                   pos_ - start_);
  }
  const uint8_t* p = data_ + pos_;
  pos_ += n;
  return p;
}

namespace {
template <typename T>
T Load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);  // the host is little-endian (x86, ARM as ROS 2 runs them)
  return v;
}
}  // namespace

uint8_t CdrReader::U8(const char* f) { return *Take(1, f); }
bool CdrReader::Bool(const char* f) {
  const size_t at = offset();
  const uint8_t v = U8(f);
  if (v > 1) throw CdrError(std::string("CDR: ") + f + " is a bool of value " + std::to_string(v), at);
  return v == 1;
}
uint16_t CdrReader::U16(const char* f) { return Align(2), Load<uint16_t>(Take(2, f)); }
int32_t CdrReader::I32(const char* f) { return Align(4), Load<int32_t>(Take(4, f)); }
uint32_t CdrReader::U32(const char* f) { return Align(4), Load<uint32_t>(Take(4, f)); }
int64_t CdrReader::I64(const char* f) { return Align(8), Load<int64_t>(Take(8, f)); }
uint64_t CdrReader::U64(const char* f) { return Align(8), Load<uint64_t>(Take(8, f)); }
float CdrReader::F32(const char* f) { return Align(4), Load<float>(Take(4, f)); }
double CdrReader::F64(const char* f) { return Align(8), Load<double>(Take(8, f)); }

std::string CdrReader::String(const char* f) {
  const size_t at = offset();
  const uint32_t n = U32(f);
  if (n == 0) return {};  // some writers send 0 for an empty string
  const uint8_t* p = Take(n, f);
  if (ros1_) return std::string(reinterpret_cast<const char*>(p), n);
  if (p[n - 1] != 0) throw CdrError(std::string("CDR: ") + f + " is a string without its NUL", at);
  return std::string(reinterpret_cast<const char*>(p), n - 1);
}

uint32_t CdrReader::Count(const char* f, size_t min_bytes) {
  const size_t at = offset();
  const uint32_t n = U32(f);
  if (min_bytes > 0 && n > remaining() / min_bytes) {
    throw CdrError(std::string("CDR: ") + f + " counts " + std::to_string(n) + " elements, " +
                       std::to_string(remaining()) + " bytes left",
                   at);
  }
  return n;
}

std::vector<float> CdrReader::F32s(const char* f) {
  const uint32_t n = Count(f, 4);
  Align(4);
  const uint8_t* p = Take(size_t{n} * 4, f);
  std::vector<float> v(n);
  if (n) std::memcpy(v.data(), p, size_t{n} * 4);
  return v;
}

std::vector<int8_t> CdrReader::I8s(const char* f) {
  const uint32_t n = Count(f, 1);
  const uint8_t* p = Take(n, f);
  return std::vector<int8_t>(reinterpret_cast<const int8_t*>(p), reinterpret_cast<const int8_t*>(p) + n);
}

void CdrReader::F64Array(const char* f, double* out, size_t n) {
  Align(8);
  std::memcpy(out, Take(n * 8, f), n * 8);
}

CdrWriter::CdrWriter() : out_{0x00, 0x01, 0x00, 0x00} {}

void CdrWriter::Align(size_t n) {
  const size_t rel = out_.size() - 4;
  out_.resize(out_.size() + (n - rel % n) % n, 0);
}
void CdrWriter::Put(const void* p, size_t n) {
  const auto* b = static_cast<const uint8_t*>(p);
  out_.insert(out_.end(), b, b + n);
}
void CdrWriter::U8(uint8_t v) { out_.push_back(v); }
void CdrWriter::U16(uint16_t v) { Align(2), Put(&v, 2); }
void CdrWriter::U32(uint32_t v) { Align(4), Put(&v, 4); }
void CdrWriter::U64(uint64_t v) { Align(8), Put(&v, 8); }
void CdrWriter::F32(float v) { Align(4), Put(&v, 4); }
void CdrWriter::F64(double v) { Align(8), Put(&v, 8); }
void CdrWriter::String(const std::string& s) {
  U32(static_cast<uint32_t>(s.size() + 1));
  Put(s.data(), s.size());
  U8(0);
}
void CdrWriter::F32s(const std::vector<float>& v) {
  U32(static_cast<uint32_t>(v.size()));
  Align(4);
  Put(v.data(), v.size() * 4);
}
void CdrWriter::I8s(const std::vector<int8_t>& v) {
  U32(static_cast<uint32_t>(v.size()));
  Put(v.data(), v.size());
}
void CdrWriter::F64Array(const double* v, size_t n) {
  Align(8);
  Put(v, n * 8);
}

}  // namespace mbot::ros2
