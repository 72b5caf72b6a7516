// Design: tests of tracker-side latency compensation (pipeline/publish/lead.h): a ball
// joint's Euler angles and quaternion and a hinge's continuous angle and quaternion
// predicted to publish + lead from the message's rates (the hinge quaternion checked
// against the convention R_rel(theta) = AngleAxis(theta, axis_parent) R0 of the angle
// solver), sds grown as client::predict grows them, joints without rates published as
// measured, a capture beyond the horizon not predicted, setup errors naming the key, the
// flag and lead carried by datagram v1/v2 through encode/decode, the udp output sending
// the predicted state only to the destinations with a lead, and no allocation.
#include <gtest/gtest.h>

#include <cmath>

#include "client/datagram.h"
#include "client/predict.h"
#include "client/udp_receiver.h"
#include "core/rotation.h"
#include "pipeline/publish/lead.h"
#include "pipeline/publish/output_registry.h"
#include "tests/support/alloc_counter.h"

namespace mocap::publish {
namespace {

const Vec3 kHingeAxis = Vec3(0.2, -0.5, 0.8).normalized();

JointModel ball_and_hinge() {
  JointModel m;
  m.joints.resize(2);
  m.joints[0].name = "shoulder";
  m.joints[0].type = JointType::kBall;
  m.joints[1].name = "elbow";
  m.joints[1].type = JointType::kHinge;
  m.joints[1].axis_parent = kHingeAxis;
  return m;
}

Mat3 hinge_rotation(double theta) {
  const Mat3 R0 = euler_xyz_to_rotation(Vec3(0.3, 0.1, -0.4));
  return Eigen::AngleAxisd(theta, kHingeAxis).toRotationMatrix() * R0;
}

void set_q(client::JointRecord& r, const Mat3& R) {
  const Quat q = canonical_quat(R);
  r.q[0] = static_cast<float>(q.w());
  r.q[1] = static_cast<float>(q.x());
  r.q[2] = static_cast<float>(q.y());
  r.q[3] = static_cast<float>(q.z());
}

// Captured at 1 s, published 2 ms later: ball, hinge near +pi, and a joint without rates.
client::JointsMessage message() {
  client::JointsMessage m;
  m.sequence = 7;
  m.capture_ns = 1'000'000'000;
  m.publish_ns = m.capture_ns + 2'000'000;
  m.joint_count = 3;
  const Vec3 a(0.3, -0.2, 0.5);
  m.joints[0] = {0, 0, 1, {0.3f, -0.2f, 0.5f}, {}};
  set_q(m.joints[0], euler_xyz_to_rotation(a));
  m.quality[0] = {1, {}, {0.001f, 0.002f, 0.003f}};
  m.rates[0] = {1, {}, {1.0f, -2.0f, 0.5f}, {0.1f, 0.2f, 0.3f}};
  m.joints[1] = {1, 1, 1, {3.1f, 0.0f, 0.0f}, {}};
  set_q(m.joints[1], hinge_rotation(3.1));
  m.quality[1] = {2, {}, {0.002f, 0.0f, 0.0f}};
  m.rates[1] = {1, {}, {10.0f, 0.0f, 0.0f}, {0.5f, 0.0f, 0.0f}};
  m.joints[2] = {2, 0, 1, {0.1f, 0.1f, 0.1f}, {1, 0, 0, 0}};
  m.rates[2] = client::JointRates{};  // not known yet
  return m;
}

double quat_angle(const client::JointRecord& r, const Mat3& R) {
  const Quat q(r.q[0], r.q[1], r.q[2], r.q[3]);
  return Eigen::AngleAxisd(q.normalized().toRotationMatrix() * R.transpose()).angle();
}

TEST(Lead, PredictsAnglesQuaternionsAndSdsToPublishPlusLead) {
  const JointModel model = ball_and_hinge();
  auto lead = LeadPredictor::create(5.0, &model, "outputs.udp");
  ASSERT_TRUE(lead.ok()) << lead.error().message;
  const client::JointsMessage in = message();
  client::JointsMessage out;
  ASSERT_TRUE(lead->apply(in, out));
  EXPECT_TRUE(out.flags & client::kFlagPredicted);
  EXPECT_EQ(out.lead_us, 5000);
  EXPECT_EQ(out.capture_ns, in.capture_ns);
  EXPECT_EQ(out.publish_ns, in.publish_ns);
  const double dt = 0.007;  // publish 2 ms after capture, plus the 5 ms lead
  // Ball: a + da dt, and its quaternion from the predicted Euler angles.
  const Vec3 a(0.3 + 1.0 * dt, -0.2 - 2.0 * dt, 0.5 + 0.5 * dt);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(out.joints[0].a[k], a[k], 1e-6);
  EXPECT_LT(quat_angle(out.joints[0], euler_xyz_to_rotation(a)), 1e-6);
  EXPECT_NEAR(out.quality[0].sd_rad[1], std::hypot(0.002, 0.2 * dt), 1e-7);
  // Hinge: continuous past +pi (3.17, not -3.11), the quaternion turned about the axis.
  EXPECT_NEAR(out.joints[1].a[0], 3.1 + 10.0 * dt, 1e-5);
  EXPECT_LT(quat_angle(out.joints[1], hinge_rotation(3.1 + 10.0 * dt)), 1e-6);
  EXPECT_NEAR(out.quality[1].sd_rad[0], std::hypot(0.002, 0.5 * dt), 1e-7);
  // Rates and how each angle was solved are carried over.
  EXPECT_EQ(out.rates[1].rate_rad_s[0], 10.0f);
  EXPECT_EQ(out.quality[1].solved_by, 2);
  // No rates: as measured.
  for (int k = 0; k < 3; ++k) EXPECT_EQ(out.joints[2].a[k], in.joints[2].a[k]);
}

TEST(Lead, AgreesWithTheClientLibrarysPrediction) {
  const JointModel model = ball_and_hinge();
  auto lead = LeadPredictor::create(3.5, &model, "outputs.iceoryx");
  ASSERT_TRUE(lead.ok());
  const client::JointsMessage in = message();
  client::JointsMessage out;
  ASSERT_TRUE(lead->apply(in, out));
  client::JointPrediction p;
  ASSERT_EQ(client::predict(in, in.publish_ns + 3'500'000, p), client::PredictStatus::kOk);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(out.joints[0].a[k], p.joints[0].a_rad[k]);
    EXPECT_EQ(out.quality[0].sd_rad[k], p.joints[0].sd_rad[k]);
  }
  // The hinge's wrapped prediction is the same angle.
  EXPECT_NEAR(std::remainder(out.joints[1].a[0] - p.joints[1].a_rad[0], 2.0 * 3.14159265358979),
              0.0, 1e-5);
}

TEST(Lead, ACaptureBeyondTheHorizonIsNotPredicted) {
  const JointModel model = ball_and_hinge();
  auto lead = LeadPredictor::create(10.0, &model, "outputs.udp");
  ASSERT_TRUE(lead.ok());
  client::JointsMessage in = message();
  in.publish_ns = in.capture_ns + 45'000'000;  // 45 ms + 10 ms lead > 50 ms
  client::JointsMessage out;
  EXPECT_FALSE(lead->apply(in, out));
  EXPECT_FALSE(out.flags & client::kFlagPredicted);
  EXPECT_EQ(out.lead_us, 0);
  EXPECT_EQ(out.joints[0].a[0], in.joints[0].a[0]);
}

TEST(Lead, SetupErrorsNameTheKey) {
  for (const double bad : {0.0, -1.0, 50.5, std::nan("")}) {
    auto lead = LeadPredictor::create(bad, nullptr, "run.yaml: outputs.iceoryx");
    ASSERT_FALSE(lead.ok());
    EXPECT_NE(lead.error().message.find("run.yaml: outputs.iceoryx: lead_ms"), std::string::npos)
        << lead.error().message;
  }
  OutputRequest r{"udp", {"127.0.0.1:9", "127.0.0.1:10"}, "run.yaml: outputs.udp", {}};
  r.options.emplace_back("leads_ms", "0,80");
  auto checked = check_outputs({r});
  ASSERT_FALSE(checked.ok());
  EXPECT_NE(checked.error().message.find("lead_ms"), std::string::npos);
  r.options.back().second = "5";  // one lead for two destinations
  EXPECT_FALSE(check_outputs({r}).ok());
  OutputRequest ice{"iceoryx", {"true"}, "run.yaml: outputs.iceoryx", {{"lead_ms", "abc"}}};
  checked = check_outputs({ice});
  ASSERT_FALSE(checked.ok());
  EXPECT_NE(checked.error().message.find("lead_ms 'abc'"), std::string::npos);
}

TEST(Lead, DatagramsCarryTheFlagAndTheLead) {
  const JointModel model = ball_and_hinge();
  auto lead = LeadPredictor::create(5.0, &model, "outputs.udp");
  ASSERT_TRUE(lead.ok());
  client::JointsMessage predicted;
  ASSERT_TRUE(lead->apply(message(), predicted));
  for (const std::uint16_t version : {client::kDatagramVersion, client::kDatagramVersion2}) {
    std::uint8_t buf[client::kMaxDatagramBytes];
    const std::size_t n = client::encode_datagram(predicted, buf, sizeof buf, version);
    ASSERT_GT(n, 0u);
    EXPECT_EQ(buf[36] | (buf[37] << 8), 5000);  // lead_us, little-endian
    client::JointsMessage back;
    ASSERT_EQ(client::decode_datagram(buf, n, back), client::DecodeStatus::kOk);
    EXPECT_TRUE(back.flags & client::kFlagPredicted);
    EXPECT_EQ(back.lead_us, 5000);
    // A measured message keeps the field 0, as version 1 always had it.
    const std::size_t m = client::encode_datagram(message(), buf, sizeof buf, version);
    EXPECT_EQ(buf[36] | buf[37] | buf[38] | buf[39], 0);
    ASSERT_EQ(client::decode_datagram(buf, m, back), client::DecodeStatus::kOk);
    EXPECT_EQ(back.lead_us, 0);
  }
}

TEST(Lead, TheUdpOutputPredictsOnlyForDestinationsWithALead) {
  auto plain = client::UdpReceiver::create("127.0.0.1:0");
  auto ahead = client::UdpReceiver::create("127.0.0.1:0");
  ASSERT_TRUE(plain.ok() && ahead.ok());
  OutputRequest r{
      "udp",
      {"127.0.0.1:" + std::to_string(plain->port()), "127.0.0.1:" + std::to_string(ahead->port())},
      "outputs.udp",
      {{"versions", "2,2"}, {"leads_ms", "0,5"}}};
  const JointModel model = ball_and_hinge();
  OutputContext context;
  context.model = &model;
  auto outputs = create_outputs({r}, context);
  ASSERT_TRUE(outputs.ok()) << outputs.error().message;
  ASSERT_EQ(outputs->sinks.size(), 1u);
  FrameResult frame;
  frame.joints = message();
  std::uint64_t allocations = 0;
  for (int k = 0; k < 20; ++k) {
    frame.joints.sequence = 10 + static_cast<std::uint64_t>(k);
    const test::AllocationScope scope;
    ASSERT_TRUE(outputs->sinks[0]->publish(frame));
    allocations += scope.count();
  }
  EXPECT_EQ(allocations, 0u);
  for (client::UdpReceiver* rx : {&plain.value(), &ahead.value()}) {
    for (int i = 0; i < 400 && rx->counters().accepted < 20; ++i)
      rx->wait(std::chrono::milliseconds(5));
    ASSERT_EQ(rx->counters().accepted, 20u);
  }
  EXPECT_FALSE(plain->latest().flags & client::kFlagPredicted);
  EXPECT_EQ(plain->latest().joints[0].a[0], 0.3f);
  EXPECT_TRUE(ahead->latest().flags & client::kFlagPredicted);
  EXPECT_NEAR(ahead->latest().joints[0].a[0], 0.3 + 0.007, 1e-6);
  EXPECT_EQ(outputs->sinks[0]->counters().published, 20u);
  EXPECT_EQ(outputs->sinks[0]->counters().not_predicted, 0u);
}

}  // namespace
}  // namespace mocap::publish
