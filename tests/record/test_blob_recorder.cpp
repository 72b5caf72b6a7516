// Tests of record::FrameRecorder in blob mode (`mocap record --blobs`) without cameras:
// the capture thread numbers the frames (on_frame) and one thread per camera hands over
// its blob lists as the detect stages do (on_blobs, allocation-free); the folder is read
// back with formats/recording.h. Concurrency label: also under TSan.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>

#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "pipeline/record/frame_recorder.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"

namespace mocap::record {
namespace {

constexpr int kBlobW = 40, kBlobH = 30;

void write_blob_rig(const std::string& dir) {
  Rig rig;
  for (int c = 0; c < 2; ++c) {
    CameraModel m;
    m.name = "cam" + std::to_string(c);
    m.width = kBlobW;
    m.height = kBlobH;
    m.fx = m.fy = 100.0;
    m.cx = kBlobW / 2.0;
    m.cy = kBlobH / 2.0;
    rig.cameras.push_back(m);
  }
  ASSERT_TRUE(save_rig(dir + "/rig.yaml", rig));
}

// Camera c's blobs of frame number f: (f + c) % 5 blobs with distinct centroids.
void blobs_of(int c, std::int64_t f, detect::BlobList& out) {
  out.clear();
  out.set_levels({10.0 + static_cast<double>(f), 1.25, 30.0 + c});
  for (int k = 0; k < static_cast<int>((f + c) % 5); ++k) {
    detect::Blob b;
    b.x_px = static_cast<double>(f) * 10.0 + k + 1.0 / 3.0;
    b.y_px = c + 0.1 * k;
    b.area_px = static_cast<float>(k + 1);
    b.flags = static_cast<std::uint32_t>(k);
    out.push_back(b);
  }
}

Image blob_test_image(int c, std::int64_t f) {
  Image im(kBlobW, kBlobH, PixelFormat::kMono8, 255);
  for (int y = 0; y < kBlobH; ++y)
    for (int x = 0; x < kBlobW; ++x)
      im.row8(y)[x] = static_cast<std::uint8_t>((x + 3 * y + 7 * f + 11 * c) & 0xff);
  return im;
}

// Blob-mode options of a two-camera recorder into `dir` (the tests set the rest).
RecorderOptions two_camera_options(const std::string& dir) {
  RecorderOptions o;
  o.dir = dir;
  o.camera_names = {"cam0", "cam1"};
  o.cameras = {CameraGeometry{kBlobW, kBlobH, PixelFormat::kMono8},
               CameraGeometry{kBlobW, kBlobH, PixelFormat::kMono8}};
  o.blobs = true;
  return o;
}

TEST(BlobRecorder, WritesEveryBlobListAndTheKeptImagesFromTheDetectThreads) {
  test::TempDir dir("rec_blobs");
  write_blob_rig(dir.path());
  RecorderOptions o = two_camera_options(dir.path());
  o.slots_per_camera = 4;
  o.wait_for_slot_ms = 5000;  // lossless (lockstep): the tap waits for the writer
  o.blobs = true;
  o.max_blobs = 8;
  o.keep_images_every = 4;
  auto rec = FrameRecorder::create(o);
  ASSERT_TRUE(rec) << rec.error().message;
  (*rec)->start();
  constexpr std::uint64_t kFirst = 500, kFrames = 24;
  // Images and lists prepared before the threads run (they must not allocate).
  std::vector<Image> images[2];
  std::vector<detect::BlobList> lists[2];
  for (int c = 0; c < 2; ++c)
    for (std::uint64_t f = 0; f < kFrames; ++f) {
      images[c].push_back(blob_test_image(c, static_cast<std::int64_t>(f)));
      lists[c].emplace_back(8);
      blobs_of(c, static_cast<std::int64_t>(f), lists[c].back());
    }
  std::atomic<std::uint64_t> captured{0};  // frames on_frame has seen (both cameras)
  std::uint64_t allocations[2] = {0, 0};
  auto detect_thread = [&](int c) {
    test::AllocationScope scope;
    for (std::uint64_t f = 0; f < kFrames; ++f) {
      // acquire: the frame was numbered (on_frame) before, as the capture ring orders it.
      while (captured.load(std::memory_order_acquire) <= f) std::this_thread::yield();
      hal::Frame fr;
      fr.image = images[c][f].view();
      fr.sequence = kFirst + f;
      fr.timestamp_ns = 2'000'000'000 + static_cast<std::int64_t>(f) * 4'000'000;
      const bool present = !(c == 1 && f == 5);  // camera 1 dropped frame 5
      fr.missing = !present;
      (*rec)->on_blobs(c, fr, present, lists[c][f]);
    }
    allocations[c] = scope.count();
  };
  std::thread d0(detect_thread, 0), d1(detect_thread, 1);
  for (std::uint64_t f = 0; f < kFrames; ++f) {
    for (int c = 0; c < 2; ++c) {
      hal::Frame fr;
      fr.image = images[c][f].view();
      fr.sequence = kFirst + f;
      (*rec)->on_frame(c, fr);
    }
    captured.store(f + 1, std::memory_order_release);
  }
  d0.join();
  d1.join();
  ASSERT_TRUE((*rec)->finish());
  EXPECT_EQ(allocations[0], 0u);
  EXPECT_EQ(allocations[1], 0u);
  const RecorderCounts k = (*rec)->counts();
  EXPECT_EQ(k.frames_written, kFrames);
  EXPECT_EQ(k.blob_lists_written, 2 * kFrames - 1);
  EXPECT_EQ(k.images_written, 12u);  // frames 0, 4, ..., 20 of both cameras
  EXPECT_EQ(k.dropped[0] + k.dropped[1] + k.kept_skipped, 0u);

  auto r = Recording::open(dir.path());
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE(r->has_blobs());
  EXPECT_TRUE(r->warnings().empty());
  ASSERT_EQ(r->frames().size(), kFrames);
  detect::BlobList got(8), want(8);
  std::vector<std::uint8_t> scratch;
  for (std::int64_t f = 0; f < static_cast<std::int64_t>(kFrames); ++f) {
    EXPECT_EQ(r->frames()[static_cast<std::size_t>(f)].frame, f);
    for (int c = 0; c < 2; ++c) {
      auto load = r->load_blobs(c, f, got, scratch);
      ASSERT_TRUE(load) << load.error().message;
      if (c == 1 && f == 5) {
        EXPECT_EQ(*load, FrameLoad::kMissing);
        continue;
      }
      ASSERT_EQ(*load, FrameLoad::kOk);
      blobs_of(c, f, want);
      ASSERT_EQ(got.size(), want.size()) << c << " " << f;
      EXPECT_EQ(got.levels().background_dn, want.levels().background_dn);
      EXPECT_EQ(got.levels().threshold_dn, want.levels().threshold_dn);
      for (std::size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].x_px, want[i].x_px);
        EXPECT_EQ(got[i].y_px, want[i].y_px);
        EXPECT_EQ(got[i].flags, want[i].flags);
      }
      Image im;
      auto kept = r->load_frame(c, f, im);
      ASSERT_TRUE(kept);
      EXPECT_EQ(*kept, f % 4 == 0 ? FrameLoad::kOk : FrameLoad::kMissing) << c << " " << f;
      if (*kept == FrameLoad::kOk) {
        const Image expect = blob_test_image(c, f);
        EXPECT_TRUE(std::equal(im.data(), im.data() + im.size_bytes(), expect.data()));
      }
    }
  }
}

