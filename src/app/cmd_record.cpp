// `mocap record [--config FILE] --out DIR [--duration SECONDS | --frames N]`: records the
// cameras of the run configuration (without --config: the built-in simulated cameras, as
// `mocap run`) into a recording folder (the spec's "Recording", docs/formats.md). The
// cameras, trigger and pairing are `mocap run`'s own: service::LiveSetup opens them and
// the live pipeline::Pipeline drives them (detection and tracking run as in `mocap run`,
// nothing is published); a pipeline::FrameTap (record::FrameRecorder) copies every
// delivered image into preallocated slots and a writer thread writes the files
// (pipeline/record). Stops after --duration / --frames, at the end of a replayed source,
// on SIGINT/SIGTERM, or at the first write error (full disk, unwritable folder): what was
// written is always a valid recording. A progress line every --progress-interval seconds;
// drops are reported at the end. Exit codes: 0 recorded (also when stopped by a signal),
// 1 writing failed (the recording holds the frames before the failure), 2 bad input.
// --blobs: the detector's blob lists (the pipeline's detect stages, the configuration's
// detection settings, every frame in order) in place of images, blobs/<camera>.blobs
// (formats/blob_file.h); --keep-images N also keeps every Nth frame's images as PGM.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "app/command_registry.h"
#include "app/config_flags.h"
#include "formats/recording.h"
#include "pipeline/pipeline.h"
#include "pipeline/record/frame_recorder.h"
#include "pipeline/record/recording_assets.h"
#include "pipeline/service/live_setup.h"

