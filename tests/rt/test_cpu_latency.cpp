// The CPU latency request: the 32-bit value the kernel reads, held until release(), one
// line naming the device when it cannot be opened or the value is out of range, and on a
// machine where this process may open /dev/cpu_dma_latency, the kernel's limit while held.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "rt/cpu_latency.h"
#include "tests/support/test_support.h"

namespace mocap::rt {
namespace {

std::int32_t read_int32(const std::string& path) {
  std::int32_t v = -12345;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return v;
  if (::read(fd, &v, sizeof v) != static_cast<ssize_t>(sizeof v)) v = -12345;
  ::close(fd);
  return v;
}

TEST(CpuLatencyRequest, WritesTheValueAsA32BitIntegerAndHoldsUntilReleased) {
  test::TempDir dir("cpu_latency");
  const std::string device = dir.file("cpu_dma_latency");
  { std::ofstream(device.c_str()).put('\0'); }
  CpuLatencyRequest r;
  EXPECT_FALSE(r.held());
  EXPECT_EQ(r.request(75, device), "");
  EXPECT_TRUE(r.held());
  EXPECT_EQ(read_int32(device), 75);
  CpuLatencyRequest moved = std::move(r);
  EXPECT_FALSE(r.held());  // NOLINT(bugprone-use-after-move): moved-from state is defined
  EXPECT_TRUE(moved.held());
  moved.release();
  EXPECT_FALSE(moved.held());
}

TEST(CpuLatencyRequest, MissingDeviceOrBadValueIsOneLineAndNotHeld) {
  CpuLatencyRequest r;
  const std::string missing = "/nonexistent/cpu_dma_latency";
  const std::string note = r.request(0, missing);
  EXPECT_FALSE(r.held());
  EXPECT_EQ(note.rfind(missing + ": No such file or directory", 0), 0u) << note;
  EXPECT_EQ(note.find('\n'), std::string::npos);
  const std::string bad = r.request(-1, missing);
  EXPECT_FALSE(r.held());
  EXPECT_NE(bad.find("outside 0..1000000"), std::string::npos) << bad;
}

TEST(CpuLatencyRequest, TheKernelLimitIsTheRequestWhileHeld) {
  CpuLatencyRequest r;
  if (const std::string note = r.request(0); !note.empty()) GTEST_SKIP() << note;
  // Reading the device returns the current aggregate limit (the minimum of all holders).
  EXPECT_EQ(read_int32(kCpuLatencyDevice), 0);
  r.release();
  EXPECT_FALSE(r.held());
}

}  // namespace
}  // namespace mocap::rt
