// Design: see thread.h. pthread calls return an errno value; each failure becomes a
// clause of the one-line note ("cpu 3: Invalid argument: not pinned").
#include "rt/thread.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>
#include <future>
#include <system_error>

namespace mocap::rt {
namespace {

void append_note(std::string& note, const std::string& clause) {
  if (!note.empty()) note += "; ";
  note += clause;
}

}  // namespace

Expected<void> validate(const ThreadSpec& spec) {
  if (spec.name.empty() || spec.name.size() > 15) {
    return make_error("thread '" + spec.name + "'", "name", "must be 1..15 characters");
  }
  if (spec.fifo_priority < 0 || spec.fifo_priority > 99) {
    return make_error(
        "thread " + spec.name, "fifo_priority",
        "must be 0 (default policy) or 1..99, got " + std::to_string(spec.fifo_priority));
  }
  if (spec.cpu < -1 || spec.cpu >= CPU_SETSIZE) {
    return make_error("thread " + spec.name, "cpu",
                      "must be -1 (not pinned) or a CPU index, got " + std::to_string(spec.cpu));
  }
  return {};
}

RtSetupResult apply_to_current_thread(const ThreadSpec& spec) {
  RtSetupResult r;
  const pthread_t self = pthread_self();
  if (!spec.name.empty()) {
    const int e = pthread_setname_np(self, spec.name.substr(0, 15).c_str());
    if (e != 0) append_note(r.note, std::string("name: ") + std::strerror(e));
  }
  if (spec.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<std::size_t>(spec.cpu), &set);
    const int e = pthread_setaffinity_np(self, sizeof set, &set);
    if (e == 0) {
      r.pinned = true;
    } else {
      append_note(r.note,
                  "cpu " + std::to_string(spec.cpu) + ": " + std::strerror(e) + ": not pinned");
    }
  }
  if (spec.fifo_priority > 0) {
    sched_param param{};
    param.sched_priority = spec.fifo_priority;
    const int e = pthread_setschedparam(self, SCHED_FIFO, &param);
    if (e == 0) {
      r.fifo = true;
    } else {
      append_note(r.note, "SCHED_FIFO " + std::to_string(spec.fifo_priority) + ": " +
                              std::strerror(e) +
                              ": default scheduling (needs CAP_SYS_NICE or LimitRTPRIO)");
    }
  }
  if (!r.note.empty()) r.note = "thread " + spec.name + ": " + r.note;
  return r;
}

RtThread& RtThread::operator=(RtThread&& other) noexcept {
  if (this != &other) {
    if (thread_.joinable()) thread_.join();
    thread_ = std::move(other.thread_);
    setup_ = std::move(other.setup_);
  }
  return *this;
}

RtThread::~RtThread() {
  if (thread_.joinable()) thread_.join();
}

void RtThread::join() {
  if (thread_.joinable()) thread_.join();
}

Expected<RtThread> start_thread(const ThreadSpec& spec, std::function<void()> body) {
  if (auto v = validate(spec); !v) return v.error();
  std::promise<RtSetupResult> applied;
  std::future<RtSetupResult> applied_future = applied.get_future();
  RtThread t;
  try {
    // The promise moves into the thread, so it outlives set_value even when the
    // starter returns at once.
    t.thread_ = std::thread([spec, promise = std::move(applied), fn = std::move(body)]() mutable {
      promise.set_value(apply_to_current_thread(spec));
      fn();
    });
  } catch (const std::system_error& e) {
    return make_error("thread " + spec.name, "", std::string("cannot start: ") + e.what());
  }
  t.setup_ = applied_future.get();
  return t;
}

std::string lock_memory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {};
  const int e = errno;
  return std::string("mlockall: ") + std::strerror(e) +
         ": memory not locked, page faults possible (needs CAP_IPC_LOCK or LimitMEMLOCK=infinity)";
}

int available_cpu_count() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return 1;
  return CPU_COUNT(&set);
}

}  // namespace mocap::rt
