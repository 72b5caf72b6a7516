// Thread set-up: validation errors, the name/affinity actually applied, SCHED_FIFO
// applied or reported in one line, and mlockall's outcome reported.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <atomic>
#include <cstring>

#include "rt/thread.h"

namespace mocap::rt {
namespace {

TEST(RtThread, RejectsInvalidSpecs) {
  auto long_name = start_thread({"a_name_longer_than_15", -1, 0}, [] {});
  ASSERT_FALSE(long_name.ok());
  EXPECT_NE(long_name.error().message.find("name"), std::string::npos);
  auto bad_prio = start_thread({"ok", -1, 120}, [] {});
  ASSERT_FALSE(bad_prio.ok());
  EXPECT_NE(bad_prio.error().message.find("fifo_priority"), std::string::npos);
  EXPECT_FALSE(start_thread({"", -1, 0}, [] {}).ok());
  EXPECT_FALSE(start_thread({"x", -5, 0}, [] {}).ok());
}

TEST(RtThread, AppliesNameAndAffinity) {
  char name[16] = {};
  int cpu_seen = -2;
  int cpus_allowed = 0;
  auto t = start_thread({"mocap_test_pin", 0, 0}, [&] {
    pthread_getname_np(pthread_self(), name, sizeof name);
    cpu_set_t set;
    CPU_ZERO(&set);
    pthread_getaffinity_np(pthread_self(), sizeof set, &set);
    cpus_allowed = CPU_COUNT(&set);
    cpu_seen = sched_getcpu();
  });
  ASSERT_TRUE(t.ok()) << t.error().message;
  t->join();
  EXPECT_STREQ(name, "mocap_test_pin");
  if (t->setup().pinned) {
    EXPECT_EQ(cpus_allowed, 1);
    EXPECT_EQ(cpu_seen, 0);
    EXPECT_TRUE(t->setup().note.empty()) << t->setup().note;
  } else {
    EXPECT_NE(t->setup().note.find("not pinned"), std::string::npos);
  }
}

TEST(RtThread, FifoAppliedOrExplained) {
  int policy = -1;
  sched_param param{};
  auto t = start_thread({"mocap_test_rt", -1, 10},
                        [&] { pthread_getschedparam(pthread_self(), &policy, &param); });
  ASSERT_TRUE(t.ok()) << t.error().message;
  t->join();
  if (t->setup().fifo) {
    EXPECT_EQ(policy, SCHED_FIFO);
    EXPECT_EQ(param.sched_priority, 10);
  } else {
    EXPECT_NE(policy, SCHED_FIFO);
    const std::string& note = t->setup().note;
    EXPECT_NE(note.find("SCHED_FIFO 10"), std::string::npos) << note;
    EXPECT_EQ(note.find('\n'), std::string::npos);
  }
}

TEST(RtThread, ImpossibleCpuFallsBackWithOneLine) {
  const int cpu = CPU_SETSIZE - 1;  // valid index, no such CPU here
  std::atomic<bool> ran{false};
  auto t = start_thread({"mocap_test_cpu", cpu, 0}, [&] { ran = true; });
  ASSERT_TRUE(t.ok()) << t.error().message;
  t->join();
  EXPECT_TRUE(ran.load());
  EXPECT_FALSE(t->setup().pinned);
  EXPECT_NE(t->setup().note.find("cpu " + std::to_string(cpu)), std::string::npos)
      << t->setup().note;
  EXPECT_EQ(t->setup().note.find('\n'), std::string::npos);
}

TEST(RtThread, LockMemoryReportsOutcome) {
  const std::string note = lock_memory();
  if (!note.empty()) {
    EXPECT_EQ(note.rfind("mlockall: ", 0), 0u) << note;
    EXPECT_EQ(note.find('\n'), std::string::npos);
  }
  munlockall();
  EXPECT_GE(available_cpu_count(), 1);
}

}  // namespace
}  // namespace mocap::rt
