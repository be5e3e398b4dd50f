#include "mbot/msgs/scan_renderer.hpp"

namespace mbot::msgs {
namespace {
ScanRenderer& Renderer() {
  static ScanRenderer renderer;
  return renderer;
}
}  // namespace

void SetScanRenderer(ScanRenderer renderer) { Renderer() = std::move(renderer); }

const ScanRenderer* GetScanRenderer() { return Renderer() ? &Renderer() : nullptr; }

}  // namespace mbot::msgs
