// `mocap preview [--config FILE] --out DIR [--frames N]`: aiming and exposure help. Runs
// the cameras of the run configuration (default: the built-in simulated cameras) through
// `mocap run`'s camera layer and pipeline (service::LiveSetup, pipeline::Pipeline) until
// each camera delivered N images (default 1; take a later one while exposure settles),
// then reviews the last image of each camera with the configured detector thresholds
// (detect::review_blobs) and writes DIR/<camera>.png (detect::draw_blob_overlay: accepted
// blobs with their centroid, rejected ones with the reason), DIR/preview.json (counts,
// sizes, peak brightness against the thresholds, every blob) and one summary line plus
// one recommendation line per camera on stdout. DIR is created when missing; its preview
// files are replaced (preview is run again and again while aiming).
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "app/command_registry.h"
#include "app/config_flags.h"
#include "detect/blob_review.h"
#include "formats/png_writer.h"
#include "pipeline/pipeline.h"
#include "pipeline/record/snapshot_tap.h"
#include "pipeline/service/live_setup.h"

namespace mocap::app {
namespace {

std::atomic<int> g_preview_signal{0};

extern "C" void on_preview_signal(int sig) {
  // relaxed: async-signal-safe lock-free store; the main loop polls it.
  g_preview_signal.store(sig, std::memory_order_relaxed);
}

struct PreviewArgs {
  std::string config, out;
  long long frames = 1;
  service::CliOverrides cli;  // --loop-frames (app/config_flags.h)
};

// A JSON string literal.
std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      char esc[8];
      std::snprintf(esc, sizeof esc, "\\u%04x", static_cast<unsigned>(ch));
      out += esc;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string camera_json(const std::string& name, const std::string& png,
                        const detect::BlobReview& r, const std::string& recommendation) {
  const detect::DetectorConfig& c = r.config;
  std::string j = "{\"camera\": " + json_string(name) + ", \"image\": " + json_string(png);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                ", \"maxval\": %u, \"image_peak_dn\": %u, \"blob_peak_dn\": %u, "
                "\"threshold_dn\": %u, \"background_dn\": %.1f, \"noise_dn\": %.2f, "
                "\"accepted\": %d, \"rejected\": {\"too_small\": %d, \"too_large\": %d, "
                "\"border\": %d, \"elongated\": %d}, \"saturated\": %d, \"merged\": %d, "
                "\"overflow\": %s, \"area_px\": {\"min\": %.1f, \"median\": %.1f, \"max\": %.1f}, "
                "\"thresholds\": {\"min_area_px\": %d, \"max_area_px\": %d, "
                "\"max_elongation\": %.3f, \"border\": \"%s\"}",
                r.maxval, r.image_peak_dn, r.blob_peak_dn, r.threshold_dn, r.background_dn,
                r.noise_dn, r.accepted, r.rejected[1], r.rejected[2], r.rejected[3], r.rejected[4],
                r.saturated, r.merged, r.overflow ? "true" : "false", r.area_min_px,
                r.area_median_px, r.area_max_px, c.min_area_px, c.max_area_px, c.max_elongation,
                c.border == detect::BorderPolicy::kReject ? "reject" : "flag");
  j += buf;
  j += ", \"recommendation\": " + json_string(recommendation) + ", \"blobs\": [";
  for (std::size_t i = 0; i < r.blobs.size(); ++i) {
    const detect::ReviewedBlob& b = r.blobs[i];
    std::snprintf(buf, sizeof buf,
                  "%s{\"x_px\": %.3f, \"y_px\": %.3f, \"area_px\": %.1f, \"peak_dn\": %u, "
                  "\"elongation\": %.3f, \"verdict\": \"%s\", \"saturated\": %s}",
                  i == 0 ? "" : ", ", b.blob.x_px, b.blob.y_px, static_cast<double>(b.blob.area_px),
                  b.blob.peak_dn, b.elongation, detect::to_string(b.verdict),
                  b.blob.has(detect::kBlobSaturated) ? "true" : "false");
    j += buf;
  }
  return j + "]}";
}

int preview(const PreviewArgs& a) {
  if (a.out.empty()) return fail("mocap preview: --out: is required (the folder for the pictures)");
  if (a.frames < 1)
    return fail("mocap preview: --frames: must be >= 1, got " + std::to_string(a.frames));
  service::CliOverrides cli = a.cli;
  cli.no_realtime = true;  // a diagnostic: no SCHED_FIFO needed
  cli.no_iceoryx = true;
  auto cfg = service::resolve_run_config(a.config, cli, false);
  if (!cfg) return fail(cfg.error().message);
  if (cfg->cameras[0].backend == config::CameraBackend::kNode)
    return fail(cfg->path +
                ": cameras[0].backend: node: this command needs images; camera nodes send blobs "
                "(run `mocap preview` on the node PC with its cameras)");
  std::error_code ec;
  std::filesystem::create_directories(a.out, ec);
  if (ec || !std::filesystem::is_directory(a.out, ec))
    return fail(a.out + ": cannot create the folder" + (ec ? ": " + ec.message() : std::string()));
  std::signal(SIGINT, on_preview_signal);
  std::signal(SIGTERM, on_preview_signal);
  auto live = service::LiveSetup::create(*cfg, stderr, "mocap preview", false);
  if (!live) return fail(live.error().message);
  std::vector<hal::CameraConfig> cams;
  for (const hal::Camera* cam : (*live)->cameras()) cams.push_back(cam->config());
  record::SnapshotTap tap(cams, static_cast<std::uint64_t>(a.frames));
  pipeline::PipelineOptions opt = (*live)->options();
  opt.tap = &tap;
  opt.max_frames = static_cast<std::uint64_t>(a.frames);
  auto pipe = pipeline::Pipeline::create((*live)->take_processor(), (*live)->cameras(), {}, opt);
  if (!pipe) return fail(pipe.error().message);
  if (auto r = (*pipe)->start(); !r) return fail(r.error().message);
  const auto t0 = std::chrono::steady_clock::now();
  while (!tap.done() && !(*pipe)->finished() && g_preview_signal.load() == 0 &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(10))
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  (*pipe)->stop();
  std::string json = "{\"cameras\": [";
  const detect::DetectorConfig& dc = cfg->tracker.detect;
  for (int c = 0; c < static_cast<int>(cams.size()); ++c) {
    const std::string& name = (*live)->assets().rig.cameras[static_cast<std::size_t>(c)].name;
    if (tap.count(c) == 0)
      return fail(name + ": no image within 10 s (camera " + std::to_string(c) + ")");
    const ImageView view = tap.image(c).view();
    auto review = detect::review_blobs(dc, view);
    if (!review) return fail(review.error().message);
    const std::string png = name + ".png";
    if (auto w = write_png(a.out + "/" + png, detect::draw_blob_overlay(view, *review)); !w)
      return fail(w.error().message);
    const std::string rec = detect::recommend(*review);
    const int rejected =
        review->rejected[1] + review->rejected[2] + review->rejected[3] + review->rejected[4];
    std::printf(
        "%s: %d accepted (area %.0f..%.0f px), %d rejected (%d too small, %d too large, "
        "%d border, %d elongated); peak %u of %u, threshold %u (background %.0f, noise "
        "%.1f)\n",
        name.c_str(), review->accepted, review->area_min_px, review->area_max_px, rejected,
        review->rejected[1], review->rejected[2], review->rejected[3], review->rejected[4],
        review->image_peak_dn, review->maxval, review->threshold_dn, review->background_dn,
        review->noise_dn);
    std::printf("%s: %s\n", name.c_str(), rec.c_str());
    json += (c == 0 ? "" : ", ") + camera_json(name, png, *review, rec);
  }
  json += "]}\n";
  const std::string json_path = a.out + "/preview.json";
  std::FILE* f = std::fopen(json_path.c_str(), "w");
  const bool ok = f != nullptr && std::fwrite(json.data(), 1, json.size(), f) == json.size();
  if ((f != nullptr && std::fclose(f) != 0) || !ok) return fail(json_path + ": cannot write");
  return 0;
}

void register_preview(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<PreviewArgs>();
  CLI::App* cmd = app.add_subcommand(
      "preview", "Aim the cameras and set exposure: blob overlay PNGs and a summary per camera");
  cmd->add_option("--config", args->config,
                  "The run configuration's cameras (default: the built-in simulated cameras)");
  cmd->add_option("--out", args->out, "Folder for <camera>.png and preview.json");
  cmd->add_option("--frames", args->frames, "Review the N-th image of each camera (default 1)");
  add_loop_frames_flag(*cmd, args->cli);
  cmd->callback([args, &exit_code] { exit_code = preview(*args); });
}

const CommandRegistrar kPreviewRegistrar(66, register_preview);

}  // namespace
}  // namespace mocap::app
