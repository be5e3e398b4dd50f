// The LCM codec's front: the table every family fills, and Decode / Encode over it.
#include "codec/codec.hpp"

namespace mbot::lcmio::lcm_adapter {

void TypeTable::Add(int64_t hash, const std::string& type, const std::string& gen, Decoder dec) {
  auto it = entries_.find(hash);
  if (it == entries_.end()) {
    entries_.emplace(hash, Entry{TypeInfo{type, gen}, std::move(dec)});
  } else {  // same layout in several generations: one decoder, all names
    if (it->second.info.type.find(type) == std::string::npos) it->second.info.type += "/" + type;
    if (it->second.info.generation.find(gen) == std::string::npos) it->second.info.generation += ", " + gen;
  }
}

namespace {

const std::map<int64_t, Entry>& Table() {
  static const TypeTable table = [] {
    TypeTable t;
    AddSensorTypes(t);
    AddPoseTypes(t);
    AddMapTypes(t);
    AddStatusTypes(t);
    AddVisionTypes(t);
    AddForkliftTypes(t);
    return t;
  }();
  return table.entries();
}

}  // namespace

int64_t Fingerprint(const uint8_t* data, size_t size) {
  if (size < 8) return 0;
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | data[i];
  return static_cast<int64_t>(v);
}

const TypeInfo* LookUp(int64_t fingerprint) {
  auto it = Table().find(fingerprint);
  return it == Table().end() ? nullptr : &it->second.info;
}

bool Decode(const std::string& channel, const uint8_t* data, size_t size, const ChannelRoles& roles, Event* event,
            std::string* error) {
  auto it = Table().find(Fingerprint(data, size));
  if (it == Table().end()) {
    *error = "unknown fingerprint";
    return false;
  }
  return it->second.decode(channel, data, size, roles, event, error);
}

std::vector<std::pair<int64_t, TypeInfo>> KnownTypes() {
  std::vector<std::pair<int64_t, TypeInfo>> out;
  for (const auto& [hash, e] : Table()) out.emplace_back(hash, e.info);
  return out;
}

bool Encode(const Event& ev, std::vector<uint8_t>* out) {
  out->clear();
  Encoder encoder(out);
  if (Visit(ev, encoder)) return true;
  out->clear();
  return false;
}

}  // namespace mbot::lcmio::lcm_adapter
