// Design: shared-memory round trip with a real iceoryx daemon. The suite starts
// `iox-roudi -m off -c <small config>` as a child process once (iceoryx allows one
// runtime per process, so every test here shares it), publishes JointsMessage through
// IceoryxPublisher / the registry's iceoryx sink and takes it with IceoryxSubscriber. Each test
// body runs in a forked child with its own iceoryx runtime that exits before RouDi stops: RouDi
// sends SIGTERM to every still-registered process when it shuts down. Skipped, with the
// reason, when iox-roudi is not installed or another RouDi already runs on the machine.
// ctest runs these under RESOURCE_LOCK iceoryx (RouDi's names are machine-global). With
// the pipeline and simulator built, also the whole-body humanoid's 14 joints.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include "client/iceoryx_subscriber.h"
#include "client/roudi_probe.h"
#include "pipeline/publish/iceoryx_publisher.h"
#include "pipeline/publish/output_registry.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"
#ifdef MOCAP_TEST_HUMANOID
#include "tests/pipeline/humanoid_frame.h"
#endif

namespace {

using mocap::client::JointsMessage;

std::string find_roudi() {
  const char* path = std::getenv("PATH");
  std::string p = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= p.size()) {
    const std::size_t end = p.find(':', start);
    const std::string dir =
        p.substr(start, end == std::string::npos ? std::string::npos : end - start);
    const std::string candidate = (dir.empty() ? "." : dir) + "/iox-roudi";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return {};
}

// Unique per (child) process: iceoryx runtime names are machine-global.
std::string app_name() { return "mocap_test_iox_" + std::to_string(::getpid()); }

class IceoryxRoundTrip : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string roudi = find_roudi();
    if (roudi.empty()) {
      skip_reason_ = "iox-roudi is not installed (Debian package 'iceoryx')";
      return;
    }
    if (mocap::client::roudi_running()) {
      skip_reason_ = "another RouDi already runs on this machine (/tmp/roudi answers)";
      return;
    }
    dir_ = new mocap::test::TempDir("iox");
    const std::string config = dir_->file("roudi.toml");
    // One mempool: chunks for JointsMessage (2464 B) plus iceoryx's chunk header.
    mocap::test::write_file(config,
                            "[general]\nversion = 1\n\n[[segment]]\n\n[[segment.mempool]]\n"
                            "size = 4096\ncount = 64\n");
    const std::string log = dir_->file("roudi.log");
    pid_ = ::fork();
    if (pid_ == 0) {
      if (!std::freopen(log.c_str(), "w", stdout) || !std::freopen(log.c_str(), "a", stderr))
        _exit(126);
      ::execl(roudi.c_str(), "iox-roudi", "-m", "off", "-c", config.c_str(),
              static_cast<char*>(nullptr));
      _exit(127);
    }
    for (int i = 0; i < 200 && !mocap::client::roudi_running(); ++i) {  // up to 10 s
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (!mocap::client::roudi_running()) {
      skip_reason_ = "iox-roudi did not come up: " + mocap::test::read_file(log);
    }
  }

  static void TearDownTestSuite() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
    delete dir_;
    dir_ = nullptr;
  }

  void SetUp() override {
    if (!skip_reason_.empty()) GTEST_SKIP() << skip_reason_;
  }

  // Runs `body` in a child process (bounded: 30 s) and expects it to pass.
  template <class Body>
  static void run_in_child(Body body) {
    std::fflush(stdout);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      body();
      std::fflush(stdout);
      std::exit(::testing::Test::HasFailure() ? 1 : 0);  // exit(): the runtime deregisters
    }
    int status = 0;
    pid_t done = 0;
    for (int i = 0; i < 3000 && done == 0; ++i) {
      done = ::waitpid(child, &status, WNOHANG);
      if (done == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (done == 0) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      FAIL() << "iceoryx child timed out";
    }
    ASSERT_TRUE(WIFEXITED(status)) << "child died by signal " << WTERMSIG(status);
    EXPECT_EQ(WEXITSTATUS(status), 0) << "child's expectations failed (see its output above)";
  }

  static inline pid_t pid_ = -1;
  static inline mocap::test::TempDir* dir_ = nullptr;
  static inline std::string skip_reason_;
};

JointsMessage make_message(std::uint64_t seq) {
  JointsMessage m;
  m.sequence = seq;
  m.capture_ns = static_cast<std::int64_t>(seq) * 1000;
  m.joint_count = 3;
  for (std::uint16_t j = 0; j < 3; ++j) {
    m.joints[j].index = j;
    m.joints[j].valid = 1;
    m.joints[j].a[1] = 0.1f * static_cast<float>(seq + j);
  }
  return m;
}

