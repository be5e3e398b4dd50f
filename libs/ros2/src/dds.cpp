// Cyclone DDS with a serialized type of our own: samples are the CDR bytes messages.cpp writes and
// reads, so Cyclone never interprets them (rmw_cyclonedds_cpp's serdata works the same way). ROS 2
// types have no key: every sample is one instance.
#include "mbot/ros2/dds.hpp"

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsi/q_radmin.h>

#include <atomic>
#include <cstring>
#include <map>
#include <stdexcept>

#include "mbot/msgs/live_source.hpp"  // WallClockUs
#include "mbot/ros2/cdr.hpp"

namespace mbot::ros2 {

std::string DdsTopicName(const std::string& ros_topic) {
  return "rt" + (ros_topic.empty() || ros_topic.front() != '/' ? "/" + ros_topic : ros_topic);
}

std::string DdsTypeName(const std::string& ros_type) {
  // pkg/msg/Type → pkg::msg::dds_::Type_
  const size_t a = ros_type.find('/'), b = ros_type.rfind('/');
  if (a == std::string::npos || a == b) throw std::runtime_error("ROS 2 type '" + ros_type + "' is not pkg/msg/Type");
  return ros_type.substr(0, a) + "::" + ros_type.substr(a + 1, b - a - 1) + "::dds_::" + ros_type.substr(b + 1) + "_";
}

namespace {

// A sertype: the type's name, the size limit, and a counter of what the limit dropped.
struct RawType : ddsi_sertype {
  size_t max_bytes = 0;
  std::atomic<long long>* too_large = nullptr;
};
struct RawSample : ddsi_serdata {
  std::vector<uint8_t> bytes;  // the CDR payload, with its encapsulation header
  int64_t arrival_us = 0;      // when Cyclone's receive thread got it (wall clock)
};
struct Blob {  // what dds_write takes
  const uint8_t* data;
  size_t size;
};

RawSample* NewSample(const ddsi_sertype* type, ddsi_serdata_kind kind) {
  auto* d = new RawSample;
  ddsi_serdata_init(d, type, kind);
  return d;
}
bool TooLarge(const ddsi_sertype* type, size_t size) {
  const auto* t = static_cast<const RawType*>(type);
  if (size <= t->max_bytes) return false;
  if (t->too_large) ++*t->too_large;
  return true;
}

bool EqKey(const ddsi_serdata*, const ddsi_serdata*) { return true; }  // keyless: one instance
uint32_t GetSize(const ddsi_serdata* d) {
  return static_cast<uint32_t>(static_cast<const RawSample*>(d)->bytes.size());
}
ddsi_serdata* FromSer(const ddsi_sertype* type, ddsi_serdata_kind kind, const nn_rdata* frag, size_t size) {
  if (TooLarge(type, size)) return nullptr;  // Cyclone drops a sample it cannot deserialize
  RawSample* d = NewSample(type, kind);
  d->arrival_us = msgs::WallClockUs();
  d->bytes.resize(size);
  uint32_t off = 0;
  for (; frag; frag = frag->nextfrag) {  // fragments in order; they may overlap
    if (frag->maxp1 <= off) continue;
    const unsigned char* payload = NN_RMSG_PAYLOADOFF(frag->rmsg, NN_RDATA_PAYLOAD_OFF(frag));
    const uint32_t end = std::min<uint32_t>(frag->maxp1, static_cast<uint32_t>(size));
    if (end > off) std::memcpy(d->bytes.data() + off, payload + (off - frag->min), end - off);
    off = frag->maxp1;
  }
  return d;
}
ddsi_serdata* FromSerIov(const ddsi_sertype* type, ddsi_serdata_kind kind, ddsrt_msg_iovlen_t niov,
                         const ddsrt_iovec_t* iov, size_t size) {
  if (TooLarge(type, size)) return nullptr;
  RawSample* d = NewSample(type, kind);
  d->arrival_us = msgs::WallClockUs();
  d->bytes.reserve(size);
  for (ddsrt_msg_iovlen_t i = 0; i < niov; ++i) {
    const auto* p = static_cast<const uint8_t*>(iov[i].iov_base);
    d->bytes.insert(d->bytes.end(), p, p + iov[i].iov_len);
  }
  d->bytes.resize(size);
  return d;
}
ddsi_serdata* FromKeyhash(const ddsi_sertype* type, const ddsi_keyhash*) { return NewSample(type, SDK_KEY); }
ddsi_serdata* FromSample(const ddsi_sertype* type, ddsi_serdata_kind kind, const void* sample) {
  RawSample* d = NewSample(type, kind);
  if (kind == SDK_DATA) {
    const auto* b = static_cast<const Blob*>(sample);
    d->bytes.assign(b->data, b->data + b->size);
  }
  return d;
}
void ToSer(const ddsi_serdata* d, size_t off, size_t sz, void* buf) {
  std::memcpy(buf, static_cast<const RawSample*>(d)->bytes.data() + off, sz);
}
ddsi_serdata* ToSerRef(const ddsi_serdata* d, size_t off, size_t sz, ddsrt_iovec_t* ref) {
  ref->iov_base = const_cast<uint8_t*>(static_cast<const RawSample*>(d)->bytes.data()) + off;
  ref->iov_len = static_cast<ddsrt_iov_len_t>(sz);
  return ddsi_serdata_ref(d);
}
void ToSerUnref(ddsi_serdata* d, const ddsrt_iovec_t*) { ddsi_serdata_unref(d); }
bool ToSample(const ddsi_serdata*, void*, void**, void*) { return false; }  // samples are taken as CDR
ddsi_serdata* ToUntyped(const ddsi_serdata* d) {
  RawSample* u = NewSample(d->type, SDK_KEY);  // no key: an empty one
  u->type = nullptr;
  return u;
}
bool UntypedToSample(const ddsi_sertype*, const ddsi_serdata*, void*, void**, void*) { return true; }
void FreeSample(ddsi_serdata* d) { delete static_cast<RawSample*>(d); }
size_t Print(const ddsi_sertype*, const ddsi_serdata* d, char* buf, size_t size) {
  return static_cast<size_t>(
      std::snprintf(buf, size, "(%zu bytes of CDR)", static_cast<const RawSample*>(d)->bytes.size()));
}
void GetKeyhash(const ddsi_serdata*, ddsi_keyhash* buf, bool) { std::memset(buf, 0, sizeof *buf); }

const ddsi_serdata_ops& SerdataOps() {
  static const ddsi_serdata_ops ops = [] {
    ddsi_serdata_ops o{};
    o.eqkey = EqKey, o.get_size = GetSize, o.from_ser = FromSer, o.from_ser_iov = FromSerIov;
    o.from_keyhash = FromKeyhash, o.from_sample = FromSample, o.to_ser = ToSer, o.to_ser_ref = ToSerRef;
    o.to_ser_unref = ToSerUnref, o.to_sample = ToSample, o.to_untyped = ToUntyped;
    o.untyped_to_sample = UntypedToSample, o.free = FreeSample, o.print = Print, o.get_keyhash = GetKeyhash;
    return o;
  }();
  return ops;
}

void FreeType(ddsi_sertype* t) {
  ddsi_sertype_fini(t);
  delete static_cast<RawType*>(t);
}
void ZeroSamples(const ddsi_sertype*, void*, size_t) {}
void ReallocSamples(void** ptrs, const ddsi_sertype*, void*, size_t, size_t count) {
  for (size_t i = 0; i < count; ++i) ptrs[i] = nullptr;
}
void FreeSamples(const ddsi_sertype*, void**, size_t, dds_free_op_t) {}
bool EqualTypes(const ddsi_sertype* a, const ddsi_sertype* b) {  // names and ops already agree
  const auto* x = static_cast<const RawType*>(a);
  const auto* y = static_cast<const RawType*>(b);
  return x->max_bytes == y->max_bytes && x->too_large == y->too_large;
}
uint32_t HashType(const ddsi_sertype* t) { return static_cast<uint32_t>(static_cast<const RawType*>(t)->max_bytes); }

const ddsi_sertype_ops& SertypeOps() {
  static const ddsi_sertype_ops ops = [] {
    ddsi_sertype_ops o{};
    o.version = ddsi_sertype_v0, o.free = FreeType, o.zero_samples = ZeroSamples;
    o.realloc_samples = ReallocSamples, o.free_samples = FreeSamples, o.equal = EqualTypes, o.hash = HashType;
    return o;
  }();
  return ops;
}

dds_qos_t* QosOf(const Qos& q) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, q.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_MSECS(100));
  dds_qset_durability(qos, q.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, q.depth > 0 ? q.depth : 1);
  return qos;
}

}  // namespace

