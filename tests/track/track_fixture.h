// Design: shared fixture of the end-to-end tests: one simulated recording per test
// binary run (written once into a temporary folder by the simulator library).
#pragma once

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>

#include "sim/simulate.h"
#include "tests/support/test_support.h"

namespace mocap::test {

// Writes a recording with the given options once per (name) and returns its folder.
inline const std::string& simulated_recording(const std::string& name, const sim::SimOptions& options) {
  static std::map<std::string, std::unique_ptr<TempDir>> dirs;
  auto& slot = dirs[name];
  if (!slot) {
    slot = std::make_unique<TempDir>("track_" + name);
    auto r = sim::write_simulated_recording(options, slot->path() + "/rec");
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  }
  static std::string path;
  path = slot->path() + "/rec";
  return path;
}

}  // namespace mocap::test
