// Measurement tool (not a test): a Cyclone DDS subscriber written from ROS 2's message
// definitions (pipeline/publish/ros2/ros2_msgs.idl) on the domain ROS_DOMAIN_ID, as a ROS 2
// node would subscribe: reliable, keep-all readers of rt/joint_states, rt/tf,
// rt/mocap/unlabeled_markers and of every rt/mocap/<body>/pose a writer announces
// (found through DDS's built-in DCPSPublication topic, so no body list is needed). It
// takes every sample for DURATION_S seconds and prints the counts and rates, so that an
// A/B latency run (bench/foxglove/viewer_ab.sh --ros2) has a matched DDS reader of every
// topic, i.e. the tracker's DDS writers really serialise and send.
//   ros2_reader [DURATION_S=10]
#include <dds/dds.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "ros2_msgs.h"

namespace {

struct Subscription {
  std::string topic;
  dds_entity_t reader = 0;
  long long count = 0;
};

bool is_pose_topic(const std::string& t) {
  const std::string prefix = "rt/mocap/", suffix = "/pose";
  return t.size() > prefix.size() + suffix.size() && t.compare(0, prefix.size(), prefix) == 0 &&
         t.compare(t.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  const double duration_s = argc > 1 ? std::atof(argv[1]) : 10.0;
  const char* domain_env = std::getenv("ROS_DOMAIN_ID");
  const dds_domainid_t domain =
      domain_env != nullptr ? static_cast<dds_domainid_t>(std::atoi(domain_env)) : 0;
  const dds_entity_t pp = dds_create_participant(domain, nullptr, nullptr);
  if (pp < 0) {
    std::fprintf(stderr, "ros2_reader: cannot create a DDS participant on domain %u: %s\n",
                 static_cast<unsigned>(domain), dds_strretcode(pp));
    return 2;
  }
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  const auto subscribe = [&](const dds_topic_descriptor_t* type, const std::string& name) {
    const dds_entity_t topic = dds_create_topic(pp, type, name.c_str(), nullptr, nullptr);
    return Subscription{name, topic < 0 ? topic : dds_create_reader(pp, topic, qos, nullptr), 0};
  };
  std::vector<Subscription> subs = {
      subscribe(&sensor_msgs_msg_dds__JointState__desc, "rt/joint_states"),
      subscribe(&tf2_msgs_msg_dds__TFMessage__desc, "rt/tf"),
      subscribe(&sensor_msgs_msg_dds__PointCloud2__desc, "rt/mocap/unlabeled_markers")};
  const dds_entity_t publications =
      dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
  for (const Subscription& s : subs) {
    if (s.reader < 0 || publications < 0) {
      std::fprintf(stderr, "ros2_reader: cannot create the readers\n");
      return 2;
    }
  }
  std::chrono::steady_clock::time_point first{};
  bool any = false;
  const auto end = std::chrono::steady_clock::now() +
                   std::chrono::microseconds(static_cast<long long>(duration_s * 1e6));
  while (std::chrono::steady_clock::now() < end) {
    // New writers of rt/mocap/<body>/pose: subscribe once per topic.
    void* found[16] = {};
    dds_sample_info_t found_info[16];
    const dds_return_t nf = dds_take(publications, found, found_info, 16, 16);
    for (int i = 0; i < nf; ++i) {
      if (!found_info[i].valid_data) continue;
      const std::string t = static_cast<const dds_builtintopic_endpoint_t*>(found[i])->topic_name;
      bool known = !is_pose_topic(t);
      for (const Subscription& s : subs) known = known || s.topic == t;
      if (!known) subs.push_back(subscribe(&geometry_msgs_msg_dds__PoseStamped__desc, t));
    }
    if (nf > 0) dds_return_loan(publications, found, nf);
    for (Subscription& s : subs) {
      if (s.reader < 0) continue;
      void* samples[64] = {};
      dds_sample_info_t infos[64];
      const dds_return_t n = dds_take(s.reader, samples, infos, 64, 64);
      for (int i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        if (!any) first = std::chrono::steady_clock::now();
        any = true;
        ++s.count;
      }
      if (n > 0) dds_return_loan(s.reader, samples, n);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  dds_delete_qos(qos);
  const double secs =
      any ? std::chrono::duration<double>(std::chrono::steady_clock::now() - first).count() : 0.0;
  long long poses = 0;
  for (std::size_t i = 3; i < subs.size(); ++i) poses += subs[i].count;
  std::printf(
      "ros2_reader: /joint_states %lld (%.1f Hz), /tf %lld (%.1f Hz), /mocap/unlabeled_markers "
      "%lld (%.1f Hz), /mocap/<body>/pose %lld on %zu topics\n",
      subs[0].count, secs > 0 ? static_cast<double>(subs[0].count) / secs : 0.0, subs[1].count,
      secs > 0 ? static_cast<double>(subs[1].count) / secs : 0.0, subs[2].count,
      secs > 0 ? static_cast<double>(subs[2].count) / secs : 0.0, poses, subs.size() - 3);
  dds_delete(pp);
  return 0;
}
