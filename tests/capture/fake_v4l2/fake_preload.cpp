// LD_PRELOAD entry points: the system calls a V4L2 client makes, answered by the fake device
// for the served paths (fake_device.h) and passed to libc for everything else.
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <sys/mman.h>
#include <sys/select.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "fake_device.h"

namespace {

template <typename F>
F real(const char* name) {
  return reinterpret_cast<F>(dlsym(RTLD_NEXT, name));
}

int mode_arg(int flags, va_list ap) {
  return (flags & O_CREAT) || (flags & __O_TMPFILE) == __O_TMPFILE ? va_arg(ap, int) : 0;
}

double now_ms() {
  using namespace std::chrono;
  return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

// poll() over a set that holds fake fds: their events come from the device model, the rest
// from the kernel with short waits, until something is ready or the timeout passes.
int fake_poll(pollfd* fds, nfds_t n, int timeout_ms) {
  static auto real_poll = real<int (*)(pollfd*, nfds_t, int)>("poll");
  const double deadline = now_ms() + timeout_ms;
  std::vector<pollfd> others;
  for (;;) {
    int ready = 0;
    others.clear();
    for (nfds_t i = 0; i < n; ++i) {
      if (fake_v4l2::is_fake_fd(fds[i].fd)) {
        fds[i].revents = fake_v4l2::device_poll_events(fds[i].fd, fds[i].events);
        ready += fds[i].revents != 0;
      } else {
        others.push_back(fds[i]);
      }
    }
    const double left = timeout_ms < 0 ? 2.0 : deadline - now_ms();
    const int wait = ready ? 0 : int(std::clamp(left, 0.0, 2.0));
    const int r = others.empty() ? 0 : real_poll(others.data(), others.size(), wait);
    if (r < 0) return r;
    if (others.empty() && !ready && wait > 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(wait));
    for (nfds_t i = 0, k = 0; i < n; ++i)
      if (!fake_v4l2::is_fake_fd(fds[i].fd)) fds[i].revents = others[k++].revents;
    ready += r;
    if (ready || (timeout_ms >= 0 && now_ms() >= deadline)) return ready;
  }
}

}  // namespace

extern "C" {

int open(const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const int mode = mode_arg(flags, ap);
  va_end(ap);
  if (fake_v4l2::is_served(path)) return fake_v4l2::open_device(path, flags);
  static auto f = real<int (*)(const char*, int, ...)>("open");
  return f(path, flags, mode);
}

int open64(const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const int mode = mode_arg(flags, ap);
  va_end(ap);
  if (fake_v4l2::is_served(path)) return fake_v4l2::open_device(path, flags);
  static auto f = real<int (*)(const char*, int, ...)>("open64");
  return f(path, flags, mode);
}

int __open_2(const char* path, int flags) { return open(path, flags); }
int __open64_2(const char* path, int flags) { return open64(path, flags); }

int openat(int dirfd, const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const int mode = mode_arg(flags, ap);
  va_end(ap);
  if (fake_v4l2::is_served(path)) return fake_v4l2::open_device(path, flags);
  static auto f = real<int (*)(int, const char*, int, ...)>("openat");
  return f(dirfd, path, flags, mode);
}

int openat64(int dirfd, const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const int mode = mode_arg(flags, ap);
  va_end(ap);
  if (fake_v4l2::is_served(path)) return fake_v4l2::open_device(path, flags);
  static auto f = real<int (*)(int, const char*, int, ...)>("openat64");
  return f(dirfd, path, flags, mode);
}

int ioctl(int fd, unsigned long request, ...) {
  va_list ap;
  va_start(ap, request);
  void* arg = va_arg(ap, void*);
  va_end(ap);
  if (fake_v4l2::is_fake_fd(fd)) return fake_v4l2::device_ioctl(fd, request, arg);
  static auto f = real<int (*)(int, unsigned long, ...)>("ioctl");
  return f(fd, request, arg);
}

void* mmap(void* addr, size_t length, int prot, int flags, int fd, off_t offset) {
  if (fd >= 0 && fake_v4l2::is_fake_fd(fd))
    return fake_v4l2::device_mmap(addr, length, prot, flags, fd, offset);
  static auto f = real<void* (*)(void*, size_t, int, int, int, off_t)>("mmap");
  return f(addr, length, prot, flags, fd, offset);
}

void* mmap64(void* addr, size_t length, int prot, int flags, int fd, off_t offset) {
  return mmap(addr, length, prot, flags, fd, offset);
}

int poll(pollfd* fds, nfds_t n, int timeout_ms) {
  for (nfds_t i = 0; i < n; ++i)
    if (fake_v4l2::is_fake_fd(fds[i].fd)) return fake_poll(fds, n, timeout_ms);
  static auto f = real<int (*)(pollfd*, nfds_t, int)>("poll");
  return f(fds, n, timeout_ms);
}

int select(int nfds, fd_set* rd, fd_set* wr, fd_set* ex, timeval* tv) {
  std::vector<pollfd> p;
  bool any_fake = false;
  for (int fd = 0; fd < nfds; ++fd) {
    short ev = 0;
    if (rd && FD_ISSET(fd, rd)) ev |= POLLIN;
    if (wr && FD_ISSET(fd, wr)) ev |= POLLOUT;
    if (ex && FD_ISSET(fd, ex)) ev |= POLLPRI;
    if (ev) p.push_back({fd, ev, 0});
    any_fake |= ev && fake_v4l2::is_fake_fd(fd);
  }
  if (!any_fake) {
    static auto f = real<int (*)(int, fd_set*, fd_set*, fd_set*, timeval*)>("select");
    return f(nfds, rd, wr, ex, tv);
  }
  const int timeout = tv ? int(tv->tv_sec * 1000 + tv->tv_usec / 1000) : -1;
  const int r = fake_poll(p.data(), p.size(), timeout);
  if (r < 0) return r;
  if (rd) FD_ZERO(rd);
  if (wr) FD_ZERO(wr);
  if (ex) FD_ZERO(ex);
  int count = 0;
  for (const pollfd& q : p) {  // kernel select: POLLERR counts as readable and writable
    if (rd && (q.events & POLLIN) && (q.revents & (POLLIN | POLLERR | POLLHUP)))
      FD_SET(q.fd, rd), ++count;
    if (wr && (q.events & POLLOUT) && (q.revents & (POLLOUT | POLLERR))) FD_SET(q.fd, wr), ++count;
    if (ex && (q.events & POLLPRI) && (q.revents & POLLPRI)) FD_SET(q.fd, ex), ++count;
  }
  return count;
}

ssize_t read(int fd, void* buf, size_t count) {
  if (fake_v4l2::is_fake_fd(fd)) return errno = EINVAL, -1;  // no read() I/O offered
  static auto f = real<ssize_t (*)(int, void*, size_t)>("read");
  return f(fd, buf, count);
}

ssize_t write(int fd, const void* buf, size_t count) {
  if (fake_v4l2::is_fake_fd(fd)) return fake_v4l2::device_write(fd, buf, count);
  static auto f = real<ssize_t (*)(int, const void*, size_t)>("write");
  return f(fd, buf, count);
}

int dup(int fd) {
  static auto f = real<int (*)(int)>("dup");
  const int r = f(fd);
  if (r >= 0 && fake_v4l2::is_fake_fd(fd)) fake_v4l2::dup_device(fd, r);
  return r;
}

// A served path is a character device (major 81, as V4L2 nodes), so clients that check
// S_ISCHR accept it.
static void fake_stat(struct stat* st, const char* path) {
  std::memset(st, 0, sizeof(*st));
  st->st_mode = S_IFCHR | 0660;
  unsigned minor = 0;
  if (path) std::sscanf(path, "/dev/video%u", &minor);
  st->st_rdev = makedev(81, minor);
}

int stat(const char* path, struct stat* st) {
  if (fake_v4l2::is_served(path)) {
    if (!fake_v4l2::is_plugged(path)) return errno = ENOENT, -1;
    return fake_stat(st, path), 0;
  }
  static auto f = real<int (*)(const char*, struct stat*)>("stat");
  return f(path, st);
}

int fstat(int fd, struct stat* st) {
  if (fake_v4l2::is_fake_fd(fd)) return fake_stat(st, fake_v4l2::path_of(fd)), 0;
  static auto f = real<int (*)(int, struct stat*)>("fstat");
  return f(fd, st);
}

// v4l2-compliance learns what a node is from /sys/dev/char/MAJOR:MINOR/uevent.
static FILE* fake_uevent(const char* path) {
  unsigned major_num = 0, minor_num = 0;
  if (!path || std::sscanf(path, "/sys/dev/char/%u:%u/uevent", &major_num, &minor_num) != 2 ||
      major_num != 81)
    return nullptr;
  const std::string dev = "/dev/video" + std::to_string(minor_num);
  if (!fake_v4l2::is_served(dev.c_str())) return nullptr;
  char text[128];
  const int n = std::snprintf(text, sizeof(text), "MAJOR=81\nMINOR=%u\nDEVNAME=video%u\n",
                              minor_num, minor_num);
  // A real fd (libstdc++ file streams read() the descriptor, so fmemopen would not do).
  const int fd = memfd_create("orthoface-fake-uevent", MFD_CLOEXEC);
  if (fd < 0) return nullptr;
  static auto real_write = real<ssize_t (*)(int, const void*, size_t)>("write");
  if (real_write(fd, text, size_t(n)) != n || lseek(fd, 0, SEEK_SET) != 0) return nullptr;
  return fdopen(fd, "r");
}

FILE* fopen(const char* path, const char* mode) {
  if (FILE* f = fake_uevent(path)) return f;
  static auto f = real<FILE* (*)(const char*, const char*)>("fopen");
  return f(path, mode);
}

FILE* fopen64(const char* path, const char* mode) {
  if (FILE* f = fake_uevent(path)) return f;
  static auto f = real<FILE* (*)(const char*, const char*)>("fopen64");
  return f(path, mode);
}

int close(int fd) {
  fake_v4l2::close_device(fd);
  static auto f = real<int (*)(int)>("close");
  return f(fd);
}

}  // extern "C"
