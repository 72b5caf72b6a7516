// Design: the one pause instruction of a bounded spin-wait (x86 `pause`, Arm `yield`):
// it tells the core that the loop waits, which saves power and gives a sibling
// hyper-thread the pipeline. No syscall, no memory effect.
#pragma once

namespace mocap::rt {

inline void cpu_relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__) || defined(__arm__)
  asm volatile("yield" ::: "memory");
#endif
}

}  // namespace mocap::rt
