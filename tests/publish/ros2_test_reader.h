// Test support of the ROS 2 output's tests (test_ros2*.cpp): an independent Cyclone DDS
// subscriber written against the ROS 2 IDL (pipeline/publish/ros2/ros2_msgs.idl) with
// ROS 2's names, as a ROS 2 node subscribes: reliable, keep-all readers of
// rt/joint_states, rt/tf, rt/mocap/unlabeled_markers, rt/mocap/<body>/pose and /twist for the
// bodies asked for, and rt/robot_description (transient local); helpers that take every
// sample or one; a DDS domain of its own per test process; the 3-body arm fixture and
// the registry's "ros2" sink on a domain with extra options.
#pragma once

#include <dds/dds.h>
#include <gtest/gtest.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/publish/output_registry.h"
#include "ros2_msgs.h"

namespace mocap::publish::ros2_test {

inline std::int64_t now_ns(clockid_t c) {
  timespec ts{};
  clock_gettime(c, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// A domain of its own per process (and per test: offset), to avoid cross-talk.
inline std::uint32_t test_domain(int offset) {
  return static_cast<std::uint32_t>(100 + (::getpid() * 3 + offset) % 120);
}

class Reader {
 public:
  // `pose_bodies`: the ROS topic tokens of the bodies whose /mocap/<body>/pose to read.
  explicit Reader(std::uint32_t domain, const std::vector<std::string>& pose_bodies = {}) {
    participant_ = dds_create_participant(domain, nullptr, nullptr);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    js_ = reader(qos, &sensor_msgs_msg_dds__JointState__desc, "rt/joint_states");
    tf_ = reader(qos, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf");
    cloud_ = reader(qos, &sensor_msgs_msg_dds__PointCloud2__desc, "rt/mocap/unlabeled_markers");
    for (const std::string& b : pose_bodies) {
      const std::string topic = "rt/mocap/" + b + "/pose";
      poses_.push_back(reader(qos, &geometry_msgs_msg_dds__PoseStamped__desc, topic.c_str()));
      const std::string twist = "rt/mocap/" + b + "/twist";
      twists_.push_back(
          reader(qos, &geometry_msgs_msg_dds__TwistStamped__desc, twist.c_str()));
    }
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
    desc_ = reader(qos, &std_msgs_msg_dds__String__desc, "rt/robot_description");
    dds_delete_qos(qos);
  }
  ~Reader() {
    if (participant_ > 0) dds_delete(participant_);
  }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  bool ok() const {
    bool ok = participant_ > 0 && js_ > 0 && tf_ > 0 && cloud_ > 0 && desc_ > 0;
    for (const dds_entity_t p : poses_) ok = ok && p > 0;
    for (const dds_entity_t t : twists_) ok = ok && t > 0;
    return ok;
  }
  // Waits until every data reader matched a writer (robot_description only when asked:
  // the sink writes it only with a calibrated model).
  bool wait_matched(bool description = false) {
    for (int i = 0; i < 500; ++i) {
      bool all =
          matched(js_) && matched(tf_) && matched(cloud_) && (!description || matched(desc_));
      for (const dds_entity_t p : poses_) all = all && matched(p);
      for (const dds_entity_t t : twists_) all = all && matched(t);
      if (all) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  dds_entity_t js_ = 0, tf_ = 0, cloud_ = 0, desc_ = 0;
  std::vector<dds_entity_t> poses_;   // in the order of `pose_bodies`
  std::vector<dds_entity_t> twists_;  // rt/mocap/<body>/twist, likewise

 private:
  static bool matched(dds_entity_t reader) {
    dds_subscription_matched_status_t s{};
    dds_get_subscription_matched_status(reader, &s);
    return s.current_count > 0;
  }
  dds_entity_t reader(const dds_qos_t* qos, const dds_topic_descriptor_t* d, const char* name) {
    const dds_entity_t t = dds_create_topic(participant_, d, name, nullptr, nullptr);
    return t < 0 ? t : dds_create_reader(participant_, t, qos, nullptr);
  }
  dds_entity_t participant_ = 0;
};

// Every sample waiting on `reader`; the loans go to `loans` (return them with
// dds_return_loan(reader, loans.data(), n)).
template <class T>
std::vector<T*> take_all(dds_entity_t reader, std::vector<void*>& loans) {
  std::vector<T*> out;
  void* samples[64];
  dds_sample_info_t infos[64];
  for (;;) {
    for (void*& s : samples) s = nullptr;
    const dds_return_t n = dds_take(reader, samples, infos, 64, 64);
    if (n <= 0) break;
    for (int i = 0; i < n; ++i) {
      if (infos[i].valid_data) out.push_back(static_cast<T*>(samples[i]));
      loans.push_back(samples[i]);
    }
    if (n < 64) break;
  }
  return out;
}

// One sample of `reader` (waits up to 3 s); the loan is returned by the caller.
template <class T>
T* take_one(dds_entity_t reader, void*& loan) {
  for (int i = 0; i < 300; ++i) {
    void* samples[1] = {nullptr};
    dds_sample_info_t info[1];
    if (dds_take(reader, samples, info, 1, 1) == 1) {
      loan = samples[0];
      if (info[0].valid_data) return static_cast<T*>(samples[0]);
      dds_return_loan(reader, samples, 1);
      continue;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return nullptr;
}

// Three bodies (torso, upper_arm, forearm), a ball shoulder and a hinge elbow.
struct ArmFixture {
  TargetSet targets;
  JointModel model;
  ArmFixture() {
    for (const char* n : {"torso", "upper_arm", "forearm"}) {
      MarkerTarget t;
      t.name = n;
      t.markers_body = {Vec3(0, 0, 0), Vec3(50, 0, 0), Vec3(0, 60, 0)};
      targets.bodies.push_back(t);
    }
    JointSpec shoulder;
    shoulder.name = "shoulder";
    shoulder.type = JointType::kBall;
    shoulder.parent = "torso";
    shoulder.child = "upper_arm";
    shoulder.parent_index = 0;
    shoulder.child_index = 1;
    JointSpec elbow = shoulder;
    elbow.name = "elbow";
    elbow.type = JointType::kHinge;
    elbow.parent = "upper_arm";
    elbow.child = "forearm";
    elbow.parent_index = 1;
    elbow.child_index = 2;
    model.joints = {shoulder, elbow};
  }
};

// The registry's "ros2" sink on `domain` with `options` added (null on failure, reported).
inline std::unique_ptr<OutputSink> make_sink(
    std::uint32_t domain, const TargetSet& targets, const JointModel* model,
    std::vector<std::pair<std::string, std::string>> options = {}) {
  OutputContext ctx;
  ctx.targets = &targets;
  ctx.model = model;
  options.emplace_back("domain_id", std::to_string(domain));
  auto outs = create_outputs({{"ros2", {"true"}, "test: outputs.ros2", options}}, ctx);
  if (!outs.ok() || outs->sinks.size() != 1) {
    ADD_FAILURE() << (outs.ok() ? "no sink: " + (outs->notices.empty() ? "" : outs->notices[0])
                                : outs.error().message);
    return nullptr;
  }
  return std::move(outs->sinks[0]);
}

}  // namespace mocap::publish::ros2_test
