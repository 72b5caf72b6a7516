// Design: the one iceoryx runtime of this process, initialised at setup only after
// roudi_running() said yes, because PoshRuntime::initRuntime blocks forever without
// RouDi (iceoryx 2.0.3). The first successful call fixes the runtime name for the
// process (iceoryx allows one runtime per process, names unique on the machine); later
// calls return ok and keep it. iceoryx's own log level is set to warnings.
// Note: when RouDi shuts down it sends SIGTERM to every registered process. Available when
// mocap_client was built with iceoryx (MOCAP_CLIENT_HAVE_ICEORYX is defined for every target
// linking mocap_client).
#pragma once

#include <string>

#include "core/expected.h"

namespace mocap::client {

// Arrays, not pointers: iceoryx's IdString_t(const char (&)[N]) checks the length at compile
// time, while its truncating const char* constructor trips GCC 12's -Warray-bounds at -O1.
inline constexpr char kIceoryxService[] = "mocap";
inline constexpr char kIceoryxInstance[] = "tracker";
inline constexpr char kIceoryxEvent[] = "joints";

// Fails fast, never blocks: "iceoryx: RouDi (iox-roudi) not running" when RouDi is absent.
// `roudi_socket_path` exists for tests; production uses the default /tmp/roudi.
Expected<void> init_iceoryx_runtime(const std::string& app_name,
                                    const char* roudi_socket_path = "/tmp/roudi");

}  // namespace mocap::client
