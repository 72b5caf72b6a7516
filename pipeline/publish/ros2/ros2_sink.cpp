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
//   rt/mocap/<body>/pose geometry_msgs::msg::dds_::PoseStamped_  per body found, one
//                    writer per body made at setup (name as a ROS topic token,
//                    ros2_mapping.h), frame "mocap", metres: the same pose as /tf;
//   rt/mocap/<body>/twist geometry_msgs::msg::dds_::TwistStamped_  per body found whose
//                    velocities are known (kinematics/body_rates.h): the origin's
//                    linear (m/s) and the angular (rad/s) velocity in the same frame;
//   rt/mocap/unlabeled_markers sensor_msgs::msg::dds_::PointCloud2_  every frame: the
//                    3D points no body claimed, x y z float32 in metres (height 1);
//   rt/robot_description std_msgs::msg::dds_::String_     the URDF of the joint model,
//                    once at start, transient local (late joiners get it), when a
//                    calibrated model is loaded.
// QoS: ROS 2's default (reliable, keep last 10, volatile); robot_description: reliable,
// keep last 1, transient local (as robot_state_publisher publishes it). Domain:
// ROS_DOMAIN_ID (default 0), or the request option domain_id (outputs.ros2.domain_id).
// Options frame_id (replaces "mocap" as the parent frame of /tf, the poses and the
// cloud) and world_rotation (a fixed rotation from mocap's world to that frame, applied
// to /tf, the poses, the twists and the cloud alike; joint angles are relative and stay as they are).
// header.stamp: the frame's capture time (CLOCK_MONOTONIC) + the CLOCK_REALTIME offset
// measured at start. The message buffers are built once; encode() only fills them (the
// DDS sequences point into them: no allocation of ours per frame).
// Missing DDS at runtime (no participant): no sink, one notice line; tracker continues.
#include <dds/dds.h>

#include <array>
#include <bit>
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

struct Ros2Settings {
  std::uint32_t domain = 0;
  std::string frame_id = "mocap";  // the contract's default
  ros2::WorldRotation rotation;
  std::vector<std::string> bodies;       // targets.yaml order
  std::vector<std::string> pose_topics;  // "rt/mocap/<token>/pose" per body
};

class Ros2Sink final : public QueuedSink {
 public:
  explicit Ros2Sink(Ros2Settings settings)
      : QueuedSink(kQueueDepth), settings_(std::move(settings)) {}
  ~Ros2Sink() override {
    stop();                                          // the worker must be gone before the entities
    if (participant_ > 0) dds_delete(participant_);  // deletes every child entity
  }
  const char* name() const noexcept override { return "ros2"; }

