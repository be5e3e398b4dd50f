#include "mbot/drivers/image_header.hpp"

#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace mbot::drivers {
namespace {

uint32_t Be16(const std::string& b, size_t at) {
  return (static_cast<uint32_t>(static_cast<uint8_t>(b[at])) << 8) | static_cast<uint8_t>(b[at + 1]);
}
uint32_t Be32(const std::string& b, size_t at) { return (Be16(b, at) << 16) | Be16(b, at + 2); }
int32_t Le32(const std::string& b, size_t at) {
  uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<uint8_t>(b[at + static_cast<size_t>(k)]);
  return static_cast<int32_t>(v);
}

[[noreturn]] void Fail(const std::string& name, const std::string& why) { throw std::runtime_error(name + ": " + why); }

void CheckSize(const std::string& name, const std::string& format, int64_t w, int64_t h) {
  if (w <= 0 || h <= 0) Fail(name, format + " header gives a size of " + std::to_string(w) + " x " + std::to_string(h));
  if (w > kMaxImageSidePx || h > kMaxImageSidePx || w * h > kMaxImagePixels) {
    Fail(name, format + " of " + std::to_string(w) + " x " + std::to_string(h) +
                   " px is larger than images are read (" + std::to_string(kMaxImageSidePx) + " px a side, " +
                   std::to_string(kMaxImagePixels) + " px in all)");
  }
}

// The next whitespace-separated PNM header field, skipping comments.
bool PnmField(const std::string& b, size_t* at, int64_t* value) {
  while (*at < b.size()) {
    if (b[*at] == '#') {
      while (*at < b.size() && b[*at] != '\n') ++*at;
    } else if (std::isspace(static_cast<unsigned char>(b[*at]))) {
      ++*at;
    } else {
      break;
    }
  }
  int64_t v = 0;
  size_t digits = 0;
  while (*at < b.size() && std::isdigit(static_cast<unsigned char>(b[*at])) && digits < 12) {
    v = v * 10 + (b[*at] - '0');
    ++*at, ++digits;
  }
  *value = v;
  return digits > 0;
}

}  // namespace

void CheckImageBytes(const std::string& b, const std::string& name) {
  auto starts = [&](const char* magic, size_t n) { return b.size() >= n && b.compare(0, n, magic, n) == 0; };
  if (starts("\x89PNG\r\n\x1a\n", 8)) {
    if (b.size() < 24 || b.compare(12, 4, "IHDR") != 0) Fail(name, "PNG without its IHDR header");
    CheckSize(name, "PNG", Be32(b, 16), Be32(b, 20));
    // The last chunk is IEND: length 0, type, CRC.
    static const char kIend[] = "\0\0\0\0IEND\xae\x42\x60\x82";
    if (b.size() < 12 || b.compare(b.size() - 12, 12, kIend, 12) != 0)
      Fail(name, "truncated PNG (it does not end with its IEND chunk)");
  } else if (starts("\xff\xd8", 2)) {
    size_t at = 2;
    while (true) {
      while (at < b.size() && static_cast<uint8_t>(b[at]) != 0xff) ++at;  // to the next marker
      while (at < b.size() && static_cast<uint8_t>(b[at]) == 0xff) ++at;  // fill bytes
      if (at + 3 > b.size()) Fail(name, "JPEG without a frame header (SOF) in its first bytes: truncated?");
      const uint8_t m = static_cast<uint8_t>(b[at]);
      if (m == 0xd8 || m == 0x01 || (m >= 0xd0 && m <= 0xd7)) {  // no length
        ++at;
        continue;
      }
      const uint32_t len = Be16(b, at + 1);
      if (m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc) {
        if (at + 8 > b.size()) Fail(name, "JPEG frame header cut short");
        CheckSize(name, "JPEG", Be16(b, at + 6), Be16(b, at + 4));
        break;
      }
      if (len < 2) Fail(name, "JPEG segment of length " + std::to_string(len) + " at byte " + std::to_string(at));
      at += 1 + len;
    }
    // The last marker is EOI (FF D9), possibly followed by padding.
    size_t end = b.size();
    while (end > 0 && (b[end - 1] == '\0' || std::isspace(static_cast<unsigned char>(b[end - 1])))) --end;
    if (end < 2 || static_cast<uint8_t>(b[end - 2]) != 0xff || static_cast<uint8_t>(b[end - 1]) != 0xd9)
      Fail(name, "truncated JPEG (it does not end with the end-of-image marker FF D9)");
  } else if (starts("BM", 2)) {
    if (b.size() < 26) Fail(name, "BMP header cut short");
    const int64_t w = Le32(b, 18), hh = Le32(b, 22);
    CheckSize(name, "BMP", w, hh < 0 ? -hh : hh);
  } else if (b.size() >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6') {
    size_t at = 2;
    int64_t w = 0, hh = 0;
    if (!PnmField(b, &at, &w) || !PnmField(b, &at, &hh)) Fail(name, "PNM header without a width and height");
    CheckSize(name, "PNM", w, hh);
  } else if (!starts("II*\0", 4) && !starts("MM\0*", 4)) {
    // (A TIFF passes: its size sits in an IFD anywhere in the file, so OpenCV's own limits apply.)
    Fail(name, "not an image of a kind read here (no PNG, JPEG, BMP, PNM or TIFF signature)");
  }
}

void CheckImageFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, "cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  CheckImageBytes(s.str(), path);
}

}  // namespace mbot::drivers
