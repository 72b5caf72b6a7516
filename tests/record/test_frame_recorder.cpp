// Tests of record::FrameRecorder and record::RecordingFiles without cameras: frames are
// handed to the tap as the capture thread would, and the folder is read back with
// formats/recording.h (the reader of `mocap track`).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "pipeline/record/frame_recorder.h"
#include "pipeline/record/recording_assets.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"

namespace mocap::record {
namespace {

constexpr int kW = 64, kH = 48;

// A rig of `cameras` kW x kH cameras (for Recording::open).
void write_rig(const std::string& dir, int cameras = 2) {
  Rig rig;
  for (int c = 0; c < cameras; ++c) {
    CameraModel m;
    m.name = "cam" + std::to_string(c);
    m.width = kW;
    m.height = kH;
    m.fx = m.fy = 100.0;
    m.cx = kW / 2.0;
    m.cy = kH / 2.0;
    rig.cameras.push_back(m);
  }
  ASSERT_TRUE(save_rig(dir + "/rig.yaml", rig));
}

Image pattern(int camera, std::uint64_t frame, PixelFormat format = PixelFormat::kMono8) {
  Image im(kW, kH, format, format == PixelFormat::kMono8 ? 255 : 4095);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const auto v =
          static_cast<unsigned>(x * 3 + y * 5 + static_cast<int>(frame) * 7 + camera * 11);
      if (format == PixelFormat::kMono8) {
        im.row8(y)[x] = static_cast<std::uint8_t>(v & 0xff);
      } else {
        im.row16(y)[x] = static_cast<std::uint16_t>((v * 13) & 0xfff);
      }
    }
  return im;
}

hal::Frame frame_of(const Image& im, std::uint64_t seq) {
  hal::Frame f;
  f.image = im.view();
  f.sequence = seq;
  f.timestamp_ns = 1'000'000'000 + static_cast<std::int64_t>(seq) * 10'000'000;
  return f;
}

RecorderOptions options(const std::string& dir, PixelFormat format = PixelFormat::kMono8) {
  RecorderOptions o;
  o.dir = dir;
  o.camera_names = {"cam0", "cam1"};
  o.cameras = {CameraGeometry{kW, kH, format}, CameraGeometry{kW, kH, format}};
  o.slots_per_camera = 8;
  return o;
}

bool same_pixels(const Image& a, const Image& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.format() != b.format()) return false;
  return std::equal(a.data(), a.data() + a.size_bytes(), b.data());
}

