// Design: real-time thread set-up. A stage thread is started with a name (<= 15
// characters, as Linux allows), an optional CPU to pin to, and an optional SCHED_FIFO
// priority. The settings are applied by the new thread itself before its body runs,
// and the starter waits for that, so the outcome is known when start_thread returns.
// Anything not permitted (EPERM without CAP_SYS_NICE / RLIMIT_RTPRIO, a CPU that does
// not exist) does not fail the start: the thread runs with the default policy and the
// result carries ONE line saying what was not applied, for the caller to log at setup
// (never printed on the hot path). Invalid specifications (empty or long names,
// priorities outside 1..99) are setup errors.
#pragma once

#include <functional>
#include <string>
#include <thread>

#include "core/expected.h"

namespace mocap::rt {

struct ThreadSpec {
  std::string name;       // 1..15 characters
  int cpu = -1;           // -1: not pinned
  int fifo_priority = 0;  // 0: default policy (SCHED_OTHER); 1..99: SCHED_FIFO
};

// What was applied. `note` is empty when everything asked for was applied.
struct RtSetupResult {
  bool pinned = false;
  bool fifo = false;
  std::string note;
};

Expected<void> validate(const ThreadSpec& spec);

// Applies spec to the calling thread (name, affinity, SCHED_FIFO), with fallback.
RtSetupResult apply_to_current_thread(const ThreadSpec& spec);

class RtThread {
 public:
  RtThread() = default;
  RtThread(RtThread&&) noexcept = default;
  RtThread& operator=(RtThread&&) noexcept;
  RtThread(const RtThread&) = delete;
  RtThread& operator=(const RtThread&) = delete;
  ~RtThread();  // joins

  const RtSetupResult& setup() const noexcept { return setup_; }
  bool joinable() const noexcept { return thread_.joinable(); }
  void join();

 private:
  friend Expected<RtThread> start_thread(const ThreadSpec&, std::function<void()>);
  std::thread thread_;
  RtSetupResult setup_;
};

// Starts `body` on a new thread configured by `spec`; returns once the settings have
// been applied (or have fallen back). Errors: an invalid spec, or thread creation
// failing.
Expected<RtThread> start_thread(const ThreadSpec& spec, std::function<void()> body);

// mlockall(MCL_CURRENT | MCL_FUTURE) so that the hot path never page-faults. Returns
// an empty note on success, else one line explaining the fallback (memory not locked).
std::string lock_memory();

// Number of CPUs this process may run on (for validating pinning at setup).
int available_cpu_count();

}  // namespace mocap::rt