struct DdsParticipant::Impl {
  dds_entity_t domain = 0, participant = 0, waitset = 0;
  std::map<std::string, dds_entity_t> topics;  // by DDS topic name
  std::vector<dds_entity_t> readers, writers;
  std::vector<std::string> reader_topics, writer_topics;
  std::atomic<long long> too_large{0};
  size_t max_bytes = 0;

  dds_entity_t discovery = 0;  // the ros_discovery_info writer
  ~Impl() {                    // also when the constructor throws: the participant holds threads and sockets
    if (participant > 0) dds_delete(participant);
    if (domain > 0) dds_delete(domain);
  }
  std::string node_name;

  // rmw_dds_common/msg/ParticipantEntitiesInfo (Jazzy: a Gid is char[16], the entity's DDS GUID):
  // this participant, one node, the GIDs of its readers and writers.
  void Announce() {
    if (discovery <= 0) return;
    CdrWriter w;
    auto gid = [&](dds_entity_t e) {
      dds_guid_t g{};
      dds_get_guid(e, &g);
      for (uint8_t b : g.v) w.U8(b);
    };
    gid(participant);
    w.U32(1);
    w.String("/");
    w.String(node_name);
    w.U32(static_cast<uint32_t>(readers.size()));
    for (dds_entity_t r : readers) gid(r);
    w.U32(static_cast<uint32_t>(writers.size()) + 1);  // its own writer too, as rmw_cyclonedds lists it
    for (dds_entity_t x : writers) gid(x);
    gid(discovery);
    const std::vector<uint8_t>& bytes = w.bytes();
    const Blob blob{bytes.data(), bytes.size()};
    dds_write(discovery, &blob);
  }