// A hardware-triggered camera node that goes silent (camera 1 never delivers): after
// its silent_after_ns bound the frames are written without it, each counted in
// without_image, instead of waiting for it until every slot is taken and then dropping
// the frames of the cameras that do deliver.
TEST(BlobRecorder, ASilentCameraDoesNotStallTheRecording) {
  test::TempDir dir("rec_blobs_silent");
  write_blob_rig(dir.path());
  RecorderOptions o = two_camera_options(dir.path());
  o.slots_per_camera = 16;
  o.blobs = true;
  o.max_blobs = 8;
  o.silent_after_ns[1] = 10'000'000;  // 10 ms: 5 frame periods of 2 ms
  auto rec = FrameRecorder::create(o);
  ASSERT_TRUE(rec) << rec.error().message;
  (*rec)->start();
  constexpr std::uint64_t kFrames = 40;
  detect::BlobList list(8);
  Image image = blob_test_image(0, 0);
  for (std::uint64_t f = 0; f < kFrames; ++f) {
    hal::Frame fr;
    fr.image = image.view();
    fr.sequence = 100 + f;
    fr.timestamp_ns = 1'000'000'000 + static_cast<std::int64_t>(f) * 2'000'000;
    blobs_of(0, static_cast<std::int64_t>(f), list);
    (*rec)->on_frame(0, fr);
    (*rec)->on_blobs(0, fr, true, list);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE((*rec)->finish());
  const RecorderCounts k = (*rec)->counts();
  EXPECT_EQ(k.frames_written, kFrames);
  EXPECT_EQ(k.dropped[0], 0u);
  EXPECT_EQ(k.without_image[0], 0u);
  EXPECT_EQ(k.without_image[1], kFrames);
  auto r = Recording::open(dir.path());
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->frames().size(), kFrames);
  detect::BlobList got(8);
  std::vector<std::uint8_t> scratch;
  for (std::uint64_t f = 0; f < kFrames; ++f) {
    const auto n = static_cast<std::int64_t>(f);
    auto c0 = r->load_blobs(0, n, got, scratch);
    ASSERT_TRUE(c0) << c0.error().message;
    EXPECT_EQ(*c0, FrameLoad::kOk) << f;
    EXPECT_EQ(got.size(), static_cast<std::size_t>(f % 5)) << f;
    auto c1 = r->load_blobs(1, n, got, scratch);
    ASSERT_TRUE(c1) << c1.error().message;
    EXPECT_EQ(*c1, FrameLoad::kMissing) << f;
  }
}

TEST(BlobRecorder, NoCameraFoldersWithoutKeptImages) {
  test::TempDir dir("rec_blobs_nokeep");
  RecorderOptions o = two_camera_options(dir.path());
  o.blobs = true;
  o.max_blobs = 0;
  EXPECT_FALSE(FrameRecorder::create(o));  // a capacity of 0 blobs is refused
  o.max_blobs = 8;
  auto rec = FrameRecorder::create(o);
  ASSERT_TRUE(rec) << rec.error().message;
  ASSERT_TRUE((*rec)->finish());
  EXPECT_TRUE(std::filesystem::exists(dir.file("blobs/cam0.blobs")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("blobs/cam1.blobs")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("cam0")));
}

}  // namespace
}  // namespace mocap::record
