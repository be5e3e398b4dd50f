#include "bag_source.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "mbot/common/log.hpp"

namespace mbot::ros2 {

using msgs::Event;
using msgs::EventKind;
using msgs::Pose2D;

namespace {

bool HasMagic(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  char head[8] = {};
  in.read(head, 8);
  return in.gcount() == 8 && std::string(head, 8) == std::string("\x89MCAP0\r\n", 8);
}

// rosbag2's metadata.yaml lists its files under relative_file_paths ("  - name_0.mcap").
std::vector<std::string> MetadataFiles(const std::filesystem::path& folder) {
  std::ifstream in(folder / "metadata.yaml");
  std::vector<std::string> files;
  std::string line;
  bool in_list = false;
  while (std::getline(in, line)) {
    const size_t start = line.find_first_not_of(' ');
    if (start == std::string::npos) continue;
    if (line.compare(start, 20, "relative_file_paths:") == 0) {
      in_list = true;
      continue;
    }
    if (!in_list) continue;
    if (line.compare(start, 2, "- ") != 0) break;
    std::string name = line.substr(start + 2);
    while (!name.empty() && (name.back() == ' ' || name.back() == '\r')) name.pop_back();
    if (name.size() >= 2 && (name.front() == '\'' || name.front() == '"')) name = name.substr(1, name.size() - 2);
    files.push_back((folder / name).string());
  }
  return files;
}

}  // namespace

namespace {

class McapFile : public BagFile {
 public:
  explicit McapFile(const std::string& path) : r_(path) {}
  bool Next(McapMessage* m) override { return r_.Next(m); }
  std::optional<ChannelDesc> Channel(uint16_t id) const override {
    const auto ch = r_.channels().find(id);
    if (ch == r_.channels().end()) return std::nullopt;
    const auto schema = r_.schemas().find(ch->second.schema_id);
    return ChannelDesc{ch->second.topic, schema != r_.schemas().end() ? schema->second.name : "",
                       ch->second.message_encoding};
  }
  uint64_t position() const override { return r_.position(); }
  long long messages() const override { return r_.stats().messages; }
  long long chunks() const override { return r_.stats().chunks; }
  long long crcs() const override { return r_.stats().crcs_checked; }
  bool truncated() const override { return r_.stats().truncated; }

 private:
  McapReader r_;
};

class Ros1File : public BagFile {
 public:
  explicit Ros1File(const std::string& path) : r_(path) {}
  bool Next(McapMessage* m) override { return r_.Next(m); }
  std::optional<ChannelDesc> Channel(uint16_t id) const override {
    const auto c = r_.connections().find(id);
    if (c == r_.connections().end()) return std::nullopt;
    // ROS 1 names types "pkg/Type"; the decoders know them by ROS 2's "pkg/msg/Type".
    std::string type = c->second.type;
    if (const size_t slash = type.find('/'); slash != std::string::npos && type.find("/msg/") == std::string::npos) {
      type = type.substr(0, slash) + "/msg/" + type.substr(slash + 1);
    }
    return ChannelDesc{c->second.topic, type, "ros1"};
  }
  uint64_t position() const override { return r_.position(); }
  long long messages() const override { return r_.messages(); }
  long long chunks() const override { return r_.chunks(); }
  long long crcs() const override { return 0; }  // ROS 1 bags have none
  bool truncated() const override { return r_.truncated(); }