  dds_entity_t Topic(const std::string& topic, const std::string& type, bool ros_name = true) {
    const std::string name = ros_name ? DdsTopicName(topic) : topic;
    if (auto it = topics.find(name); it != topics.end()) return it->second;
    auto* t = new RawType;
    ddsi_sertype_init_flags(t, DdsTypeName(type).c_str(), &SertypeOps(), &SerdataOps(),
                            DDSI_SERTYPE_FLAG_TOPICKIND_NO_KEY);
    t->max_bytes = max_bytes;
    t->too_large = &too_large;
    ddsi_sertype* st = t;
    const dds_entity_t e = dds_create_topic_sertype(participant, name.c_str(), &st, nullptr, nullptr, nullptr);
    if (e < 0) {
      ddsi_sertype_fini(t);
      delete t;
      throw std::runtime_error("dds: topic " + topic + " (" + name + ", " + type + "): " + dds_strretcode(e));
    }
    topics[name] = e;
    return e;
  }
};

DdsParticipant::DdsParticipant(const DdsOptions& options) : impl_(std::make_unique<Impl>()), options_(options) {
  impl_->max_bytes = options.max_sample_bytes;
  if (options.domain_id < 0 || options.domain_id > 232)
    throw std::runtime_error("dds: domain id " + std::to_string(options.domain_id) + " is outside 0..232");
  const auto domain = static_cast<dds_domainid_t>(options.domain_id);
  if (!options.config.empty()) {
    impl_->domain = dds_create_domain(domain, options.config.c_str());
    if (impl_->domain < 0)
      throw std::runtime_error("dds: domain " + std::to_string(options.domain_id) + " with config '" + options.config +
                               "': " + dds_strretcode(impl_->domain));
  }
  dds_qos_t* qos = dds_create_qos();
  const char enclave[] = "enclave=/;";  // what an rmw participant says of itself
  dds_qset_userdata(qos, enclave, sizeof enclave - 1);
  impl_->participant = dds_create_participant(domain, qos, nullptr);
  dds_delete_qos(qos);
  if (impl_->participant < 0)
    throw std::runtime_error("dds: cannot join domain " + std::to_string(options.domain_id) + ": " +
                             dds_strretcode(impl_->participant));
  impl_->waitset = dds_create_waitset(impl_->participant);
  if (!options.node_name.empty()) {
    // As rmw_cyclonedds: reliable, transient local, keep last 1, not under rt/.
    impl_->node_name = options.node_name;
    dds_qos_t* dq = QosOf({1, true, true});
    impl_->discovery = dds_create_writer(
        impl_->participant,
        impl_->Topic("ros_discovery_info", "rmw_dds_common/msg/ParticipantEntitiesInfo", /*ros_name=*/false), dq,
        nullptr);
    dds_delete_qos(dq);
    if (impl_->discovery < 0)
      throw std::runtime_error("dds: ros_discovery_info: " + std::string(dds_strretcode(impl_->discovery)));
    impl_->Announce();
  }
}

DdsParticipant::~DdsParticipant() = default;

