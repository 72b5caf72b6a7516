// Design: the ROS 2 output over DDS (docs/ros2.md; spec "ROS 2"): a QueuedSink, so that
// the DDS serialisation and writes run on its own worker thread, never on the real-time
// publish thread. Eclipse Cyclone DDS's C API with the types of ros2_msgs.idl (ROS 2's
// message definitions in ROS 2's DDS names), in ROS 2's wire conventions:
//   rt/joint_states  sensor_msgs::msg::dds_::JointState_  one entry per VALID joint DOF,
//                    named as the URDF of `mocap calibrate --urdf` (ros2_mapping.h),
//                    position in radians (the datagram's float angles, widened),
//                    velocity in rad/s (the tracker's causal rates; NaN for a DOF
//                    whose rate is not known yet, the two frames after it was found);
//   rt/tf            tf2_msgs::msg::dds_::TFMessage_      one transform per body found,
//                    frame_id "mocap", child_frame_id the body name, metres;
//   rt/robot_description std_msgs::msg::dds_::String_     the URDF of the joint model,
//                    once at start, transient local (late joiners get it), when a
//                    calibrated model is loaded.
// QoS: ROS 2's default (reliable, keep last 10, volatile); robot_description: reliable,
// keep last 1, transient local (as robot_state_publisher publishes it). Domain:
// ROS_DOMAIN_ID (default 0), or the request option domain_id (outputs.ros2.domain_id).
// header.stamp: the frame's capture time (CLOCK_MONOTONIC) + the CLOCK_REALTIME offset
// measured at start. The message buffers are built once; encode() only fills them.
// Missing DDS at runtime (no participant): no sink, one notice line; tracker continues.
#include <dds/dds.h>

#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "kinematics/urdf_writer.h"
#include "pipeline/publish/output_registry.h"
#include "pipeline/publish/queued_sink.h"
#include "pipeline/publish/ros2/ros2_mapping.h"
#include "ros2_msgs.h"

namespace mocap::publish {
namespace {

constexpr int kQueueDepth = 8;  // frames waiting for the worker (drop-oldest beyond)
constexpr const char* kParentFrame = "mocap";

class Ros2Sink final : public QueuedSink {
 public:
  Ros2Sink() : QueuedSink(kQueueDepth) {}
  ~Ros2Sink() override {
    stop();                                          // the worker must be gone before the entities
    if (participant_ > 0) dds_delete(participant_);  // deletes every child entity
  }
  const char* name() const noexcept override { return "ros2"; }

  // Setup: participant, topics, writers, buffers. Not an Error: DDS missing at runtime.
  std::string open(std::uint32_t domain, const OutputContext& ctx) {
    participant_ = dds_create_participant(domain, nullptr, nullptr);
    if (participant_ < 0)
      return std::string("ros2: DDS unavailable (dds_create_participant: ") +
             dds_strretcode(participant_) + "); continuing without ROS 2 output";
    dds_qos_t* qos = dds_create_qos();  // ROS 2 default: reliable, keep last 10, volatile
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
    const dds_entity_t js_topic = dds_create_topic(
        participant_, &sensor_msgs_msg_dds__JointState__desc, "rt/joint_states", nullptr, nullptr);
    const dds_entity_t tf_topic = dds_create_topic(participant_, &tf2_msgs_msg_dds__TFMessage__desc,
                                                   "rt/tf", nullptr, nullptr);
    joint_states_ =
        js_topic < 0 ? js_topic : dds_create_writer(participant_, js_topic, qos, nullptr);
    tf_ = tf_topic < 0 ? tf_topic : dds_create_writer(participant_, tf_topic, qos, nullptr);
    dds_delete_qos(qos);
    if (joint_states_ < 0 || tf_ < 0)
      return std::string("ros2: cannot create the DDS writers (") +
             dds_strretcode(joint_states_ < 0 ? joint_states_ : tf_) +
             "); continuing without ROS 2 output";
    if (ctx.targets != nullptr)
      for (const MarkerTarget& b : ctx.targets->bodies) bodies_.push_back(b.name);
    if (ctx.model != nullptr) dofs_ = ros2::joint_dofs(*ctx.model, client::kMaxJoints);
    build_buffers();
    offset_ns_ = ros2::realtime_offset_ns();
    if (ctx.model != nullptr && ctx.targets != nullptr)
      publish_description(*ctx.model, *ctx.targets);
    return {};
  }