TEST(FrameRecorder, WritesEveryFrameLosslesslyAndReadsBack) {
  for (PixelFormat format : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    test::TempDir dir("rec_unit");
    write_rig(dir.path());
    RecorderOptions o = options(dir.path(), format);
    o.wait_for_slot_ms = 5000;  // lossless (lockstep): the tap waits for the writer
    auto rec = FrameRecorder::create(o);
    ASSERT_TRUE(rec) << rec.error().message;
    (*rec)->start();
    for (std::uint64_t s = 100; s < 120; ++s) {
      for (int c = 0; c < 2; ++c) {
        if (s == 105 && c == 1) continue;  // camera 1 dropped frame 5
        const Image im = pattern(c, s, format);
        (*rec)->on_frame(c, frame_of(im, s));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_TRUE((*rec)->finish());
    EXPECT_EQ((*rec)->counts().frames_written, 20u);
    EXPECT_EQ((*rec)->counts().images_written, 39u);
    auto r = Recording::open(dir.path());
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->frames().size(), 20u);
    for (std::int64_t f = 0; f < 20; ++f) {
      EXPECT_EQ(r->frames()[static_cast<std::size_t>(f)].frame, f);
      EXPECT_EQ(r->frames()[static_cast<std::size_t>(f)].timestamp_ns,
                1'000'000'000 + (f + 100) * 10'000'000);
      for (int c = 0; c < 2; ++c) {
        Image got;
        auto load = r->load_frame(c, f, got);
        ASSERT_TRUE(load) << load.error().message;
        if (f == 5 && c == 1) {
          EXPECT_EQ(*load, FrameLoad::kMissing);
          continue;
        }
        ASSERT_EQ(*load, FrameLoad::kOk);
        EXPECT_TRUE(same_pixels(got, pattern(c, static_cast<std::uint64_t>(f) + 100, format)));
        EXPECT_EQ(got.maxval(), format == PixelFormat::kMono8 ? 255 : 4095);
      }
    }
  }
}

TEST(FrameRecorder, ThreeCamerasOneFolderEachAndOneRowPerFrame) {
  test::TempDir dir("rec_three");
  write_rig(dir.path(), 3);
  RecorderOptions o = options(dir.path());
  o.camera_names.push_back("cam2");
  o.cameras.push_back(CameraGeometry{kW, kH, PixelFormat::kMono8});
  o.wait_for_slot_ms = 5000;
  auto rec = FrameRecorder::create(o);
  ASSERT_TRUE(rec) << rec.error().message;
  (*rec)->start();
  for (std::uint64_t s = 0; s < 6; ++s) {
    for (int c = 0; c < 3; ++c) {
      if (s == 3 && c == 2) continue;  // camera 2 dropped frame 3: the others' images stay
      const Image im = pattern(c, s);
      (*rec)->on_frame(c, frame_of(im, s));
    }
  }
  ASSERT_TRUE((*rec)->finish());
  EXPECT_EQ((*rec)->counts().frames_written, 6u);
  EXPECT_EQ((*rec)->counts().images_written, 17u);
  EXPECT_EQ((*rec)->counts().not_written, 0u);
  ASSERT_EQ((*rec)->counts().dropped.size(), 3u);
  auto r = Recording::open(dir.path());
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->frames().size(), 6u);
  Image got;
  auto load = r->load_frame(2, 3, got);
  ASSERT_TRUE(load) << load.error().message;
  EXPECT_EQ(*load, FrameLoad::kMissing);
  load = r->load_frame(1, 3, got);
  ASSERT_TRUE(load) << load.error().message;
  ASSERT_EQ(*load, FrameLoad::kOk);
  EXPECT_TRUE(same_pixels(got, pattern(1, 3)));
}

TEST(FrameRecorder, DropsAndCountsWhenTheWriterIsBehind) {
  test::TempDir dir("rec_drop");
  write_rig(dir.path());
  auto rec = FrameRecorder::create(options(dir.path()));
  ASSERT_TRUE(rec);
  // Writer not started: the 8 slots per camera fill, the rest is dropped, never blocks.
  const Image im = pattern(0, 0);
  for (std::uint64_t s = 0; s < 12; ++s) (*rec)->on_frame(0, frame_of(im, s));
  EXPECT_EQ((*rec)->counts().dropped[0], 4u);
  EXPECT_EQ((*rec)->counts().dropped[1], 0u);
  ASSERT_TRUE((*rec)->finish());
  auto r = Recording::open(dir.path());
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->frames().size(), 8u);  // camera 0 only (camera 1 never delivered)
}