void publish_subscribe_body() {
  auto pub = mocap::publish::IceoryxPublisher::create(app_name());
  ASSERT_TRUE(pub.ok()) << pub.error().message;
  auto sub = mocap::client::IceoryxSubscriber::create(app_name());
  ASSERT_TRUE(sub.ok()) << sub.error().message;
  auto& p = *pub.value();
  auto& s = *sub.value();
  for (int i = 0; i < 200 && !(s.subscribed() && p.has_subscribers()); ++i) {  // RouDi discovery
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  ASSERT_TRUE(s.subscribed());

  JointsMessage out;
  std::uint64_t seqs[] = {1, 2, 3, 7, 8};
  {
    mocap::test::AllocationScope scope;
    for (std::uint64_t q : seqs) {
      ASSERT_TRUE(p.publish(make_message(q)));
      EXPECT_TRUE(s.take_latest(out));
      EXPECT_EQ(out.sequence, q);
    }
    EXPECT_FALSE(s.take_latest(out));  // nothing new
    EXPECT_EQ(scope.count(), 0u);
  }
  EXPECT_EQ(out.joint_count, 3u);
  EXPECT_FLOAT_EQ(out.joints[2].a[1], 0.1f * 10.0f);
  EXPECT_EQ(s.counters().received, 5u);
  EXPECT_EQ(s.counters().dropped_frames, 3u);  // 4, 5, 6
  EXPECT_EQ(p.counters().published, 5u);
  EXPECT_EQ(p.counters().loan_failures, 0u);

  // Several messages between two takes: the newest wins, none is lost from the count.
  for (std::uint64_t q = 9; q <= 12; ++q) ASSERT_TRUE(p.publish(make_message(q)));
  EXPECT_TRUE(s.take_latest(out));
  EXPECT_EQ(out.sequence, 12u);
  EXPECT_EQ(s.counters().received, 9u);
}

TEST_F(IceoryxRoundTrip, PublishSubscribeCountsGapsAndAllocatesNothing) {
  run_in_child(publish_subscribe_body);
}

void registry_body() {
  std::vector<mocap::publish::OutputRequest> req = {
      {"iceoryx", {"true"}, "test: outputs.iceoryx", {{"app_name", app_name()}}}};
  auto outs = mocap::publish::create_outputs(req, {});
  ASSERT_TRUE(outs.ok()) << outs.error().message;
  ASSERT_EQ(outs->sinks.size(), 1u);
  EXPECT_TRUE(outs->notices.empty());
  auto sub = mocap::client::IceoryxSubscriber::create(app_name());
  ASSERT_TRUE(sub.ok());
  auto& s = *sub.value();
  for (int i = 0; i < 200 && !s.subscribed(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // publisher side sees it too
  ASSERT_TRUE(s.subscribed());
  auto frame = std::make_unique<mocap::publish::FrameResult>();
  frame->joints = make_message(41);
  frame->joints.publish_ns = 777;
  ASSERT_TRUE(outs->sinks[0]->publish(*frame));
  JointsMessage out;
  ASSERT_TRUE(s.take_latest(out));
  EXPECT_EQ(out.sequence, 41u);
  EXPECT_EQ(out.publish_ns, 777);  // stamped by the publish stage, sent unchanged
  EXPECT_EQ(outs->sinks[0]->counters().published, 1u);
}

TEST_F(IceoryxRoundTrip, RegistryIceoryxSinkUsesSharedMemoryWhenRouDiRuns) {
  run_in_child(registry_body);
}

#ifdef MOCAP_TEST_HUMANOID
// The whole-body humanoid's full frame (tests/pipeline/humanoid_frame.h): its 14 joint
// records (8 ball, 6 hinge, the tracker's angles of the true model) arrive through shared
// memory as published, record for record.
void humanoid_body() {
  std::vector<mocap::publish::OutputRequest> req = {
      {"iceoryx", {"true"}, "test: outputs.iceoryx", {{"app_name", app_name()}}}};
  auto outs = mocap::publish::create_outputs(req, {});
  ASSERT_TRUE(outs.ok()) << outs.error().message;
  ASSERT_EQ(outs->sinks.size(), 1u);
  auto sub = mocap::client::IceoryxSubscriber::create(app_name());
  ASSERT_TRUE(sub.ok());
  auto& s = *sub.value();
  for (int i = 0; i < 200 && !s.subscribed(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(s.subscribed());
  auto h = mocap::testing::make_humanoid_frame(3, 31);
  const auto frame = h->make_result(123456);
  ASSERT_EQ(frame->joints.joint_count, 14u);
  ASSERT_TRUE(outs->sinks[0]->publish(*frame));
  JointsMessage out;
  ASSERT_TRUE(s.take_latest(out));
  EXPECT_EQ(out.sequence, 7u);
  EXPECT_EQ(out.capture_ns, 123456);
  EXPECT_EQ(out.flags, frame->joints.flags);
  ASSERT_EQ(out.joint_count, 14u);
  int hinges = 0;
  for (int j = 0; j < 14; ++j) {
    const mocap::JointSpec& spec = h->scene.joints_true.joints[static_cast<std::size_t>(j)];
    const mocap::kinematics::JointAngle& a = h->out->angles.joints[static_cast<std::size_t>(j)];
    hinges += out.joints[j].type == 1;
    EXPECT_EQ(out.joints[j].index, j);
    EXPECT_EQ(out.joints[j].type, spec.type == mocap::JointType::kHinge ? 1 : 0) << spec.name;
    EXPECT_EQ(out.joints[j].valid, 1) << spec.name;
    EXPECT_FLOAT_EQ(out.joints[j].a[0], static_cast<float>(a.a0)) << spec.name;
    EXPECT_FLOAT_EQ(out.joints[j].a[2], static_cast<float>(a.a2)) << spec.name;
    EXPECT_EQ(out.quality[j].solved_by, frame->joints.quality[j].solved_by);
  }
  EXPECT_EQ(hinges, 6);
}

TEST_F(IceoryxRoundTrip, HumanoidFrameArrivesWithEveryJoint) { run_in_child(humanoid_body); }
#endif

TEST(IceoryxNoRouDi, FailsFastAtAPathNobodyBinds) {
  mocap::test::TempDir dir("no_roudi");
  const std::string path = dir.file("roudi");
  auto p = mocap::publish::IceoryxPublisher::create("mocap_test_nobody", path.c_str());
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().message, mocap::publish::kNoRouDiMessage);
}

TEST(IceoryxNoRouDi, SubscriberFailsFastWhenNoRouDiRuns) {
  if (mocap::client::roudi_running()) GTEST_SKIP() << "a RouDi runs on this machine";
  auto s = mocap::client::IceoryxSubscriber::create("mocap_test_nobody_sub");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message, "iceoryx: RouDi (iox-roudi) not running");
}

}  // namespace
