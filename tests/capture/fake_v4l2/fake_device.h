#pragma once
// A V4L2 capture device that exists only at the system-call boundary (see fake_preload.cpp).
// It follows the V4L2 rules a real UVC camera with videobuf2 follows: formats YUYV and MJPG at
// 320x240 / 640x480 / 1280x720, 30 or 15 fps, mmap streaming, CLOCK_MONOTONIC timestamps.
//
// Control (environment):
//   ORTHOFACE_FAKE_V4L2=/dev/video42[=frames.bgr][,/dev/video43[=side.bgr]]
//     device paths served, each optionally fed from a frame file written by another process
//     (header "OFV1", int32 width, int32 height, then width*height*3 BGR bytes; rewritten
//     atomically by rename). Without a file the device shows a moving test pattern.
//   ORTHOFACE_FAKE_V4L2_CTL=DIR  failure switches, by file name, for device /dev/videoN:
//     DIR/unplug-videoN  present: the device is gone (open -> ENOENT, open fds -> ENODEV);
//                        removed: it can be opened again (a new device instance)
//     DIR/eio-videoN     present: the next DQBUF fails with EIO (the file is then removed)
//     DIR/busy-videoN    present: S_FMT fails with EBUSY (the format is held elsewhere)
//   ORTHOFACE_FAKE_V4L2_OUTPUT=/dev/video50[=written.frames][,...]
//     video OUTPUT devices served, as v4l2loopback with exclusive_caps=1 shows them to a writer:
//     QUERYCAP says VIDEO_OUTPUT | STREAMING | READWRITE; the one format is YUYV at any even
//     size (S_FMT fills bytesperline and sizeimage; a capture-type format is EINVAL). Each
//     write() of exactly sizeimage bytes, and each QBUF while streaming, is a frame: appended to
//     the named file as a 16-byte header ("OFW1", int32 width, int32 height, int32 byte count,
//     host order) followed by the YUYV bytes. A write() of another size is EINVAL.

#include <linux/videodev2.h>
#include <poll.h>

#include <memory>
#include <string>

namespace fake_v4l2 {

class Device;

// True if `path` is one of the served device paths.
bool is_served(const char* path);
// False while the device is unplugged (ORTHOFACE_FAKE_V4L2_CTL/unplug-videoN exists).
bool is_plugged(const char* path);
// The device path of a fake fd (nullptr for other fds).
const char* path_of(int fd);
// Opens the device at `path`: returns a real eventfd standing for the device file, or -1 with
// errno set (ENOENT when unplugged). flags: the open() flags (O_NONBLOCK honoured).
int open_device(const char* path, int flags);
bool is_fake_fd(int fd);
// Records new_fd (from dup) as another name of fd's open file.
void dup_device(int fd, int new_fd);
// ioctl on a fake fd; returns 0 or -1 with errno, exactly as the kernel would.
int device_ioctl(int fd, unsigned long request, void* arg);
// write() on a fake fd: a frame for an output device, EINVAL for a capture device.
ssize_t device_write(int fd, const void* buf, size_t count);
// mmap of a buffer by its QUERYBUF offset; MAP_FAILED with errno on error.
void* device_mmap(void* addr, size_t length, int prot, int flags, int fd, off_t offset);
// poll events of a fake fd (POLLIN|POLLRDNORM when a buffer is done, POLLERR when not
// streaming, POLLERR|POLLHUP when unplugged).
short device_poll_events(int fd, short requested);
// Releases the fd's state (stops streaming if it owned the queue).
void close_device(int fd);

}  // namespace fake_v4l2
