#pragma once
// Internal: the device model behind the fake V4L2 node (fake_device.cpp: registry of fds,
// fake_ioctls.cpp: the ioctls and the frame producer).
#include <errno.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/utsname.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "frame_source.h"

namespace fake_v4l2 {

inline constexpr int kSizes[][2] = {{320, 240}, {640, 480}, {1280, 720}};
inline constexpr unsigned kFormats[] = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG};
inline constexpr unsigned kFpsList[] = {30, 15};
inline constexpr unsigned kMaxBuffers = 8;

struct Buffer {
  int memfd = -1;
  size_t length = 0;
  void* data = nullptr;  // the device's own mapping
  enum State { Dequeued, Queued, Done } state = Dequeued;
  unsigned bytesused = 0, sequence = 0, flags = 0;
  timeval timestamp{};
};

inline std::string served_env() {
  const char* e = std::getenv("ORTHOFACE_FAKE_V4L2");
  return e ? e : "";
}

// "path[=file][,path[=file]]" -> path -> file.
inline std::map<std::string, std::string> parse_paths(const std::string& s) {
  std::map<std::string, std::string> out;
  size_t start = 0;
  while (start < s.size()) {
    size_t comma = s.find(',', start);
    std::string item =
        s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    size_t eq = item.find('=');
    if (!item.empty()) out[item.substr(0, eq)] = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// path -> frame file ("" = test pattern).
inline std::map<std::string, std::string> served_paths() { return parse_paths(served_env()); }

// Output devices: path -> file the written frames are appended to ("" = discarded).
inline std::map<std::string, std::string> output_paths() {
  const char* e = std::getenv("ORTHOFACE_FAKE_V4L2_OUTPUT");
  return parse_paths(e ? e : "");
}

inline std::string ctl_file(const std::string& path, const char* what) {
  const char* dir = std::getenv("ORTHOFACE_FAKE_V4L2_CTL");
  if (!dir || !*dir) return "";
  const size_t slash = path.rfind('/');
  return std::string(dir) + "/" + what + "-" + path.substr(slash + 1);
}

inline bool file_exists(const std::string& p) {
  struct stat st;
  return !p.empty() && ::stat(p.c_str(), &st) == 0;
}

inline unsigned kernel_version() {
  utsname u{};
  uname(&u);
  unsigned a = 0, b = 0, c = 0;
  std::sscanf(u.release, "%u.%u.%u", &a, &b, &c);
  return (a << 16) | (b << 8) | std::min(c, 255u);
}

class Device {
 public:
  // An output device (output_file set) takes frames instead of producing them.
  Device(std::string path, std::string frame_file, bool output = false,
         std::string output_file = "")
      : path_(std::move(path)),
        source_(std::move(frame_file)),
        output_(output),
        output_file_(std::move(output_file)) {
    set_format(640, 480, V4L2_PIX_FMT_YUYV);
  }
  ~Device() {
    stop_streaming();
    free_buffers();
  }

  bool gone() {
    if (!gone_ && file_exists(ctl_file(path_, "unplug"))) {
      gone_ = true;
      cv_.notify_all();
    }
    return gone_;
  }
  int ioctl(int fd, unsigned long request, void* arg);
  // write() I/O of an output device: one whole frame (sizeimage bytes) per call.
  ssize_t write(int fd, const void* buf, size_t count);
  void* mmap(void* addr, size_t length, int prot, int flags, off_t offset);
  short poll_events(int fd, short requested);
  void release(int fd) {
    std::unique_lock<std::mutex> lock(m_);
    if (owner_ == fd) {
      lock.unlock();
      stop_streaming();
      lock.lock();
      free_buffers();
      owner_ = -1;
    }
    prio_.erase(fd);
  }
  const std::string& path() const { return path_; }
  void rename_owner(int from, int to) {
    std::lock_guard<std::mutex> lock(m_);
    if (owner_ == from) owner_ = to;
    if (prio_.count(from)) prio_[to] = prio_[from], prio_.erase(from);
  }
  void open_file(int fd) {
    std::lock_guard<std::mutex> lock(m_);
    prio_[fd] = V4L2_PRIORITY_DEFAULT;
  }

 private:
  unsigned prio_of(int fd) const {
    auto it = prio_.find(fd);
    return it == prio_.end() ? unsigned(V4L2_PRIORITY_DEFAULT) : it->second;
  }
  unsigned max_prio() const {
    unsigned m = V4L2_PRIORITY_BACKGROUND;
    for (const auto& [f, p] : prio_) m = std::max(m, p);
    return m;
  }
  void set_format(unsigned w, unsigned h, unsigned pixfmt) {
    fmt_ = {};
    fmt_.width = w;
    fmt_.height = h;
    fmt_.pixelformat = pixfmt;
    fmt_.field = V4L2_FIELD_NONE;
    fmt_.bytesperline = pixfmt == V4L2_PIX_FMT_YUYV ? w * 2 : 0;
    fmt_.sizeimage = w * h * 2;
    fmt_.colorspace = V4L2_COLORSPACE_SRGB;
  }
  static void adjust(v4l2_pix_format& f) {
    bool known = false;
    for (unsigned p : kFormats) known |= p == f.pixelformat;
    if (!known) f.pixelformat = V4L2_PIX_FMT_YUYV;  // V4L2: S_FMT adjusts, never EINVAL
    int best = 0;
    long best_d = -1;
    for (int i = 0; i < 3; ++i) {
      long d = std::labs(long(f.width) - kSizes[i][0]) + std::labs(long(f.height) - kSizes[i][1]);
      if (best_d < 0 || d < best_d) best = i, best_d = d;
    }
    const unsigned pix = f.pixelformat;
    f = {};
    f.width = kSizes[best][0];
    f.height = kSizes[best][1];
    f.pixelformat = pix;
    f.field = V4L2_FIELD_NONE;
    f.bytesperline = pix == V4L2_PIX_FMT_YUYV ? f.width * 2 : 0;
    f.sizeimage = f.width * f.height * 2;
    f.colorspace = V4L2_COLORSPACE_SRGB;
  }
  // The one buffer type of this device's queue.
  bool valid_type(unsigned type) const {
    return type == (output_ ? V4L2_BUF_TYPE_VIDEO_OUTPUT : V4L2_BUF_TYPE_VIDEO_CAPTURE);
  }
  // Output (v4l2loopback-like): YUYV at any even size up to 8192x8192.
  static void adjust_output(v4l2_pix_format& f) {
    const unsigned w = std::clamp(f.width, 2u, 8192u) & ~1u, h = std::clamp(f.height, 2u, 8192u);
    f = {};
    f.width = w;
    f.height = h;
    f.pixelformat = V4L2_PIX_FMT_YUYV;
    f.field = V4L2_FIELD_NONE;
    f.bytesperline = w * 2;
    f.sizeimage = w * h * 2;
    f.colorspace = V4L2_COLORSPACE_SRGB;
  }
  // Appends one frame to output_file_ (header "OFW1", int32 width, height, bytes; the bytes).
  void consume_locked(const void* data, size_t bytes);
  // Output streaming: the queued buffers are frames, taken at once and handed back as done.
  void consume_queued_locked();
  int fmt_ioctl(int fd, unsigned long request, v4l2_format* f);
  int reqbufs(int fd, v4l2_requestbuffers* r);
  void fill_buf(unsigned index, v4l2_buffer* b) const;
  int querybuf(v4l2_buffer* b);
  int qbuf(int fd, v4l2_buffer* b);
  int dqbuf(int fd, v4l2_buffer* b, std::unique_lock<std::mutex>& lock);
  int streamon(int fd, const int* type);
  int streamoff(int fd, const int* type);
  int parm(v4l2_streamparm* p, bool set);
  void free_buffers();
  void stop_streaming();
  void produce();
  void signal_locked();
  void unsignal_locked();

  std::string path_;
  FrameSource source_;
  bool output_ = false;
  std::string output_file_;
  std::mutex m_;
  std::condition_variable cv_;
  v4l2_pix_format fmt_{};
  unsigned fps_ = 30;
  std::vector<Buffer> buffers_;
  std::deque<unsigned> queued_, done_;
  int owner_ = -1;
  bool streaming_ = false;
  bool signalled_ = false;
  std::atomic<bool> gone_{false};
  std::atomic<bool> run_{false};
  unsigned sequence_ = 0;
  std::map<int, unsigned> prio_;  // open file -> V4L2 priority
  std::thread producer_;
};

}  // namespace fake_v4l2