 private:
  Ros1BagReader r_;
};

bool HasRos1Magic(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  char head[13] = {};
  in.read(head, 13);
  return in.gcount() == 13 && std::string(head, 13) == "#ROSBAG V2.0\n";
}

}  // namespace

std::unique_ptr<BagFile> OpenBagFile(const std::string& path) {
  if (HasRos1Magic(path)) return std::make_unique<Ros1File>(path);
  return std::make_unique<McapFile>(path);
}

std::vector<std::string> BagFiles(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return {path};  // a .mcap or a ROS 1 .bag
  std::vector<std::string> files = MetadataFiles(path);
  if (files.empty()) {
    for (const auto& entry : fs::directory_iterator(path, ec)) {
      if (entry.path().extension() == ".mcap") files.push_back(entry.path().string());
    }
    std::sort(files.begin(), files.end());
  }
  if (files.empty())
    throw std::runtime_error(path + ": a folder with no .mcap file (not a rosbag2 bag with storage mcap)");
  for (const std::string& f : files) {
    if (!fs::is_regular_file(f, ec))
      throw std::runtime_error(path + ": metadata.yaml lists " + f + ", which is missing");
    if (!HasMagic(f)) throw std::runtime_error(f + ": not an MCAP file (no MCAP magic bytes)");
  }
  return files;
}

McapBagSource::McapBagSource(const msgs::SourceOptions& options)
    : options_(options),
      bag_(msgs::ExtraOr<BagSourceOptions>(options)),
      files_(BagFiles(options.path)),
      decoder_(bag_.robot_frame, options.path) {
  std::error_code ec;
  for (const std::string& f : files_) bytes_total_ += std::filesystem::file_size(f, ec);
  ros1_ = HasRos1Magic(files_[0]);
  reader_ = OpenBagFile(files_[0]);
}

double McapBagSource::Progress() const {
  if (eof_ || bytes_total_ == 0) return 1.0;
  return std::min(1.0, double(bytes_before_ + (reader_ ? reader_->position() : 0)) / double(bytes_total_));
}

std::vector<std::pair<std::string, std::string>> McapBagSource::Details() const {
  std::vector<std::pair<std::string, std::string>> d = {
      {"files", std::to_string(files_.size())},
      {"messages", std::to_string(messages_ + (reader_ ? reader_->messages() : 0))},
      {"chunks", std::to_string(chunks_ + (reader_ ? reader_->chunks() : 0))},
      {"CRCs checked", std::to_string(crcs_ + (reader_ ? reader_->crcs() : 0))}};
  for (auto& kv : decoder_.Details()) d.push_back(std::move(kv));
  return d;
}

bool McapBagSource::ReadMore() {
  while (reader_) {
    McapMessage m;
    bool got = false;
    try {
      got = reader_->Next(&m);
    } catch (const std::runtime_error& e) {  // McapError, Ros1BagError
      // What came before the damage was read; the rest of this file cannot be trusted.
      mbot::log::Warn(std::string(e.what()) + " (the file's messages up to there were replayed)");
      diagnostics_.truncated_tail = true;
      got = false;
    }
    if (got) {
      Handle(m);
      return true;
    }
    if (reader_->truncated()) diagnostics_.truncated_tail = true;
    messages_ += reader_->messages();
    chunks_ += reader_->chunks();
    crcs_ += reader_->crcs();
    std::error_code ec;
    bytes_before_ += std::filesystem::file_size(files_[file_index_], ec);
    reader_.reset();
    routes_.clear();  // channel ids are per file
    if (++file_index_ < files_.size()) reader_ = OpenBagFile(files_[file_index_]);
  }
  return false;
}

void McapBagSource::Reject(const std::string& topic, const McapMessage& m, const std::string& why) {
  ++diagnostics_.rejected_messages;
  mbot::log::Warn(files_[file_index_] + ": rejected message on topic " + topic + " (sequence " +
                  std::to_string(m.sequence) + ", record at byte " + std::to_string(m.offset) + "): " + why);
}

McapBagSource::Route McapBagSource::RouteOf(uint16_t channel_id) {
  // Once per channel of each file: what its messages are, under which topic.
  Route r;
  const std::optional<BagFile::ChannelDesc> ch = reader_->Channel(channel_id);
  if (!ch) return r;  // the reader checks that a message's channel came first
  r.wire = ch->topic;
  const std::string type = ch->type;
  r.topic = bag_.topics.Topic(r.wire);
  msgs::ChannelInfo& info = channels_[r.topic];  // keyed by the pipeline's topic, as the events are
  info.type = type;
  info.generation = std::string(ch->encoding == "ros1" ? "ROS 1 " : "ROS 2 ") + r.wire + " (" + ch->encoding + ")";
  r.info = &info;
  r.type = MessageDecoder::TypeOf(type, r.wire);
  if (ch->encoding == "ros1") r.serialization = Serialization::kRos1;
  if (ch->encoding != "cdr" && ch->encoding != "ros1") r.type = MessageDecoder::Type::kUnknown;
  if (r.type == MessageDecoder::Type::kUnknown) {
    info.decoded = false;
    mbot::log::Warn(files_[file_index_] + ": topic " + r.wire + " carries " + (type.empty() ? "no schema" : type) +
                    " (" + ch->encoding +
                    "), which this reader does not decode; its messages are "
                    "skipped");
  }
  if (r.type == MessageDecoder::Type::kTf || r.type == MessageDecoder::Type::kTfStatic) info.kind = EventKind::kOther;
  r.type_name = type;
  return r;
}

void McapBagSource::Handle(const McapMessage& m) {
  auto found = routes_.find(m.channel_id);
  if (found == routes_.end()) found = routes_.emplace(m.channel_id, RouteOf(m.channel_id)).first;
  const Route& route = found->second;
  if (!route.info) return;
  if (route.type == MessageDecoder::Type::kUnknown) {
    ++diagnostics_.unknown_messages;
    return;
  }
  if (route.type == MessageDecoder::Type::kTf) return;  // the odometry's, which /odom carries
  const std::string& wire = route.wire;
  const std::string& topic = route.topic;
  msgs::ChannelInfo& info = *route.info;
  const int64_t t_us = static_cast<int64_t>(m.log_time_ns / 1000);
  if (!msgs::IsPlausibleTimeUs(t_us)) {
    Reject(wire, m, "absurd log time " + std::to_string(m.log_time_ns) + " ns");
    return;
  }
  Event ev;
  ev.t_us = t_us;
  ev.channel = topic;
  std::string refused;
  bool got = false;
  try {
    got = decoder_.Decode(route.type, topic, wire, m.data.data(), m.data.size(), route.serialization, t_us,
                          options_.roles, &ev, &refused);
  } catch (const std::exception& e) {  // CdrError names the field and offset
    Reject(wire, m, route.type_name + ": " + e.what());
    return;
  }
  if (!refused.empty()) {
    ++diagnostics_.rejected_messages;
    mbot::log::Warn(files_[file_index_] + ": topic " + wire + " (record at byte " + std::to_string(m.offset) +
                    "): transforms refused: " + refused);
  }
  if (!got) return;
  info.kind = ev.kind;
  if (ev.kind == EventKind::kOther) return;
  if (t_us < last_emitted_us_) {
    ++diagnostics_.out_of_order;
    if (warned_.insert("order:" + wire).second) {
      mbot::log::Warn(files_[file_index_] + ": topic " + wire + ": a message " +
                      std::to_string((last_emitted_us_ - t_us) * 1e-3) +
                      " ms older than one already replayed "
                      "(beyond reorder_window_s) is skipped; such messages are counted");
    }
    return;
  }
  pending_.emplace(t_us, std::move(ev));
}

std::optional<Event> McapBagSource::Next() {
  while (true) {
    if (!pending_.empty() && (eof_ || pending_.rbegin()->first - pending_.begin()->first > bag_.reorder_window_us)) {
      Event ev = std::move(pending_.begin()->second);
      pending_.erase(pending_.begin());
      last_emitted_us_ = ev.t_us;
      return ev;
    }
    if (eof_) return std::nullopt;
    if (!ReadMore()) eof_ = true;
  }
}

}  // namespace mbot::ros2
