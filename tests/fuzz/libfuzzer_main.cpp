// Design: the libFuzzer adapter: one binary per entry point, chosen at compile time by
// MOCAP_FUZZ_ENTRY (tests/fuzz/CMakeLists.txt, MOCAP_FUZZ=ON with clang).
#include "tests/fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return mocap::fuzz::MOCAP_FUZZ_ENTRY(data, size);
}
