#include <algorithm>
#include <deque>
#include <stdexcept>

#include "mbot/msgs/stage.hpp"

namespace mbot::msgs {
namespace {

// Deques: registering never moves what is registered (the pointers handed out stay valid). Function
// statics: stage files register from their static initialisers, before main.
std::deque<StageType>& Stages() {
  static std::deque<StageType> types;
  return types;
}
std::deque<OutputType>& Outputs() {
  static std::deque<OutputType> types;
  return types;
}

template <typename T>
std::vector<const T*> Sorted(const std::deque<T>& types) {
  std::vector<const T*> out;
  for (const T& t : types) out.push_back(&t);
  std::sort(out.begin(), out.end(), [](const T* a, const T* b) { return a->name < b->name; });
  return out;
}

template <typename T>
const T* Find(const std::deque<T>& types, const std::string& name) {
  for (const T& t : types) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

}  // namespace

void RegisterStageType(StageType type) {
  if (Find(Stages(), type.name)) throw std::logic_error("stage type '" + type.name + "' is registered twice");
  Stages().push_back(std::move(type));
}
std::vector<const StageType*> StageTypes() { return Sorted(Stages()); }
const StageType* FindStageType(const std::string& name) { return Find(Stages(), name); }

void RegisterOutputType(OutputType type) {
  if (Find(Outputs(), type.name)) throw std::logic_error("output type '" + type.name + "' is registered twice");
  Outputs().push_back(std::move(type));
}
std::vector<const OutputType*> OutputTypes() { return Sorted(Outputs()); }
const OutputType* FindOutputType(const std::string& name) { return Find(Outputs(), name); }

void Inbox::Post(Event event) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (events_.size() >= capacity_) {
    events_.pop_front();
    ++dropped_;
  }
  events_.push_back(std::move(event));
}

std::vector<Event> Inbox::Take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Event> out(std::make_move_iterator(events_.begin()), std::make_move_iterator(events_.end()));
  events_.clear();
  return out;
}

long long Inbox::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

}  // namespace mbot::msgs