 protected:
  void encode(const FrameResult& f) override {
    const ros2::Stamp stamp = ros2::to_stamp(f.joints.capture_ns, offset_ns_);
    // /joint_states: the valid DOFs only.
    std::uint32_t n = 0;
    for (std::size_t i = 0; i < dofs_.size(); ++i) {
      const ros2::JointDof& d = dofs_[i];
      if (d.joint >= f.joints.joint_count) continue;
      const client::JointRecord& r = f.joints.joints[d.joint];
      if (r.valid == 0) continue;
      name_ptrs_[n] = const_cast<char*>(dofs_[i].name.c_str());  // DDS only reads
      positions_[n] = static_cast<double>(r.a[d.component]);
      const client::JointRates& rates = f.joints.rates[d.joint];
      velocities_[n] = rates.valid ? static_cast<double>(rates.rate_rad_s[d.component])
                                   : std::numeric_limits<double>::quiet_NaN();
      ++n;
    }
    if (n > 0) {
      sensor_msgs_msg_dds__JointState_ js{};
      js.header.stamp.sec = stamp.sec;
      js.header.stamp.nanosec = stamp.nanosec;
      js.header.frame_id = const_cast<char*>("");
      js.name._length = js.name._maximum = n;
      js.name._buffer = name_ptrs_.data();
      js.position._length = js.position._maximum = n;
      js.position._buffer = positions_.data();
      js.velocity._length = js.velocity._maximum = n;
      js.velocity._buffer = velocities_.data();
      if (const dds_return_t rc = dds_write(joint_states_, &js); rc < 0)
        throw std::runtime_error(dds_strretcode(rc));
    }
    // /tf: one transform per body found.
    std::uint32_t t = 0;
    for (int b = 0; b < f.body_count && b < static_cast<int>(bodies_.size()); ++b) {
      const ResultBody& body = f.bodies[static_cast<std::size_t>(b)];
      if (body.found == 0) continue;
      geometry_msgs_msg_dds__TransformStamped_& ts = transforms_[t++];
      ts.header.stamp.sec = stamp.sec;
      ts.header.stamp.nanosec = stamp.nanosec;
      ts.header.frame_id = const_cast<char*>(kParentFrame);
      ts.child_frame_id = const_cast<char*>(bodies_[static_cast<std::size_t>(b)].c_str());
      ts.transform.translation.x = body.t_world_body_mm[0] * 1e-3;
      ts.transform.translation.y = body.t_world_body_mm[1] * 1e-3;
      ts.transform.translation.z = body.t_world_body_mm[2] * 1e-3;
      ts.transform.rotation.w = body.q_world_body[0];
      ts.transform.rotation.x = body.q_world_body[1];
      ts.transform.rotation.y = body.q_world_body[2];
      ts.transform.rotation.z = body.q_world_body[3];
    }
    if (t > 0) {
      tf2_msgs_msg_dds__TFMessage_ tf{};
      tf.transforms._length = tf.transforms._maximum = t;
      tf.transforms._buffer = transforms_.data();
      if (const dds_return_t rc = dds_write(tf_, &tf); rc < 0)
        throw std::runtime_error(dds_strretcode(rc));
    }
  }

 private:
  void build_buffers() {
    name_ptrs_.assign(dofs_.size() + 1, nullptr);
    positions_.assign(dofs_.size() + 1, 0.0);
    velocities_.assign(dofs_.size() + 1, 0.0);
    transforms_.assign(bodies_.size() + 1, geometry_msgs_msg_dds__TransformStamped_{});
  }

  void publish_description(const JointModel& model, const TargetSet& targets) {
    auto urdf = kinematics::make_urdf(model, "mocap_robot", targets.bodies.size());
    if (!urdf) return;  // an uncalibrated model has no URDF: nothing to describe
    urdf_ = std::move(urdf).value();
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
    const dds_entity_t topic = dds_create_topic(participant_, &std_msgs_msg_dds__String__desc,
                                                "rt/robot_description", nullptr, nullptr);
    if (topic >= 0) description_ = dds_create_writer(participant_, topic, qos, nullptr);
    dds_delete_qos(qos);
    if (description_ <= 0) return;
    std_msgs_msg_dds__String_ s{};
    s.data = urdf_.data();
    (void)dds_write(description_, &s);
  }

  dds_entity_t participant_ = 0, joint_states_ = 0, tf_ = 0, description_ = 0;
  std::vector<std::string> bodies_;
  std::vector<ros2::JointDof> dofs_;
  std::vector<char*> name_ptrs_;
  std::vector<double> positions_;
  std::vector<double> velocities_;
  std::vector<geometry_msgs_msg_dds__TransformStamped_> transforms_;
  std::string urdf_;
  std::int64_t offset_ns_ = 0;
};

Expected<std::uint32_t> domain_of(const OutputRequest& r) {
  if (const std::string* d = r.option("domain_id")) {
    auto id = ros2::parse_domain_id(d->c_str());
    if (!id || d->empty())
      return make_error(r.where, "domain_id", "expected an integer in 0..232, got '" + *d + "'");
    return id;
  }
  return ros2::parse_domain_id(std::getenv("ROS_DOMAIN_ID"));
}

Expected<void> check_ros2(const OutputRequest& r) {
  auto on = request_flag(r);
  if (!on) return on.error();
  if (*on) {
    if (auto d = domain_of(r); !d) return d.error();
  }
  return {};
}

Expected<OutputCreated> create_ros2(const OutputRequest& r, const OutputContext& ctx) {
  OutputCreated out;
  auto on = request_flag(r);
  if (!on) return on.error();
  if (!*on) return out;
  auto domain = domain_of(r);
  if (!domain) return domain.error();
  auto sink = std::make_unique<Ros2Sink>();
  out.notice = sink->open(*domain, ctx);
  if (!out.notice.empty()) return out;
  if (auto s = sink->start(); !s) return s.error();
  out.sink = std::move(sink);
  return out;
}

}  // namespace

extern const OutputKind kRos2Output;
const OutputKind kRos2Output{"ros2", "ROS 2 /joint_states and /tf over DDS (Cyclone DDS)",
                             "domain_id", &check_ros2, &create_ros2};

}  // namespace mocap::publish
