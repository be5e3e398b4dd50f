// An image file's size and completeness, checked from its header before any decoder allocates for it: a
// PNG whose header claims 20000 × 20000 pixels, a 60000² JPEG or a JPEG cut short is refused
// naming the file, instead of an allocation failure or a silent half image.
#pragma once

#include <cstdint>
#include <string>

namespace mbot::drivers {

// Largest image accepted from a file: 2^26 pixels (8192 × 8192; a 48 MP camera fits) and
// 32768 pixels a side.
constexpr int64_t kMaxImagePixels = int64_t{1} << 26;
constexpr int kMaxImageSidePx = 32768;

// Reads the image file at `path` (its header and its last bytes decide) and throws std::runtime_error naming the file
// when it is no image of a known kind (PNG, JPEG, BMP, PNM, TIFF), claims a size of 0 or beyond the limits above, or is
// cut short (a JPEG without its end-of-image marker, a PNG without its IEND chunk).
void CheckImageFile(const std::string& path);

// The same for the bytes of a file, `name` naming it in errors.
void CheckImageBytes(const std::string& bytes, const std::string& name);

}  // namespace mbot::drivers