TEST(FrameRecorder, TheTapAllocatesNothing) {
  test::TempDir dir("rec_alloc");
  write_rig(dir.path());
  auto rec = FrameRecorder::create(options(dir.path()));
  ASSERT_TRUE(rec);
  (*rec)->start();
  const Image a = pattern(0, 0), b = pattern(1, 0);
  std::uint64_t allocations = 0;
  for (std::uint64_t s = 0; s < 40; ++s) {  // slots taken, copied, freed by the writer
    test::AllocationScope scope;
    (*rec)->on_frame(0, frame_of(a, s));
    (*rec)->on_frame(1, frame_of(b, s));
    allocations += scope.count();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(allocations, 0u);
  ASSERT_TRUE((*rec)->finish());
  EXPECT_GT((*rec)->counts().frames_written, 0u);
}

TEST(FrameRecorder, OutOfOrderPairingStillWritesIncreasingFrames) {
  test::TempDir dir("rec_order");
  write_rig(dir.path());
  auto rec = FrameRecorder::create(options(dir.path()));
  ASSERT_TRUE(rec);
  const Image im = pattern(0, 0);
  // Camera 1 stalls for frames 0..2, then delivers 3: 0..2 become camera-0-only frames,
  // written before frame 3 although the pair (3) completes first.
  for (std::uint64_t s = 0; s < 4; ++s) (*rec)->on_frame(0, frame_of(im, s));
  (*rec)->on_frame(1, frame_of(im, 3));
  ASSERT_TRUE((*rec)->finish());
  auto r = Recording::open(dir.path());
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->frames().size(), 4u);
  Image got;
  EXPECT_EQ(*r->load_frame(1, 2, got), FrameLoad::kMissing);
  EXPECT_EQ(*r->load_frame(1, 3, got), FrameLoad::kOk);
}

TEST(FrameRecorder, FullDiskEndsWithOneLineErrorAndAValidRecording) {
  test::TempDir dir("rec_full");
  write_rig(dir.path());
  RecorderOptions o = options(dir.path());
  const std::uint64_t image_bytes = kW * kH + 11;                     // "P5\n64 48\n255\n"
  o.byte_budget = 19 + 5 * (2 * image_bytes + 20) + image_bytes / 2;  // ~5 frames fit
  auto rec = FrameRecorder::create(o);
  ASSERT_TRUE(rec);
  (*rec)->start();
  for (std::uint64_t s = 0; s < 8; ++s) {
    for (int c = 0; c < 2; ++c) {
      const Image im = pattern(c, s);
      (*rec)->on_frame(c, frame_of(im, s));
    }
  }
  auto done = (*rec)->finish();
  ASSERT_FALSE(done);
  EXPECT_NE(done.error().message.find("No space left on device"), std::string::npos)
      << done.error().message;
  EXPECT_EQ(done.error().message.find('\n'), std::string::npos);
  EXPECT_TRUE((*rec)->failed());
  auto r = Recording::open(dir.path());
  ASSERT_TRUE(r) << r.error().message;
  const std::size_t n = r->frames().size();
  EXPECT_GE(n, 4u);
  EXPECT_LT(n, 8u);
  // frames.csv agrees with the files: every row has both files, no file without a row.
  for (std::size_t f = 0; f < n; ++f) {
    Image got;
    for (int c = 0; c < 2; ++c)
      EXPECT_EQ(*r->load_frame(c, static_cast<std::int64_t>(f), got), FrameLoad::kOk);
  }
  for (int c = 0; c < 2; ++c) {
    std::size_t files = 0;
    for (const auto& e :
         std::filesystem::directory_iterator(dir.path() + "/cam" + std::to_string(c))) {
      EXPECT_EQ(e.path().extension(), ".pgm") << e.path();
      ++files;
    }
    EXPECT_EQ(files, n);
  }
}

TEST(FrameRecorder, RejectsBadSlotCounts) {
  test::TempDir dir("rec_bad");
  RecorderOptions o = options(dir.path());
  o.slots_per_camera = 6;
  auto rec = FrameRecorder::create(o);
  ASSERT_FALSE(rec);
  EXPECT_NE(rec.error().message.find("--buffer-frames"), std::string::npos);
}

TEST(RecordingAssets, OutputFolderMustBeNewOrEmpty) {
  test::TempDir dir("rec_dir");
  EXPECT_TRUE(prepare_output_dir(dir.path()));           // empty: fine
  EXPECT_TRUE(prepare_output_dir(dir.file("a/b/new")));  // created with parents
  test::write_file(dir.file("a/b/new/x.txt"), "x");
  auto r = prepare_output_dir(dir.file("a/b/new"));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("not empty"), std::string::npos);
  auto f = prepare_output_dir(dir.file("a/b/new/x.txt"));
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("not a folder"), std::string::npos);
}

}  // namespace
}  // namespace mocap::record