namespace mocap::app {
namespace {

std::atomic<int> g_record_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "used from a signal handler");

extern "C" void on_record_signal(int sig) {
  // relaxed: a lock-free atomic store is async-signal-safe; the main loop polls it.
  g_record_signal.store(sig, std::memory_order_relaxed);
}

constexpr int kExitWriteFailed = 1;

struct RecordArgs {
  std::string config;
  std::string out;
  double duration_s = 0.0;
  long long frames = 0;
  int buffer_frames = 64;
  double progress_interval_s = 1.0;
  service::CliOverrides cli;  // --rate, --loop-frames, --no-realtime (app/config_flags.h)
  bool duration_given = false, frames_given = false;
  bool blobs = false;
  long long keep_images = 0;
  bool keep_given = false;
};

Expected<void> check_args(const RecordArgs& a) {
  if (a.out.empty())
    return make_error("mocap record", "--out", "is required (the recording folder)");
  if (a.duration_given && a.frames_given)
    return make_error("mocap record", "--duration/--frames", "give one of them, not both");
  if (a.duration_given && !(a.duration_s > 0.0))
    return make_error("mocap record", "--duration", "must be > 0 seconds");
  if (a.frames_given && a.frames < 1)
    return make_error("mocap record", "--frames", "must be >= 1, got " + std::to_string(a.frames));
  if (a.keep_given && !a.blobs)
    return make_error("mocap record", "--keep-images",
                      "only with --blobs (an image recording keeps every image)");
  if (a.keep_given && (a.keep_images < 1 || a.keep_images > 1'000'000))
    return make_error("mocap record", "--keep-images",
                      "must be 1..1000000 (every Nth frame), got " + std::to_string(a.keep_images));
  if (!(a.progress_interval_s >= 0.0))
    return make_error("mocap record", "--progress-interval", "must be >= 0");
  return {};
}

std::uint64_t total(const std::vector<std::uint64_t>& v) {
  std::uint64_t t = 0;
  for (std::uint64_t x : v) t += x;
  return t;
}

// Data rate of the cameras as configured, MB/s (for the drop warning).
double camera_rate_mb_s(const record::RecorderOptions& o, double rate_hz) {
  double bytes = 0.0;
  for (const record::CameraGeometry& g : o.cameras)
    bytes += static_cast<double>(g.width) * g.height * bytes_per_pixel(g.format);
  return bytes * rate_hz / 1e6;
}

// Nothing lost silently: every frame triggered and not written, and every camera's frames
// without its image (the writer was behind, the camera missed the trigger, a replay's file
// was missing), in one line; a warning when anything was lost.
void report_losses(std::uint64_t triggered, const record::RecorderCounts& k) {
  std::string per_camera;
  std::uint64_t without = 0;
  for (std::size_t c = 0; c < k.without_image.size(); ++c) {
    per_camera +=
        (c > 0 ? ", cam" : "cam") + std::to_string(c) + " " + std::to_string(k.without_image[c]);
    without += k.without_image[c];
  }
  const std::uint64_t not_written = triggered > k.frames_written ? triggered - k.frames_written : 0;
  std::printf(
      "mocap record: %llu frames triggered, %llu written, %llu not written; frames written "
      "without a camera's image: %s\n",
      static_cast<unsigned long long>(triggered), static_cast<unsigned long long>(k.frames_written),
      static_cast<unsigned long long>(not_written), per_camera.c_str());
  if (not_written > 0 || without > 0)
    std::fprintf(stderr,
                 "mocap record: warning: %llu triggered frames were not written and %llu camera "
                 "images are missing from written frames (see the line above)\n",
                 static_cast<unsigned long long>(not_written),
                 static_cast<unsigned long long>(without));
}

int record(const RecordArgs& a) {
  if (auto r = check_args(a); !r) return fail(r.error().message);
  service::CliOverrides cli = a.cli;
  cli.no_iceoryx = true;
  auto cfg = service::resolve_run_config(a.config, cli, false);
  if (!cfg) return fail(cfg.error().message);
  if (cfg->cameras[0].backend == config::CameraBackend::kNode && !a.blobs)
    return fail(cfg->path +
                ": cameras[0].backend: node: node cameras send blob lists, no images: record "
                "them with `mocap record --blobs`");
  if (cfg->cameras[0].backend == config::CameraBackend::kNode && a.keep_given)
    return fail(cfg->path +
                ": cameras[0].backend: node: --keep-images: node cameras send no images");
  if (auto r = record::prepare_output_dir(a.out); !r) return fail(r.error().message);
  std::signal(SIGINT, on_record_signal);
  std::signal(SIGTERM, on_record_signal);
  auto live = service::LiveSetup::create(*cfg, stderr, "mocap record", false);
  if (!live) return fail(live.error().message);
  for (const std::string& n : (*live)->notices())
    std::fprintf(stderr, "mocap record: note: %s\n", n.c_str());
  auto assets = record::write_recording_assets(a.out, *cfg, (*live)->assets());
  if (!assets) return fail(assets.error().message);

  pipeline::PipelineOptions opt = (*live)->options();
  const bool lockstep = opt.pacing == pipeline::TriggerPacing::kLockstep;
  record::RecorderOptions ro;
  ro.dir = a.out;
  const std::vector<hal::Camera*> cams = (*live)->cameras();
  for (std::size_t c = 0; c < cams.size(); ++c) {  // every camera of the rig: one folder each
    const hal::CameraConfig& cc = cams[c]->config();
    const CameraModel& rig_camera = (*live)->assets().rig.cameras[c];
    ro.camera_names.push_back(rig_camera.name);
    // A node camera has no image size of its own (it sends blob lists): the rig's.
    const bool sized = cc.width > 0 && cc.height > 0;
    ro.cameras.push_back(record::CameraGeometry{sized ? cc.width : rig_camera.width,
                                                sized ? cc.height : rig_camera.height, cc.format});
  }
  ro.slots_per_camera = static_cast<std::uint32_t>(a.buffer_frames);
  // A replay ends with its source: the pipeline triggers its frames (lockstep: one frame
  // per trigger) and the recorder takes the source's frame numbers.
  std::uint64_t trigger_limit = a.frames_given ? static_cast<std::uint64_t>(a.frames) : 0;
  std::uint64_t frame_limit = trigger_limit;
  if (!a.frames_given && cfg->cameras[0].backend == config::CameraBackend::kReplay) {
    auto source = Recording::open(cfg->cameras[0].device);
    if (!source) return fail(source.error().message);
    trigger_limit = source->frames().size();
    frame_limit = static_cast<std::uint64_t>(source->frames().back().frame) + 1;
  }
  ro.max_frames = frame_limit;
  ro.wait_for_slot_ms = lockstep ? 1000 : 0;  // lockstep records every frame
  ro.pair_by = opt.pair_by;
  ro.pair_tolerance_ns = opt.pair_tolerance_us * 1000;
  ro.silent_after_ns = opt.silent_after_ns;  // a silent hardware-triggered node: go on
  ro.blobs = a.blobs;
  ro.max_blobs = static_cast<std::uint32_t>(cfg->tracker.detect.max_blobs);
  ro.keep_images_every = static_cast<std::uint32_t>(a.keep_images);
  auto recorder = record::FrameRecorder::create(ro);
  if (!recorder) return fail(recorder.error().message);
  // The images at the capture, or (--blobs) the blob lists of the pipeline's detect
  // stages, every frame in order.
  (*recorder)->attach(opt);
  opt.max_frames = trigger_limit;
  auto pipe = pipeline::Pipeline::create((*live)->take_processor(), (*live)->cameras(), {}, opt);
  if (!pipe) return fail(pipe.error().message);
  (*recorder)->start();
  if (g_record_signal.load(std::memory_order_relaxed) == 0) {
    if (auto r = (*pipe)->start(); !r) {
      (void)(*recorder)->finish();
      return fail(r.error().message);
    }
  }
  for (const std::string& n : (*pipe)->notes())
    std::fprintf(stderr, "mocap record: note: %s\n", n.c_str());
  std::fprintf(stderr, "mocap record: recording %s cameras at %.0f Hz into %s%s\n",
               config::to_string(cfg->cameras[0].backend), opt.trigger_rate_hz, a.out.c_str(),
               a.duration_given ? (" for " + std::to_string(a.duration_s) + " s").c_str()
                                : " (Ctrl-C stops)");

  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  auto last_report = t0;
  record::RecorderCounts last = (*recorder)->counts();
  Clock::time_point all_seen{};
  bool have_all_seen = false;
  while ((*pipe)->running() && g_record_signal.load(std::memory_order_relaxed) == 0) {
    if ((*recorder)->failed() || (*pipe)->finished()) break;
    if (a.duration_given && since(t0) >= a.duration_s) break;
    if (frame_limit != 0 && (*recorder)->frames_seen() >= frame_limit) {
      if (!have_all_seen) all_seen = Clock::now();
      have_all_seen = true;
      if (since(all_seen) > 0.5) break;  // free-running cameras: the last partner had time
    }
    if (a.progress_interval_s > 0.0 && since(last_report) >= a.progress_interval_s) {
      const double dt = since(last_report);
      last_report = Clock::now();
      const record::RecorderCounts k = (*recorder)->counts();
      std::fprintf(stderr, "mocap record: %.1f s, %llu frames, %llu dropped, %.1f MB/s\n",
                   since(t0), static_cast<unsigned long long>(k.frames_written),
                   static_cast<unsigned long long>(total(k.dropped)),
                   static_cast<double>(k.bytes_written - last.bytes_written) / 1e6 / dt);
      last = k;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  (*pipe)->stop();
  const double elapsed_s = since(t0);
  auto finished = (*recorder)->finish();
  const record::RecorderCounts k = (*recorder)->counts();
  std::uint64_t camera_drops = 0;
  for (hal::Camera* cam : (*live)->cameras()) camera_drops += cam->counters().dropped.get();
  if (a.blobs) {
    std::printf(
        "mocap record: %llu frames (%llu blob lists, %llu kept images, %.1f MB) in %.1f s "
        "written to %s\n",
        static_cast<unsigned long long>(k.frames_written),
        static_cast<unsigned long long>(k.blob_lists_written),
        static_cast<unsigned long long>(k.images_written),
        static_cast<double>(k.bytes_written) / 1e6, elapsed_s, a.out.c_str());
  } else {
    std::printf("mocap record: %llu frames (%llu images, %.1f MB) in %.1f s written to %s\n",
                static_cast<unsigned long long>(k.frames_written),
                static_cast<unsigned long long>(k.images_written),
                static_cast<double>(k.bytes_written) / 1e6, elapsed_s, a.out.c_str());
  }
  std::string per_camera;  // "cam0 N, cam1 N, ..."
  for (std::size_t c = 0; c < k.dropped.size(); ++c)
    per_camera +=
        (c > 0 ? ", cam" : "cam") + std::to_string(c) + " " + std::to_string(k.dropped[c]);
  if (a.blobs) {
    // Frames that never reached the recorder: the detect stage had no blob slot, or its
    // input ring was full (every_frame: a detector behind drops at the capture).
    std::uint64_t not_detected = 0;
    for (const auto& [name, value] : (*pipe)->stats().counters)
      if ((name.rfind("detect", 0) == 0 && name.find("_no_slot") != std::string::npos) ||
          name.rfind("capture_dropped_cam", 0) == 0)
        not_detected += value;
    std::printf(
        "mocap record: dropped blob lists: %s (writer behind); frames the pipeline did not "
        "detect: %llu; frames the cameras dropped: %llu\n",
        per_camera.c_str(), static_cast<unsigned long long>(not_detected),
        static_cast<unsigned long long>(camera_drops));
    if (k.kept_skipped > 0)
      std::fprintf(stderr,
                   "mocap record: warning: %llu images to keep were skipped (writer "
                   "behind)\n",
                   static_cast<unsigned long long>(k.kept_skipped));
  } else {
    std::printf(
        "mocap record: dropped images: %s (writer behind); "
        "frames the cameras dropped: %llu\n",
        per_camera.c_str(), static_cast<unsigned long long>(camera_drops));
  }
  if (!a.blobs && total(k.dropped) > 0) {
    std::fprintf(stderr,
                 "mocap record: warning: %llu images dropped because the disk wrote %.1f MB/s, "
                 "slower than the cameras' %.1f MB/s (their frames have missing files)\n",
                 static_cast<unsigned long long>(total(k.dropped)),
                 elapsed_s > 0.0 ? static_cast<double>(k.bytes_written) / 1e6 / elapsed_s : 0.0,
                 camera_rate_mb_s(ro, opt.trigger_rate_hz));
  }
  {
    // The triggers that found the source's end (a replay's, a node's) are no frames.
    const pipeline::PipelineStats stats = (*pipe)->stats();
    std::uint64_t past_end = 0;
    for (const auto& [name, value] : stats.counters)
      if (name == "triggers_past_end") past_end = value;
    report_losses(stats.triggered - std::min(past_end, stats.triggered), k);
  }
  if (!finished) {
    std::fprintf(stderr, "mocap: %s (the recording keeps the %llu frames written before)\n",
                 finished.error().message.c_str(),
                 static_cast<unsigned long long>(k.frames_written));
    return kExitWriteFailed;
  }
  if (const int sig = g_record_signal.load(std::memory_order_relaxed); sig != 0) {
    if (k.frames_written > 0) {
      std::fprintf(stderr, "mocap record: stopped by %s: %s is a valid recording\n",
                   sig == SIGINT ? "SIGINT" : "SIGTERM", a.out.c_str());
    } else {
      std::fprintf(stderr,
                   "mocap record: stopped by %s before the first frame: %s holds no frame\n",
                   sig == SIGINT ? "SIGINT" : "SIGTERM", a.out.c_str());
    }
  }
  return 0;
}

void register_record(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<RecordArgs>();
  CLI::App* cmd = app.add_subcommand(
      "record", "Record the cameras of the run configuration into a recording folder");
  cmd->add_option("--config", args->config,
                  "Record the cameras of this run configuration (default: the built-in "
                  "simulated cameras)");
  cmd->add_option("--out", args->out, "The recording folder to write (new or empty)");
  cmd->add_option("--duration", args->duration_s, "Stop after this many seconds");
  cmd->add_option("--frames", args->frames, "Stop after this many frames");
  add_rate_flag(*cmd, args->cli);
  add_loop_frames_flag(*cmd, args->cli);
  cmd->add_option("--buffer-frames", args->buffer_frames,
                  "Frames per camera the writer may fall behind before images are dropped "
                  "(power of two, default 64)");
  cmd->add_option("--progress-interval", args->progress_interval_s,
                  "Seconds between progress lines on stderr (default 1; 0: off)");
  cmd->add_flag("--blobs", args->blobs,
                "Record the detector's blob lists (blobs/<camera>.blobs) instead of images");
  cmd->add_option("--keep-images", args->keep_images,
                  "With --blobs: also keep every Nth frame's images as PGM, for inspection");
  add_no_realtime_flag(*cmd, args->cli);
  cmd->callback([cmd, args, &exit_code] {
    args->keep_given = cmd->count("--keep-images") > 0;
    args->duration_given = cmd->count("--duration") > 0;
    args->frames_given = cmd->count("--frames") > 0;
    exit_code = record(*args);
  });
}

const CommandRegistrar kRecordRegistrar(65, register_record);

}  // namespace
}  // namespace mocap::app
