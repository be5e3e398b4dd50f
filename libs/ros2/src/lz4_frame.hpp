#pragma once
// One LZ4 frame decompressed into a buffer that grows with what really comes out, so a chunk that
// lies about its size costs what it decompresses to, not what it claims (MCAP and ROS 1 bags).
#include <lz4frame.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace mbot::ros2 {

struct Lz4FrameResult {
  size_t size = 0;     // bytes written to the buffer (it is resized to this)
  bool ended = false;  // the frame ended
  std::string error;   // empty unless lz4 refused the input
};

inline Lz4FrameResult DecompressLz4Frame(const uint8_t* src, size_t size, size_t claimed, std::vector<uint8_t>* out) {
  Lz4FrameResult r;
  out->clear();
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) {
    r.error = "no lz4 context";
    return r;
  }
  size_t in = 0, hint = 1;
  while (hint != 0 && in < size) {
    if (r.size == out->size() && out->size() < claimed)
      out->resize(std::min<size_t>(claimed, std::max<size_t>(out->size() * 2, size_t(1) << 20)));
    size_t dst = out->size() - r.size, n = size - in;
    if (dst == 0) break;  // more than it claims
    hint = LZ4F_decompress(ctx, out->data() + r.size, &dst, src + in, &n, nullptr);
    if (LZ4F_isError(hint)) {
      r.error = LZ4F_getErrorName(hint);
      break;
    }
    r.size += dst, in += n;
    if (dst == 0 && n == 0) break;
  }
  LZ4F_freeDecompressionContext(ctx);
  r.ended = r.error.empty() && hint == 0;
  out->resize(r.size);
  return r;
}

}  // namespace mbot::ros2
