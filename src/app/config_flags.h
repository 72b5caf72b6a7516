// Design: the command-line flags that override the run configuration (`mocap run`,
// `mocap record`, `mocap preview`). Each fills service::CliOverrides directly: an unset
// std::optional means "the configuration's value", so a flag has no default of its own,
// and no check of its own either: service::resolve_run_config validates every override
// with the configuration file's checks and names the flag in its one-line error. The
// configuration therefore reaches RunConfig by one path, with one default and one
// validation per setting.
#pragma once

#include <CLI/CLI.hpp>

#include "pipeline/service/live_setup.h"

namespace mocap::app {

inline void add_rate_flag(CLI::App& cmd, service::CliOverrides& cli) {
  cmd.add_option("--rate", cli.rate_hz,
                 "Trigger rate in Hz (default: the configuration's; built in: 100)");
}

inline void add_loop_frames_flag(CLI::App& cmd, service::CliOverrides& cli) {
  cmd.add_option("--loop-frames", cli.loop_frames,
                 "Frames pre-rendered for the simulated cameras (default: the "
                 "configuration's; built in: 200, 320 MB)");
}

inline void add_no_realtime_flag(CLI::App& cmd, service::CliOverrides& cli) {
  cmd.add_flag("--no-realtime", cli.no_realtime, "No CPU pinning and no SCHED_FIFO");
}

}  // namespace mocap::app
