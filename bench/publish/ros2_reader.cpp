// Measurement tool (not a test): a Cyclone DDS subscriber written from ROS 2's message
// definitions (pipeline/publish/ros2/ros2_msgs.idl) on the domain ROS_DOMAIN_ID, as a ROS 2
// node would subscribe: reliable, keep-all readers of rt/joint_states and rt/tf. It takes
// every sample for DURATION_S seconds and prints the counts and rates, so that an A/B
// latency run (bench/foxglove/viewer_ab.sh --ros2) has a matched DDS reader, i.e. the
// tracker's DDS writer really serialises and sends.
//   ros2_reader [DURATION_S=10]
#include <dds/dds.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "ros2_msgs.h"

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
  const dds_entity_t js = dds_create_reader(
      pp,
      dds_create_topic(pp, &sensor_msgs_msg_dds__JointState__desc, "rt/joint_states", nullptr,
                       nullptr),
      qos, nullptr);
  const dds_entity_t tf = dds_create_reader(
      pp, dds_create_topic(pp, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf", nullptr, nullptr), qos,
      nullptr);
  dds_delete_qos(qos);
  if (js < 0 || tf < 0) {
    std::fprintf(stderr, "ros2_reader: cannot create the readers\n");
    return 2;
  }
  long long counts[2] = {0, 0};
  std::chrono::steady_clock::time_point first{};
  bool any = false;
  const auto end = std::chrono::steady_clock::now() +
                   std::chrono::microseconds(static_cast<long long>(duration_s * 1e6));
  while (std::chrono::steady_clock::now() < end) {
    int k = 0;
    for (const dds_entity_t reader : {js, tf}) {
      void* samples[64] = {};
      dds_sample_info_t infos[64];
      const dds_return_t n = dds_take(reader, samples, infos, 64, 64);
      for (int i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        if (!any) first = std::chrono::steady_clock::now();
        any = true;
        ++counts[k];
      }
      if (n > 0) dds_return_loan(reader, samples, n);
      ++k;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const double s =
      any ? std::chrono::duration<double>(std::chrono::steady_clock::now() - first).count() : 0.0;
  std::printf("ros2_reader: /joint_states %lld (%.1f Hz), /tf %lld (%.1f Hz)\n", counts[0],
              s > 0 ? static_cast<double>(counts[0]) / s : 0.0, counts[1],
              s > 0 ? static_cast<double>(counts[1]) / s : 0.0);
  dds_delete(pp);
  return 0;
}