  // Setup: participant, topics, writers, buffers. Not an Error: DDS missing at runtime.
  std::string open(const OutputContext& ctx) {
    participant_ = dds_create_participant(settings_.domain, nullptr, nullptr);
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
    const dds_entity_t cloud_topic =
        dds_create_topic(participant_, &sensor_msgs_msg_dds__PointCloud2__desc,
                         "rt/mocap/unlabeled_markers", nullptr, nullptr);
    joint_states_ = writer(js_topic, qos);
    tf_ = writer(tf_topic, qos);
    cloud_ = writer(cloud_topic, qos);
    dds_entity_t failed = joint_states_ < 0 ? joint_states_ : tf_ < 0 ? tf_ : cloud_;
    for (std::size_t b = 0; b < settings_.pose_topics.size() && failed >= 0; ++b) {
      const dds_entity_t t =
          dds_create_topic(participant_, &geometry_msgs_msg_dds__PoseStamped__desc,
                           settings_.pose_topics[b].c_str(), nullptr, nullptr);
      poses_.push_back(writer(t, qos));
      failed = poses_.back();
      if (failed < 0) break;
      // "rt/mocap/<token>/pose" -> ".../twist": the same body's velocities.
      const std::string& pose = settings_.pose_topics[b];
      const std::string twist = pose.substr(0, pose.size() - 4) + "twist";
      const dds_entity_t tw = dds_create_topic(
          participant_, &geometry_msgs_msg_dds__TwistStamped__desc, twist.c_str(), nullptr, nullptr);
      twists_.push_back(writer(tw, qos));
      failed = twists_.back();
    }
    dds_delete_qos(qos);
    if (failed < 0)
      return std::string("ros2: cannot create the DDS writers (") + dds_strretcode(failed) +
             "); continuing without ROS 2 output";
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
      ts.header.frame_id = frame_id();
      ts.child_frame_id = const_cast<char*>(bodies_[static_cast<std::size_t>(b)].c_str());
      const ros2::PoseOut p = ros2::published_pose(body, settings_.rotation);
      ts.transform.translation.x = p.t_m[0];
      ts.transform.translation.y = p.t_m[1];
      ts.transform.translation.z = p.t_m[2];
      ts.transform.rotation.w = p.q[0];
      ts.transform.rotation.x = p.q[1];
      ts.transform.rotation.y = p.q[2];
      ts.transform.rotation.z = p.q[3];
      // /mocap/<body>/pose: the same pose, one message per body found.
      geometry_msgs_msg_dds__PoseStamped_ ps{};
      ps.header = ts.header;
      ps.pose.position.x = p.t_m[0];
      ps.pose.position.y = p.t_m[1];
      ps.pose.position.z = p.t_m[2];
      ps.pose.orientation = ts.transform.rotation;
      if (const dds_return_t rc = dds_write(poses_[static_cast<std::size_t>(b)], &ps); rc < 0)
        throw std::runtime_error(dds_strretcode(rc));
      // /mocap/<body>/twist: when the body's velocities are known.
      if (body.velocity_valid == 0) continue;
      const ros2::TwistOut v = ros2::published_twist(body, settings_.rotation);
      geometry_msgs_msg_dds__TwistStamped_ tw{};
      tw.header = ts.header;
      tw.twist.linear = {v.v_m_s[0], v.v_m_s[1], v.v_m_s[2]};
      tw.twist.angular = {v.w_rad_s[0], v.w_rad_s[1], v.w_rad_s[2]};
      if (const dds_return_t rc = dds_write(twists_[static_cast<std::size_t>(b)], &tw); rc < 0)
        throw std::runtime_error(dds_strretcode(rc));
    }
    if (t > 0) {
      tf2_msgs_msg_dds__TFMessage_ tf{};
      tf.transforms._length = tf.transforms._maximum = t;
      tf.transforms._buffer = transforms_.data();
      if (const dds_return_t rc = dds_write(tf_, &tf); rc < 0)
        throw std::runtime_error(dds_strretcode(rc));
    }
    // /mocap/unlabeled_markers: every frame (an empty cloud says "none").
    const std::uint32_t n_points = ros2::pack_unlabelled(f, settings_.rotation, cloud_data_.data());
    sensor_msgs_msg_dds__PointCloud2_ pc{};
    pc.header.stamp.sec = stamp.sec;
    pc.header.stamp.nanosec = stamp.nanosec;
    pc.header.frame_id = frame_id();
    pc.height = 1;
    pc.width = n_points;
    pc.fields._length = pc.fields._maximum = static_cast<std::uint32_t>(cloud_fields_.size());
    pc.fields._buffer = cloud_fields_.data();
    pc.is_bigendian = std::endian::native == std::endian::big;
    pc.point_step = ros2::kCloudPointStep;
    pc.row_step = ros2::kCloudPointStep * n_points;
    pc.data._length = pc.data._maximum = pc.row_step;
    pc.data._buffer = cloud_data_.data();
    pc.is_dense = true;  // no invalid (NaN) points
    if (const dds_return_t rc = dds_write(cloud_, &pc); rc < 0)
      throw std::runtime_error(dds_strretcode(rc));
  }

 private:
  void build_buffers() {
    name_ptrs_.assign(dofs_.size() + 1, nullptr);
    positions_.assign(dofs_.size() + 1, 0.0);
    velocities_.assign(dofs_.size() + 1, 0.0);
    transforms_.assign(bodies_.size() + 1, geometry_msgs_msg_dds__TransformStamped_{});
    cloud_data_.assign(static_cast<std::size_t>(kMaxResultPoints) * ros2::kCloudPointStep, 0);
    static const char* const kXyz[3] = {"x", "y", "z"};
    for (std::uint32_t k = 0; k < 3; ++k) {
      sensor_msgs_msg_dds__PointField_& pf = cloud_fields_[k];
      pf.name = const_cast<char*>(kXyz[k]);  // DDS only reads
      pf.offset = 4 * k;
      pf.datatype = ros2::kPointFieldFloat32;
      pf.count = 1;
    }
  }

  dds_entity_t writer(dds_entity_t topic, const dds_qos_t* qos) {
    return topic < 0 ? topic : dds_create_writer(participant_, topic, qos, nullptr);
  }
  char* frame_id() { return settings_.frame_id.data(); }  // DDS only reads

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

  Ros2Settings settings_;
  dds_entity_t participant_ = 0, joint_states_ = 0, tf_ = 0, cloud_ = 0, description_ = 0;
  std::vector<dds_entity_t> poses_;   // per body, targets.yaml order
  std::vector<dds_entity_t> twists_;  // per body, targets.yaml order
  const std::vector<std::string>& bodies_ = settings_.bodies;
  std::array<sensor_msgs_msg_dds__PointField_, 3> cloud_fields_{};
  std::vector<std::uint8_t> cloud_data_;
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

// The request's settings without the bodies (validated: one line naming the key).
Expected<Ros2Settings> settings_of(const OutputRequest& r) {
  Ros2Settings s;
  if (const std::string* f = r.option("frame_id")) {
    if (auto c = ros2::check_frame_id(*f, r.where); !c) return c.error();
    s.frame_id = *f;
  }
  if (const std::string* w = r.option("world_rotation")) {
    auto rot = ros2::parse_world_rotation(*w, r.where);
    if (!rot) return rot.error();
    s.rotation = *rot;
  }
  return s;
}

Expected<void> check_ros2(const OutputRequest& r) {
  auto on = request_flag(r);
  if (!on) return on.error();
  if (auto s = settings_of(r); !s) return s.error();
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
  auto settings = settings_of(r);
  if (!settings) return settings.error();
  auto domain = domain_of(r);
  if (!domain) return domain.error();
  settings->domain = *domain;
  if (ctx.targets != nullptr)
    for (const MarkerTarget& b : ctx.targets->bodies) settings->bodies.push_back(b.name);
  auto topics = ros2::pose_topics(settings->bodies);
  if (!topics) return topics.error();
  settings->pose_topics = std::move(topics).value();
  auto sink = std::make_unique<Ros2Sink>(std::move(settings).value());
  out.notice = sink->open(ctx);
  if (!out.notice.empty()) return out;
  if (auto s = sink->start(); !s) return s.error();
  out.sink = std::move(sink);
  return out;
}

}  // namespace

extern const OutputKind kRos2Output;
const OutputKind kRos2Output{"ros2",
                             "ROS 2 /joint_states, /tf, /mocap/<body>/pose and "
                             "/mocap/unlabeled_markers over DDS (Cyclone DDS)",
                             "domain_id frame_id world_rotation", &check_ros2, &create_ros2};

}  // namespace mocap::publish
