// The device model of the fake V4L2 camera (see fake_device.h).
#include "fake_device.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "device_model.h"

namespace fake_v4l2 {
namespace {
// Function-local statics: open() may be called by other libraries' constructors before ours.
std::mutex g_mutex;
std::map<std::string, std::shared_ptr<Device>>& devices() {  // path -> live instance
  static auto* m = new std::map<std::string, std::shared_ptr<Device>>;
  return *m;
}
struct OpenFile {
  std::shared_ptr<Device> device;
  int file = -1;  // the fd open() returned; dup()ed fds share it, as they share a struct file
};
std::map<int, OpenFile>& fds() {  // fake fd -> open file
  static auto* m = new std::map<int, OpenFile>;
  return *m;
}

OpenFile file_of(int fd) {
  std::lock_guard<std::mutex> lock(g_mutex);
  auto it = fds().find(fd);
  return it == fds().end() ? OpenFile{} : it->second;
}
std::shared_ptr<Device> device_of(int fd) { return file_of(fd).device; }

}  // namespace

bool is_served(const char* path) {
  return path && (served_paths().count(path) > 0 || output_paths().count(path) > 0);
}

bool is_plugged(const char* path) { return !file_exists(ctl_file(path, "unplug")); }

const char* path_of(int fd) {
  auto dev = device_of(fd);
  return dev ? dev->path().c_str() : nullptr;
}

int open_device(const char* path, int flags) {
  const auto paths = served_paths();
  const auto outputs = output_paths();
  auto p = paths.find(path);
  auto o = outputs.find(path);
  if (p == paths.end() && o == outputs.end()) return errno = ENOENT, -1;
  if (file_exists(ctl_file(path, "unplug"))) return errno = ENOENT, -1;
  std::lock_guard<std::mutex> lock(g_mutex);
  auto& dev = devices()[path];
  if (!dev || dev->gone())
    dev = o != outputs.end() ? std::make_shared<Device>(path, "", true, o->second)
                             : std::make_shared<Device>(path, p->second);
  const int fd = eventfd(0, EFD_CLOEXEC | ((flags & O_NONBLOCK) ? EFD_NONBLOCK : 0));
  if (fd < 0) return -1;
  fds()[fd] = {dev, fd};
  dev->open_file(fd);
  return fd;
}

void dup_device(int fd, int new_fd) {
  std::lock_guard<std::mutex> lock(g_mutex);
  auto it = fds().find(fd);
  if (it != fds().end()) fds()[new_fd] = it->second;
}

bool is_fake_fd(int fd) { return device_of(fd) != nullptr; }

int device_ioctl(int fd, unsigned long request, void* arg) {
  const OpenFile f = file_of(fd);
  if (!f.device) return errno = EBADF, -1;
  if (f.device->gone()) return errno = ENODEV, -1;
  return f.device->ioctl(f.file, request, arg);
}

ssize_t device_write(int fd, const void* buf, size_t count) {
  const OpenFile f = file_of(fd);
  if (!f.device) return errno = EBADF, -1;
  if (f.device->gone()) return errno = ENODEV, -1;
  return f.device->write(f.file, buf, count);
}

void* device_mmap(void* addr, size_t length, int prot, int flags, int fd, off_t offset) {
  auto dev = device_of(fd);
  if (!dev) return errno = EBADF, MAP_FAILED;
  if (dev->gone()) return errno = ENODEV, MAP_FAILED;
  return dev->mmap(addr, length, prot, flags, offset);
}

short device_poll_events(int fd, short requested) {
  const OpenFile f = file_of(fd);
  if (!f.device) return POLLNVAL;
  if (f.device->gone()) return POLLERR | POLLHUP;
  return f.device->poll_events(f.file, requested);
}

void close_device(int fd) {
  OpenFile f;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    auto it = fds().find(fd);
    if (it == fds().end()) return;
    f = it->second;
    fds().erase(it);
    for (const auto& [other, of] : fds())
      if (of.file == f.file) {
        if (fd == f.file) {  // keep a live fd as the file's name (the eventfd is shared)
          for (auto& [o, g] : fds())
            if (g.file == f.file) g.file = other;
          f.device->rename_owner(fd, other);
        }
        return;
      }
  }
  f.device->release(f.file);
}

}  // namespace fake_v4l2