int DdsParticipant::AddReader(const std::string& topic, const std::string& type, const Qos& q, bool dds_name) {
  dds_qos_t* qos = QosOf(q);
  dds_qset_ignorelocal(qos, DDS_IGNORELOCAL_PARTICIPANT);  // not our own writers' samples
  const dds_entity_t r = dds_create_reader(impl_->participant, impl_->Topic(topic, type, !dds_name), qos, nullptr);
  dds_delete_qos(qos);
  if (r < 0) throw std::runtime_error("dds: reader on " + topic + ": " + dds_strretcode(r));
  const dds_entity_t cond = dds_create_readcondition(r, DDS_ANY_STATE);
  dds_waitset_attach(impl_->waitset, cond, static_cast<dds_attach_t>(impl_->readers.size()));
  impl_->readers.push_back(r);
  impl_->reader_topics.push_back(topic);
  impl_->Announce();
  return static_cast<int>(impl_->readers.size()) - 1;
}

int DdsParticipant::AddWriter(const std::string& topic, const std::string& type, const Qos& q, bool dds_name) {
  dds_qos_t* qos = QosOf(q);
  dds_qset_ignorelocal(qos, DDS_IGNORELOCAL_PARTICIPANT);
  const dds_entity_t w = dds_create_writer(impl_->participant, impl_->Topic(topic, type, !dds_name), qos, nullptr);
  dds_delete_qos(qos);
  if (w < 0) throw std::runtime_error("dds: writer on " + topic + ": " + dds_strretcode(w));
  impl_->writers.push_back(w);
  impl_->writer_topics.push_back(topic);
  impl_->Announce();
  return static_cast<int>(impl_->writers.size()) - 1;
}

bool DdsParticipant::Write(int writer, const uint8_t* cdr, size_t size) {
  if (writer < 0 || writer >= static_cast<int>(impl_->writers.size())) return false;
  const Blob blob{cdr, size};
  return dds_write(impl_->writers[writer], &blob) == DDS_RETCODE_OK;
}

namespace {

// Every sample waiting on `reader` (index `index`), in batches.
void TakeAll(dds_entity_t reader, int index, const std::function<void(const DdsParticipant::Sample&)>& on_sample) {
  constexpr uint32_t kBatch = 16;
  ddsi_serdata* got[kBatch];
  dds_sample_info_t info[kBatch];
  for (;;) {
    const dds_return_t n = dds_takecdr(reader, got, kBatch, info, DDS_ANY_STATE);
    if (n <= 0) break;
    for (dds_return_t k = 0; k < n; ++k) {
      const auto* s = static_cast<const RawSample*>(got[k]);
      if (info[k].valid_data && !s->bytes.empty())
        on_sample({index, s->bytes.data(), s->bytes.size(), info[k].source_timestamp / 1000,
                   s->arrival_us ? s->arrival_us : msgs::WallClockUs()});
      ddsi_serdata_unref(got[k]);
    }
    if (static_cast<uint32_t>(n) < kBatch) break;
  }
}

}  // namespace

void DdsParticipant::Take(int timeout_ms, const std::function<void(const Sample&)>& on_sample) {
  if (impl_->readers.empty()) {
    if (timeout_ms > 0) dds_sleepfor(DDS_MSECS(timeout_ms));
    return;
  }
  if (timeout_ms > 0) dds_waitset_wait(impl_->waitset, nullptr, 0, DDS_MSECS(timeout_ms));
  for (size_t i = 0; i < impl_->readers.size(); ++i) TakeAll(impl_->readers[i], static_cast<int>(i), on_sample);
}

void DdsParticipant::TakeFrom(int reader, int timeout_ms, const std::function<void(const Sample&)>& on_sample) {
  if (timeout_ms > 0) dds_sleepfor(DDS_MSECS(timeout_ms));
  TakeAll(impl_->readers.at(reader), reader, on_sample);
}

int DdsParticipant::MatchedReaders(int writer) const {
  dds_publication_matched_status_t s{};
  if (dds_get_publication_matched_status(impl_->writers.at(writer), &s) != DDS_RETCODE_OK) return 0;
  return static_cast<int>(s.current_count);
}

int DdsParticipant::MatchedWriters(int reader) const {
  dds_subscription_matched_status_t s{};
  if (dds_get_subscription_matched_status(impl_->readers.at(reader), &s) != DDS_RETCODE_OK) return 0;
  return static_cast<int>(s.current_count);
}

long long DdsParticipant::too_large() const { return impl_->too_large.load(); }
const std::string& DdsParticipant::reader_topic(int reader) const { return impl_->reader_topics.at(reader); }
const std::string& DdsParticipant::writer_topic(int writer) const { return impl_->writer_topics.at(writer); }

}  // namespace mbot::ros2
