// Design: wand and L-frame recordings for rig calibration (`mocap simulate --motion wand`
// / `--motion lframe`, docs/rig_calibration.md). They reuse the shoulder scenario's
// rig (the built-in pair, --cameras N or --rig), imaging model and renderer, with a
// different scene:
//  - wand:   one rigid body, a straight rod carrying 3..8 marker balls at the offsets of
//            the wand description plus a handle (both dark, they occlude), waved through
//            the cameras' common volume on a smooth quasi-random path (sums of
//            sinusoids of incommensurate frequencies in position and direction, with a
//            slow roll); the path is spread over the recording so any frame count sweeps
//            the whole volume.
//  - lframe: a static L-shaped bar on the floor carrying the L-frame's markers, at a
//            known pose T_world_lframe (yawed, off-centre, below the cameras).
// Both scenes add static shiny spots in the room (glints, --stray) and the renderer's
// random drop-outs (--dropout). Ground truth: gt/rig_true.yaml (the true rig),
// gt/rig_lframe_true.yaml (the true rig with the L-frame as world, lframe only),
// gt/markers.csv (frame,marker,x,y,z, then uK,vK,visK for every camera K: for two
// cameras u0,v0,vis0,u1,v1,vis1), plus wand.yaml.
#pragma once

#include <functional>
#include <string>

#include "core/expected.h"
#include "formats/wand_yaml.h"
#include "sim/scene.h"
#include "sim/simulate.h"

namespace mocap::sim {

enum class CalibObjectKind { kWand, kLFrame };

// The default wand (0, 110, 300 mm: asymmetric) and L-frame (origin, 400 mm on +X,
// 250 mm on +Y and 200 mm on +X) of the simulator.
CalibrationObjects default_calibration_objects();

// The pose of the simulated L-frame in the simulator's world.
Iso3 simulated_T_world_lframe();

// The true rig with the L-frame as world (X_cam = R X_lframe + t).
Rig rig_in_lframe(const Rig& rig, const Iso3& T_world_lframe);

// Wand pose of a frame: X_world = T * (offset, 0, 0).
Iso3 wand_pose(int frame, int frames, std::uint64_t seed) noexcept;

// Writes a wand or L-frame recording (options: frames, seed, noise, blur, stray,
// dropout, bits, maxval, fps, threads; motion is ignored).
Expected<SimSummary> write_calibration_recording(const SimOptions& options, CalibObjectKind kind,
                                                 const std::string& dir,
                                                 const std::function<void(int)>& progress = {});

}  // namespace mocap::sim
