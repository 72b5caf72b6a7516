// Design: the non-image files of a recording that `mocap record` writes before the first
// frame: rig.yaml (the rig the configuration tracks with: the configured rig file, the
// sim scene's, or the replayed recording's) and the configuration's targets.yaml,
// model.yaml and joints.yaml where it has them. Files named in the configuration are
// copied byte for byte (comments and extra keys kept); the backend's own assets (the sim
// scene) are written with the formats/ writers; joints.yaml is the model's topology (the
// model without its parameters) unless a joints file sits next to the configured model.
// Also the output-folder policy: DIR must be new or empty (a recording is never
// overwritten or mixed with another one). Setup code: one-line errors naming the file.
#pragma once

#include <string>
#include <vector>

#include "config/run_config.h"
#include "config/tracking_assets.h"
#include "core/expected.h"

namespace mocap::record {

// DIR does not exist (it is created, parents included) or is an empty folder.
Expected<void> prepare_output_dir(const std::string& dir);

// Writes rig.yaml, and targets.yaml / model.yaml / joints.yaml where the configuration
// has them. Returns the names of the files written.
Expected<std::vector<std::string>> write_recording_assets(const std::string& dir,
                                                          const config::RunConfig& cfg,
                                                          const config::TrackingAssets& assets);

}  // namespace mocap::record
