// Design: the capture modes every layer names: how a camera's exposures start
// (TriggerMode: the HAL's cameras, the run configuration's `trigger:` key) and how the
// live pipeline paces its software triggers (TriggerPacing: the configuration's
// `pipeline.pacing` key, PipelineOptions). One definition, below the configuration, the
// HAL and the pipeline, so that none of them mirrors another's enum.
#pragma once

#include <cstdint>

namespace mocap {

enum class TriggerMode : std::uint8_t {
  kFreeRun,   // the camera runs at its frame rate
  kExternal,  // a hardware trigger line starts each exposure (every camera shares it)
  kSoftware,  // each trigger() call starts one exposure
};

enum class TriggerPacing : std::uint8_t {
  kPeriodic,  // software trigger every 1/trigger_rate_hz (absolute deadlines, no drift)
  kLockstep,  // next trigger once the previous frame was published or dropped, and at
              // most at trigger_rate_hz (replays, tests: lossless)
};

// Software trigger rates the pipeline accepts (the lower bound keeps the period's
// nanoseconds in range; the configuration, its flags and Pipeline::create use these).
inline constexpr double kMinTriggerRateHz = 0.01;
inline constexpr double kMaxTriggerRateHz = 10000.0;

}  // namespace mocap
