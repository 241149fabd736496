#pragma once
// Built only when libcamera is found (ORTHOFACE_WITH_LIBCAMERA, defines ORTHOFACE_HAVE_LIBCAMERA).

#include <memory>
#include <string>
#include <vector>

#include "capture/camera.h"

namespace orthoface::capture {

// Opens the libcamera camera with id `id` (as listed by list_libcamera_devices, without the
// "libcamera:" prefix): viewfinder stream, FrameBufferAllocator buffers, requests re-queued as
// they complete, buffer timestamps (CLOCK_MONOTONIC, end of frame), converted to BGR.
// Throws std::runtime_error "no libcamera cameras found" when the system has none, naming the
// id when it is unknown or in use by another process.
std::unique_ptr<Camera> open_libcamera_camera(const std::string& id);

// The cameras libcamera sees ("libcamera:<id>"), with modes; empty when there are none.
std::vector<DeviceInfo> list_libcamera_devices();

}  // namespace orthoface::capture
