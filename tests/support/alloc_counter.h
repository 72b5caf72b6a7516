// Design: counts heap allocations made by the current thread, to prove that
// steady-state processing allocates nothing. Add tests/support/alloc_counter.cpp to a
// test executable's sources (it replaces the global operator new/delete of that
// binary). Usage:
//   mocap::test::AllocationScope scope;   // starts counting on this thread
//   ... hot-path work ...
//   EXPECT_EQ(scope.count(), 0u);
#pragma once

#include <cstdint>

namespace mocap::test {

// Allocations by this thread since program start (operator new and malloc-backed new).
std::uint64_t thread_allocation_count() noexcept;

class AllocationScope {
 public:
  AllocationScope() noexcept : start_(thread_allocation_count()) {}
  std::uint64_t count() const noexcept { return thread_allocation_count() - start_; }

 private:
  std::uint64_t start_;
};

}  // namespace mocap::test
