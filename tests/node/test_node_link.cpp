// Tests of the central side of the camera nodes (pipeline/node/node_link.h,
// node_camera.h) against hand-made messages written to mocap/blobs on a DDS domain of
// the test's own: frames delivered in trigger order with their blobs; a duplicate, a late,
// a malformed, an oversized and an unknown camera's message counted and dropped; a silent
// camera's frames delivered missing once another node answered, then the camera down and
// back (reconnects); the end-of-stream message ends the camera's stream. A domain created
// for real time closes with its last participant.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "detect/blob.h"
#include "pipeline/node/node_camera.h"
#include "pipeline/node/node_dds.h"

namespace mocap::node {
namespace {

class NodeLinkTest : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = 1 + static_cast<std::uint32_t>((::getpid() * 7) % 231);
    // realtime: the link creates the domain (one SCHED_FIFO receive thread); the peer below
    // joins it.
    auto link = NodeLink::create(domain_, 0.3, true);  // 2 nodes configured, 1 peer: short
    ASSERT_TRUE(link) << link.error().message;
    link_ = std::move(link).value();
    for (const char* dev : {"n0/cam0", "n1/cam1"}) {
      auto cam = NodeCamera::open(link_, dev, 4, 50);
      ASSERT_TRUE(cam) << cam.error().message;
      hal::CameraConfig c = (*cam)->native_config();
      ASSERT_TRUE((*cam)->configure(c));
      cams_.push_back(std::move(cam).value());
    }
    auto d = NodeDomain::open(domain_, "test", true);
    ASSERT_TRUE(d) << d.error().message;
    peer_ = std::move(d).value();
    auto w = peer_.writer(peer_.blob_topic(), "test");
    ASSERT_TRUE(w);
    writer_ = *w;
    // A reader of the triggers, so that the link's start sees the "node" both ways.
    ASSERT_TRUE(peer_.reader(peer_.trigger_topic(), "test"));
  }
  void TearDown() override {
    for (auto& c : cams_) c->stop();
  }
  void send(const char* node, const char* camera, std::uint64_t number, std::uint32_t blobs,
            std::uint16_t version = kWireVersion, std::uint16_t flags = 0) {
    WireHeader h;
    set_name(h.node, node);
    set_name(h.camera, camera);
    h.version = version;
    h.flags = flags;
    h.frame_number = number;
    h.capture_ns = 1'000'000'000 + static_cast<std::int64_t>(number) * 10'000'000;
    h.blob_count = blobs;
    detect::BlobList list(blobs);
    for (std::uint32_t i = 0; i < blobs; ++i) {
      detect::Blob b;
      b.x_px = 10.5 + i;
      b.y_px = 20.25;
      b.x_min = b.x_max = 10;
      b.y_min = b.y_max = 20;
      b.roundness = 1.0f;
      list.push_back(b);
    }
    std::vector<std::uint8_t> bytes(blobs * kBlobRecordBytes + 1);
    encode_blobs(list, bytes.data(), bytes.size());
    mocap_node_BlobFrame s{};
    to_sample(h, s);
    s.blobs._length = s.blobs._maximum = blobs * static_cast<std::uint32_t>(kBlobRecordBytes);
    s.blobs._buffer = bytes.data();
    s.blobs._release = false;
    ASSERT_GE(dds_write(writer_, &s), 0);
  }
  // The next frame of camera c within 2 s (kOk), or the status.
  hal::CameraStatus next(int c, hal::Frame& f) {
    for (int i = 0; i < 200; ++i) {
      const hal::CameraStatus st = cams_[static_cast<std::size_t>(c)]->dequeue(f, 10);
      if (st != hal::CameraStatus::kTimeout) return st;
    }
    return hal::CameraStatus::kTimeout;
  }
  void wait_for_writer() {
    for (int i = 0; i < 300; ++i) {
      dds_publication_matched_status_t st{};
      dds_get_publication_matched_status(writer_, &st);
      if (st.current_count >= 1) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  std::uint32_t domain_ = 1;
  std::shared_ptr<NodeLink> link_;
  std::vector<std::unique_ptr<NodeCamera>> cams_;
  NodeDomain peer_;
  dds_entity_t writer_ = 0;
};

TEST_F(NodeLinkTest, DeliversInOrderAndCountsEveryBadMessage) {
  for (auto& c : cams_) ASSERT_TRUE(c->start());
  wait_for_writer();
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(cams_[0]->trigger(), hal::CameraStatus::kOk);
    ASSERT_EQ(cams_[1]->trigger(), hal::CameraStatus::kOk);
  }
  send("n0", "cam0", 0, 3);
  send("n0", "cam0", 0, 3);     // duplicate
  send("n0", "cam0", 1, 2, 7);  // malformed: version 7
  send("n0", "cam0", 1, 5);     // oversized: 5 > max_blobs 4
  send("n9", "cam0", 1, 1);     // unknown node
  send("n0", "cam0", 2, 1);     // frame 1 never comes: 2 first
  send("n1", "cam1", 0, 1);
  send("n1", "cam1", 1, 1);
  send("n1", "cam1", 2, 1);
  hal::Frame f;
  ASSERT_EQ(next(0, f), hal::CameraStatus::kOk);
  EXPECT_EQ(f.sequence, 0u);
  ASSERT_NE(f.blobs, nullptr);
  ASSERT_EQ(f.blobs->size(), 3u);
  EXPECT_EQ((*f.blobs)[1].x_px, 11.5);
  EXPECT_TRUE(f.image.empty());
  EXPECT_EQ(cams_[0]->release(f), hal::CameraStatus::kOk);
  ASSERT_EQ(next(0, f), hal::CameraStatus::kOk);  // 1: skipped by the node (2 came first)
  EXPECT_EQ(f.sequence, 1u);
  EXPECT_TRUE(f.missing);
  EXPECT_EQ(f.blobs, nullptr);
  cams_[0]->release(f);
  ASSERT_EQ(next(0, f), hal::CameraStatus::kOk);
  EXPECT_EQ(f.sequence, 2u);
  EXPECT_FALSE(f.missing);
  cams_[0]->release(f);
  for (std::uint64_t k = 0; k < 3; ++k) {
    ASSERT_EQ(next(1, f), hal::CameraStatus::kOk);
    EXPECT_EQ(f.sequence, k);
    cams_[1]->release(f);
  }
  EXPECT_EQ(cams_[0]->duplicates(), 1u);
  EXPECT_EQ(cams_[0]->counters().missing.get(), 1u);
  ASSERT_EQ(link_->nodes().size(), 2u);
  EXPECT_EQ(link_->nodes()[0]->malformed.get(), 1u);
  EXPECT_EQ(link_->nodes()[0]->oversized.get(), 1u);
  EXPECT_EQ(link_->unknown(), 1u);

  // A late frame (1, already delivered missing) is counted and dropped.
  send("n0", "cam0", 1, 1);
  ASSERT_EQ(cams_[0]->trigger(), hal::CameraStatus::kOk);  // 3
  ASSERT_EQ(cams_[1]->trigger(), hal::CameraStatus::kOk);
  send("n1", "cam1", 3, 1);
  send("n0", "cam0", 3, 1);
  ASSERT_EQ(next(0, f), hal::CameraStatus::kOk);
  EXPECT_EQ(f.sequence, 3u);
  cams_[0]->release(f);
  EXPECT_EQ(cams_[0]->late(), 1u);
}

TEST_F(NodeLinkTest, ASilentCameraGoesMissingThenDownThenComesBack) {
  for (auto& c : cams_) ASSERT_TRUE(c->start());
  wait_for_writer();
  hal::Frame f;
  // Node n0 is silent for frames 0..4, node n1 answers every one.
  for (std::uint64_t k = 0; k < 5; ++k) {
    cams_[0]->trigger();
    cams_[1]->trigger();
    send("n1", "cam1", k, 1);
    ASSERT_EQ(next(1, f), hal::CameraStatus::kOk);
    cams_[1]->release(f);
    ASSERT_EQ(next(0, f), hal::CameraStatus::kOk);  // after timeout_ms (50), then at once
    EXPECT_EQ(f.sequence, k);
    EXPECT_TRUE(f.missing);
    cams_[0]->release(f);
  }
  EXPECT_EQ(cams_[0]->counters().missing.get(), 5u);
  // n0 comes back.
  cams_[0]->trigger();
  cams_[1]->trigger();
  send("n0", "cam0", 5, 2);
  ASSERT_EQ(next(0, f), hal::CameraStatus::kOk);
  EXPECT_EQ(f.sequence, 5u);
  EXPECT_FALSE(f.missing);
  cams_[0]->release(f);
  EXPECT_EQ(cams_[0]->reconnects(), 1u);
  // The replay ends: end of stream (no frame invented for the trigger it answered).
  cams_[0]->trigger();
  send("n0", "cam0", 0, 0, kWireVersion, kWireEndOfStream);
  EXPECT_EQ(next(0, f), hal::CameraStatus::kEndOfStream);
}

TEST(NodeCameraOpen, RejectsABadDevice) {
  auto link = NodeLink::create(1 + static_cast<std::uint32_t>(::getpid() % 231), 0.0, false);
  ASSERT_TRUE(link);
  EXPECT_FALSE(NodeCamera::open(*link, "nocamera", 16, 100));
  EXPECT_FALSE(NodeCamera::open(*link, "a/b/c", 16, 100));
  EXPECT_FALSE(NodeCamera::open(*link, "a/b", 0, 100));
}

// A domain created for real time by one NodeDomain and joined by another outlives the
// first one closed, and goes with the last (the domain can then be created anew).
TEST(NodeDomainOpen, TheLastParticipantClosesTheDomainItCreated) {
  const auto id = 1 + static_cast<std::uint32_t>((::getpid() * 3) % 231);
  for (const bool creator_first : {true, false}) {
    auto a = std::make_unique<NodeDomain>();
    auto b = std::make_unique<NodeDomain>();
    {
      auto d = NodeDomain::open(id, "a", true);
      ASSERT_TRUE(d) << d.error().message;
      *a = std::move(d).value();
      auto e = NodeDomain::open(id, "b", true);  // the domain exists: joined
      ASSERT_TRUE(e) << e.error().message;
      *b = std::move(e).value();
    }
    (creator_first ? a : b).reset();
    const auto& left = creator_first ? b : a;
    EXPECT_GT(dds_get_parent(left->participant()), 0);  // still alive
    EXPECT_TRUE(left->writer(left->blob_topic(), "left"));
    EXPECT_EQ(dds_create_domain(id, ""), DDS_RETCODE_PRECONDITION_NOT_MET);
    (creator_first ? b : a).reset();
    const dds_entity_t again = dds_create_domain(id, "");  // gone with the last one
    EXPECT_GT(again, 0);
    if (again > 0) dds_delete(again);
  }
}

}  // namespace
}  // namespace mocap::node
