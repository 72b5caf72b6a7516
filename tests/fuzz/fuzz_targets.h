// Design: the fuzz entry points of issue 8, one per untrusted-input parser. Each has the
// libFuzzer signature (returns 0; any crash, sanitizer report or failed invariant
// check is the finding) and is built two ways: linked into a libFuzzer binary per
// target with clang (MOCAP_FUZZ=ON, deploy/fuzz.sh), and into the GCC test
// test_fuzz_corpus, which replays the committed seed corpus tests/fuzz/corpus/<name>/
// plus deterministic mutations of every seed (fuzz_mutate.h) in CI.
// Invariant violations call fuzz_check_failed(), which aborts with a message.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mocap::fuzz {

int fuzz_pgm(const std::uint8_t* data, std::size_t size);            // PGM reader (read_pgm)
int fuzz_rig(const std::uint8_t* data, std::size_t size);            // rig.yaml loader
int fuzz_targets(const std::uint8_t* data, std::size_t size);        // targets.yaml loader
int fuzz_joints(const std::uint8_t* data, std::size_t size);         // joints.yaml loader
int fuzz_model(const std::uint8_t* data, std::size_t size);          // model.yaml loader
int fuzz_frames_csv(const std::uint8_t* data, std::size_t size);     // frames.csv loader
int fuzz_datagram(const std::uint8_t* data, std::size_t size);       // UDP datagram decoder
int fuzz_blob_detector(const std::uint8_t* data, std::size_t size);  // detector on any image
int fuzz_vrpn(const std::uint8_t* data, std::size_t size);           // VRPN client input
int fuzz_blob_file(const std::uint8_t* data, std::size_t size);      // blob file reader
int fuzz_node_message(const std::uint8_t* data, std::size_t size);   // camera-node message

struct FuzzTarget {
  const char* name;  // also the corpus folder name
  int (*entry)(const std::uint8_t*, std::size_t);
};
inline constexpr FuzzTarget kFuzzTargets[] = {
    {"pgm", fuzz_pgm},
    {"rig", fuzz_rig},
    {"targets", fuzz_targets},
    {"joints", fuzz_joints},
    {"model", fuzz_model},
    {"frames_csv", fuzz_frames_csv},
    {"datagram", fuzz_datagram},
    {"blob_detector", fuzz_blob_detector},
    {"vrpn", fuzz_vrpn},
    {"blob_file", fuzz_blob_file},
    {"node_message", fuzz_node_message},
};

// Aborts with "fuzz invariant failed: <what>" (a finding in both builds).
[[noreturn]] void fuzz_check_failed(const char* what);
inline void fuzz_check(bool ok, const char* what) {
  if (!ok) fuzz_check_failed(what);
}

// The bytes as a file that the path-based loaders can open: an in-memory file
// (memfd) rewritten on every call, reached as /proc/self/fd/N. One per thread.
const char* fuzz_file(const std::uint8_t* data, std::size_t size);

}  // namespace mocap::fuzz
