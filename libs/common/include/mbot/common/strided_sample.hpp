// A uniform sample of a stream of any length in bounded memory: every stride-th item, at most
// `capacity` of them. When full, every other kept item goes and the stride doubles.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace mbot {

template <typename T>
class StridedSample {
 public:
  struct Item {
    size_t index = 0;  // the item's position in the stream
    T value;
  };

  explicit StridedSample(size_t capacity) : capacity_(capacity < 2 ? 2 : capacity) {}

  // Whether the stream's item `index` (counting up from 0) belongs in the sample; call Add if so.
  bool Wants(size_t index) {
    if (index % stride_ != 0) return false;
    if (items_.size() < capacity_) return true;
    size_t kept = 0;
    for (size_t i = 0; i < items_.size(); i += 2) items_[kept++] = std::move(items_[i]);
    items_.resize(kept);
    stride_ *= 2;
    return index % stride_ == 0;
  }
  void Add(size_t index, T value) { items_.push_back({index, std::move(value)}); }

  const std::vector<Item>& items() const { return items_; }
  std::vector<Item>& mutable_items() { return items_; }  // the values may change, not the indices

 private:
  size_t capacity_;
  size_t stride_ = 1;
  std::vector<Item> items_;
};

}  // namespace mbot
