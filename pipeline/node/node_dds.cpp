// Design: see node_dds.h.
#include "pipeline/node/node_dds.h"

#include <time.h>

#include <cstdlib>
#include <cstring>

#if defined(__SANITIZE_THREAD__)
// ThreadSanitizer builds: Debian's libddsc is not instrumented and hands its receive buffers
// between its threads with its own atomics, which TSan cannot see, so it reports races
// inside libddsc (ddsrt_recvmsg against the dq.builtins thread) that are not ours. Every
// binary with the camera nodes (mocap, tests/node) suppresses reports within libddsc only.
extern "C" const char* __tsan_default_suppressions() { return "race:libddsc.so\n"; }
#endif

namespace mocap::node {
namespace {

dds_qos_t* node_qos() {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, kHistoryDepth);
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  return qos;
}

Expected<dds_entity_t> check(dds_entity_t e, const std::string& who, const char* what) {
  if (e < 0) return make_error(who, what, std::string("DDS: ") + dds_strretcode(e));
  return e;
}

// The user's configuration (CYCLONEDDS_URI: files and/or XML, comma-separated), then,
// when realtime, one receive thread at SCHED_FIFO kDdsFifoPriority, and when batching,
// Internal/WriteBatch.
std::string domain_config(bool realtime, bool batch_writes) {
  std::string c;
  if (const char* uri = std::getenv("CYCLONEDDS_URI"); uri != nullptr && uri[0] != '\0')
    c = std::string(uri) + ",";
  if (realtime)
    c +=
        std::string("<Internal><MultipleReceiveThreads>false</MultipleReceiveThreads></Internal>") +
        "<Threads><Thread name=\"recv\"><Scheduling><Class>realtime</Class><Priority>" +
        std::to_string(kDdsFifoPriority) + "</Priority></Scheduling></Thread></Threads>";
  if (batch_writes) c += "<Internal><WriteBatch>true</WriteBatch></Internal>";
  return c;
}

}  // namespace

Expected<NodeDomain> NodeDomain::open(std::uint32_t domain_id, const std::string& who,
                                      bool realtime, bool batch_writes) {
  if (domain_id > 232) return make_error(who, "node.domain_id", "must be in 0..232");
  NodeDomain d;
  const dds_entity_t dom =
      realtime || batch_writes
          ? dds_create_domain(domain_id, domain_config(realtime, batch_writes).c_str())
          : dds_entity_t{0};
  // PRECONDITION_NOT_MET: this process has the domain already (joined below as it is).
  if (dom < 0 && dom != DDS_RETCODE_PRECONDITION_NOT_MET)
    return make_error(who, "dds_create_domain", std::string("DDS: ") + dds_strretcode(dom));
  d.participant_ = dds_create_participant(domain_id, nullptr, nullptr);
  if (auto r = check(d.participant_, who, "dds_create_participant"); !r) {
    d.participant_ = 0;
    if (dom > 0) dds_delete(dom);
    return r.error();
  }
  d.blob_topic_ =
      dds_create_topic(d.participant_, &mocap_node_BlobFrame_desc, kBlobTopic, nullptr, nullptr);
  if (auto r = check(d.blob_topic_, who, kBlobTopic); !r) return r.error();
  d.trigger_topic_ =
      dds_create_topic(d.participant_, &mocap_node_Trigger_desc, kTriggerTopic, nullptr, nullptr);
  if (auto r = check(d.trigger_topic_, who, kTriggerTopic); !r) return r.error();
  return d;
}

NodeDomain& NodeDomain::operator=(NodeDomain&& o) noexcept {
  if (this != &o) {
    close();
    participant_ = o.participant_;
    blob_topic_ = o.blob_topic_;
    trigger_topic_ = o.trigger_topic_;
    o.participant_ = o.blob_topic_ = o.trigger_topic_ = 0;
  }
  return *this;
}

NodeDomain::~NodeDomain() { close(); }

void NodeDomain::close() noexcept {
  if (participant_ <= 0) return;
  const dds_entity_t domain = dds_get_parent(participant_);
  dds_delete(participant_);
  participant_ = blob_topic_ = trigger_topic_ = 0;
  // An implicit domain went with its last participant; one created by open() (realtime)
  // stays until deleted: by whoever closes its last participant (0 children left).
  if (domain > 0 && dds_get_children(domain, nullptr, 0) == 0) dds_delete(domain);
}

Expected<dds_entity_t> NodeDomain::writer(dds_entity_t topic, const std::string& who) const {
  dds_qos_t* qos = node_qos();
  const dds_entity_t w = dds_create_writer(participant_, topic, qos, nullptr);
  dds_delete_qos(qos);
  return check(w, who, "dds_create_writer");
}

Expected<dds_entity_t> NodeDomain::reader(dds_entity_t topic, const std::string& who) const {
  dds_qos_t* qos = node_qos();
  const dds_entity_t r = dds_create_reader(participant_, topic, qos, nullptr);
  dds_delete_qos(qos);
  return check(r, who, "dds_create_reader");
}

void to_sample(const WireHeader& h, mocap_node_BlobFrame& s) noexcept {
  static_assert(sizeof(s.node) == kNameBytes && sizeof(s.camera) == kNameBytes,
                "node_msgs.idl string<63> matches kNameBytes");
  std::memcpy(s.node, h.node, kNameBytes);
  std::memcpy(s.camera, h.camera, kNameBytes);
  s.node[kNameBytes - 1] = '\0';
  s.camera[kNameBytes - 1] = '\0';
  s.version = h.version;
  s.flags = h.flags;
  s.frame_number = h.frame_number;
  s.capture_ns = h.capture_ns;
  s.trigger_sent_ns = h.trigger_sent_ns;
  s.trigger_received_ns = h.trigger_received_ns;
  s.sent_ns = h.sent_ns;
  s.detected_ns = h.detected_ns;
  s.realtime_offset_ns = h.realtime_offset_ns;
  s.frames = h.health.frames;
  s.camera_dropped = h.health.camera_dropped;
  s.queue_dropped = h.health.queue_dropped;
  s.detect_overflow = h.health.detect_overflow;
  s.timeouts = h.health.timeouts;
  s.background_dn = h.background_dn;
  s.noise_dn = h.noise_dn;
  s.threshold_dn = h.threshold_dn;
  s.blob_count = h.blob_count;
}

void from_sample(const mocap_node_BlobFrame& s, WireHeader& h) noexcept {
  std::memcpy(h.node, s.node, kNameBytes);  // checked by check_header (NUL within bound)
  std::memcpy(h.camera, s.camera, kNameBytes);
  h.version = s.version;
  h.flags = s.flags;
  h.frame_number = s.frame_number;
  h.capture_ns = s.capture_ns;
  h.trigger_sent_ns = s.trigger_sent_ns;
  h.trigger_received_ns = s.trigger_received_ns;
  h.sent_ns = s.sent_ns;
  h.detected_ns = s.detected_ns;
  h.realtime_offset_ns = s.realtime_offset_ns;
  h.health = {s.frames, s.camera_dropped, s.queue_dropped, s.detect_overflow, s.timeouts};
  h.background_dn = s.background_dn;
  h.noise_dn = s.noise_dn;
  h.threshold_dn = s.threshold_dn;
  h.blob_count = s.blob_count;
}

std::int64_t realtime_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace mocap::node
