// The libcamera backend on a machine without cameras (CI, this build machine): the
// session starts, and opening any camera is the one-line "no camera found" error. On
// a machine with a camera, an unknown id is an error naming the available ones.
#include <gtest/gtest.h>

#ifdef MOCAP_HAVE_LIBCAMERA
#include "hal/libcamera_camera.h"

namespace mocap::hal {
namespace {

TEST(LibcameraCamera, MissingCameraIsAClearError) {
  auto session = LibcameraSession::get();
  ASSERT_TRUE(session.ok()) << session.error().message;
  auto again = LibcameraSession::get();  // one CameraManager per process: shared
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(session->get(), again->get());
  const auto ids = (*session)->camera_ids();
  auto cam = LibcameraCamera::open(*session, "no-such-camera");
  ASSERT_FALSE(cam.ok());
  if (ids.empty()) {
    EXPECT_EQ(cam.error().message, "libcamera: no camera found");
    auto by_index = LibcameraCamera::open(*session, "0");
    ASSERT_FALSE(by_index.ok());
    EXPECT_EQ(by_index.error().message, "libcamera: no camera found");
  } else {
    EXPECT_NE(
        cam.error().message.find("camera 'no-such-camera' not found (available: " + ids.front()),
        std::string::npos)
        << cam.error().message;
  }
  EXPECT_EQ(cam.error().message.find('\n'), std::string::npos);
}

TEST(LibcameraCamera, NullSessionIsAnError) {
  auto cam = LibcameraCamera::open(nullptr, "0");
  ASSERT_FALSE(cam.ok());
  EXPECT_EQ(cam.error().message, "libcamera: no session");
}

}  // namespace
}  // namespace mocap::hal
#endif
