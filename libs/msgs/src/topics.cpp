#include "mbot/msgs/topics.hpp"

#include "mbot/common/config.hpp"

namespace mbot::msgs {

TopicTable::TopicTable(std::map<std::string, std::string> defaults) : to_wire_(std::move(defaults)) {
  for (const auto& [topic, wire] : to_wire_) to_topic_[wire] = topic;
}

void TopicTable::Parse(config::Section& s, const std::string& key) {
  for (const std::string& item :
       s.GetList(key, {}, "TOPIC:name pairs renaming the pipeline's topics on this transport (e.g. LIDAR:/scan)")) {
    const size_t colon = item.find(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == item.size()) {
      s.Fail(key, "'" + item + "' is not TOPIC:name");
    }
    to_wire_[item.substr(0, colon)] = item.substr(colon + 1);
  }
  to_topic_.clear();
  for (const auto& [topic, wire] : to_wire_) {
    if (!to_topic_.emplace(wire, topic).second) {
      s.Fail(key, "'" + wire + "' names two topics (" + to_topic_[wire] + " and " + topic + ")");
    }
  }
}

std::string TopicTable::Wire(const std::string& topic) const {
  auto it = to_wire_.find(topic);
  return it == to_wire_.end() ? topic : it->second;
}

std::string TopicTable::Topic(const std::string& wire) const {
  auto it = to_topic_.find(wire);
  return it == to_topic_.end() ? wire : it->second;
}

}  // namespace mbot::msgs
