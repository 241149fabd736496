// libcamera backend: this machine has no camera, so what can be tested is the path through
// CameraManager to "no cameras" and the clear message; with a camera the mode list is checked.
#include <gtest/gtest.h>

#include "capture/camera.h"
#ifdef ORTHOFACE_HAVE_LIBCAMERA
#include "capture/libcamera_camera.h"
#endif

namespace orthoface::capture {
namespace {

#ifdef ORTHOFACE_HAVE_LIBCAMERA
TEST(LibcameraCamera, NoCamerasGivesClearMessage) {
  const std::vector<DeviceInfo> cams = list_libcamera_devices();
  if (!cams.empty()) GTEST_SKIP() << "a libcamera camera is present: " << cams[0].id;
  try {
    open_camera("libcamera:/base/soc/i2c0/imx219@10");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no libcamera cameras found"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("libcamera:/base/soc/i2c0/imx219@10"), std::string::npos);
  }
}

TEST(LibcameraCamera, PresentCamerasListModes) {
  const std::vector<DeviceInfo> cams = list_libcamera_devices();
  if (cams.empty()) GTEST_SKIP() << "no libcamera camera on this machine";
  for (const DeviceInfo& d : cams) {
    EXPECT_EQ(d.id.rfind("libcamera:", 0), 0u);
    EXPECT_FALSE(d.formats.empty()) << d.id;
  }
}
#else
TEST(LibcameraCamera, NotBuiltSaysSo) {
  EXPECT_THROW(open_camera("libcamera:any"), std::runtime_error);
}
#endif

}  // namespace
}  // namespace orthoface::capture
