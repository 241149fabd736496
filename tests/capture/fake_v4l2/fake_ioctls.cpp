// The ioctls of the fake V4L2 device, written after the V4L2 specification and videobuf2.
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <cmath>

#include <cstdint>
#include <cstring>

#include "device_model.h"

namespace fake_v4l2 {
namespace {

bool known_size(unsigned w, unsigned h) {
  for (auto& s : kSizes)
    if (unsigned(s[0]) == w && unsigned(s[1]) == h) return true;
  return false;
}
bool known_format(unsigned p) { return p == kFormats[0] || p == kFormats[1]; }
int fail(int e) { return errno = e, -1; }
double now_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int querycap(v4l2_capability* c, bool output) {
  std::memset(c, 0, sizeof(*c));
  std::snprintf(reinterpret_cast<char*>(c->driver), sizeof(c->driver), "orthoface_fake");
  std::snprintf(reinterpret_cast<char*>(c->card), sizeof(c->card), "%s",
                output ? "orthoface fake output" : "orthoface fake camera");
  std::snprintf(reinterpret_cast<char*>(c->bus_info), sizeof(c->bus_info),
                "platform:orthoface-fake");
  c->version = kernel_version();
  c->device_caps = output ? V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING | V4L2_CAP_READWRITE |
                                V4L2_CAP_EXT_PIX_FORMAT
                          : V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING | V4L2_CAP_EXT_PIX_FORMAT;
  c->capabilities = c->device_caps | V4L2_CAP_DEVICE_CAPS;
  return 0;
}

int enum_fmt(v4l2_fmtdesc* d, bool type_ok, bool output) {
  if (!type_ok || d->index >= (output ? 1u : 2u)) return fail(EINVAL);
  const unsigned index = d->index, type = d->type;
  std::memset(d, 0, sizeof(*d));
  d->index = index;
  d->type = type;
  d->pixelformat = kFormats[index];
  d->flags = kFormats[index] == V4L2_PIX_FMT_MJPEG ? V4L2_FMT_FLAG_COMPRESSED : 0;
  std::snprintf(reinterpret_cast<char*>(d->description), sizeof(d->description), "%s",
                index == 0 ? "YUYV 4:2:2" : "Motion-JPEG");
  return 0;
}

int enum_framesizes(v4l2_frmsizeenum* s, bool output) {
  if (!known_format(s->pixel_format) || s->index >= 3) return fail(EINVAL);
  if (output && s->pixel_format != V4L2_PIX_FMT_YUYV) return fail(EINVAL);
  const unsigned index = s->index, pix = s->pixel_format;
  std::memset(s, 0, sizeof(*s));
  s->index = index;
  s->pixel_format = pix;
  s->type = V4L2_FRMSIZE_TYPE_DISCRETE;
  s->discrete.width = kSizes[index][0];
  s->discrete.height = kSizes[index][1];
  return 0;
}

int enum_frameintervals(v4l2_frmivalenum* i) {
  if (!known_format(i->pixel_format) || !known_size(i->width, i->height) || i->index >= 2)
    return fail(EINVAL);
  const v4l2_frmivalenum in = *i;
  std::memset(i, 0, sizeof(*i));
  i->index = in.index;
  i->pixel_format = in.pixel_format;
  i->width = in.width;
  i->height = in.height;
  i->type = V4L2_FRMIVAL_TYPE_DISCRETE;
  i->discrete = {1, kFpsList[in.index]};
  return 0;
}

int inputs(unsigned long request, void* arg) {
  if (request == VIDIOC_ENUMINPUT) {
    auto* in = static_cast<v4l2_input*>(arg);
    if (in->index != 0) return fail(EINVAL);
    std::memset(in, 0, sizeof(*in));
    std::snprintf(reinterpret_cast<char*>(in->name), sizeof(in->name), "Camera");
    in->type = V4L2_INPUT_TYPE_CAMERA;
    return 0;
  }
  if (request == VIDIOC_G_INPUT) return *static_cast<int*>(arg) = 0, 0;
  return *static_cast<int*>(arg) == 0 ? 0 : fail(EINVAL);  // S_INPUT
}

}  // namespace

int Device::ioctl(int fd, unsigned long request, void* arg) {
  static const unsigned long kKnown[] = {VIDIOC_QUERYCAP,
                                         VIDIOC_ENUM_FMT,
                                         VIDIOC_ENUM_FRAMESIZES,
                                         VIDIOC_ENUM_FRAMEINTERVALS,
                                         VIDIOC_ENUMINPUT,
                                         VIDIOC_G_INPUT,
                                         VIDIOC_S_INPUT,
                                         VIDIOC_G_FMT,
                                         VIDIOC_S_FMT,
                                         VIDIOC_TRY_FMT,
                                         VIDIOC_G_PARM,
                                         VIDIOC_S_PARM,
                                         VIDIOC_REQBUFS,
                                         VIDIOC_QUERYBUF,
                                         VIDIOC_QBUF,
                                         VIDIOC_DQBUF,
                                         VIDIOC_STREAMON,
                                         VIDIOC_STREAMOFF,
                                         VIDIOC_G_PRIORITY,
                                         VIDIOC_S_PRIORITY};
  if (std::find(std::begin(kKnown), std::end(kKnown), request) == std::end(kKnown))
    return fail(ENOTTY);  // controls, events, std, tuner, ...: not offered
  if (!arg) return fail(EFAULT);
  std::unique_lock<std::mutex> lock(m_);
  // v4l2-ioctl.c: these need the highest priority among the open files.
  switch (request) {
    case VIDIOC_S_FMT:
    case VIDIOC_S_INPUT:
    case VIDIOC_S_PARM:
    case VIDIOC_REQBUFS:
    case VIDIOC_STREAMON:
    case VIDIOC_STREAMOFF:
    case VIDIOC_S_PRIORITY:
      if (prio_of(fd) < max_prio()) return fail(EBUSY);
      break;
    default:
      break;
  }
  switch (request) {
    case VIDIOC_G_PRIORITY:
      return *static_cast<unsigned*>(arg) = max_prio(), 0;
    case VIDIOC_S_PRIORITY: {
      const unsigned p = *static_cast<unsigned*>(arg);
      if (p != V4L2_PRIORITY_BACKGROUND && p != V4L2_PRIORITY_INTERACTIVE &&
          p != V4L2_PRIORITY_RECORD)
        return fail(EINVAL);
      prio_[fd] = p;
      return 0;
    }
    case VIDIOC_QUERYCAP:
      return querycap(static_cast<v4l2_capability*>(arg), output_);
    case VIDIOC_ENUM_FMT: {
      auto* d = static_cast<v4l2_fmtdesc*>(arg);
      return enum_fmt(d, valid_type(d->type), output_);
    }
    case VIDIOC_ENUM_FRAMESIZES:
      return enum_framesizes(static_cast<v4l2_frmsizeenum*>(arg), output_);
    case VIDIOC_ENUM_FRAMEINTERVALS:
      return enum_frameintervals(static_cast<v4l2_frmivalenum*>(arg));
    case VIDIOC_ENUMINPUT:
    case VIDIOC_G_INPUT:
    case VIDIOC_S_INPUT:
      return output_ ? fail(ENOTTY) : inputs(request, arg);
    case VIDIOC_G_FMT:
    case VIDIOC_S_FMT:
    case VIDIOC_TRY_FMT:
      return fmt_ioctl(fd, request, static_cast<v4l2_format*>(arg));
    case VIDIOC_G_PARM:
      return parm(static_cast<v4l2_streamparm*>(arg), false);
    case VIDIOC_S_PARM:
      return parm(static_cast<v4l2_streamparm*>(arg), true);
    case VIDIOC_REQBUFS:
      return reqbufs(fd, static_cast<v4l2_requestbuffers*>(arg));
    case VIDIOC_QUERYBUF:
      return querybuf(static_cast<v4l2_buffer*>(arg));
    case VIDIOC_QBUF:
      return qbuf(fd, static_cast<v4l2_buffer*>(arg));
    case VIDIOC_DQBUF:
      return dqbuf(fd, static_cast<v4l2_buffer*>(arg), lock);
    case VIDIOC_STREAMON:
      return streamon(fd, static_cast<int*>(arg));
    case VIDIOC_STREAMOFF:
      return streamoff(fd, static_cast<int*>(arg));
    default:
      return fail(ENOTTY);
  }
}

int Device::fmt_ioctl(int fd, unsigned long request, v4l2_format* f) {
  if (!valid_type(f->type)) return fail(EINVAL);
  if (request == VIDIOC_G_FMT) {
    std::memset(&f->fmt, 0, sizeof(f->fmt));
    f->fmt.pix = fmt_;
    return 0;
  }
  v4l2_pix_format p = f->fmt.pix;
  if (output_)
    adjust_output(p);
  else
    adjust(p);
  std::memset(&f->fmt, 0, sizeof(f->fmt));
  f->fmt.pix = p;
  if (request == VIDIOC_TRY_FMT) return 0;
  if (file_exists(ctl_file(path_, "busy"))) return fail(EBUSY);
  if (!buffers_.empty() && (owner_ != fd || streaming_ || p.pixelformat != fmt_.pixelformat ||
                            p.width != fmt_.width || p.height != fmt_.height))
    return fail(EBUSY);  // vb2: format is fixed while buffers are allocated
  fmt_ = p;
  return 0;
}

int Device::parm(v4l2_streamparm* p, bool set) {
  if (!valid_type(p->type)) return fail(EINVAL);
  if (set) {
    const v4l2_fract t = p->parm.capture.timeperframe;
    const double want = t.numerator ? double(t.denominator) / t.numerator : 30.0;
    fps_ = std::abs(want - 15.0) < std::abs(want - 30.0) ? 15 : 30;
  }
  const unsigned type = p->type;
  std::memset(p, 0, sizeof(*p));
  p->type = type;
  p->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
  p->parm.capture.timeperframe = {1, fps_};
  return 0;
}

int Device::reqbufs(int fd, v4l2_requestbuffers* r) {
  if (!valid_type(r->type)) return fail(EINVAL);
  const unsigned caps = V4L2_BUF_CAP_SUPPORTS_MMAP | V4L2_BUF_CAP_SUPPORTS_ORPHANED_BUFS;
  if (r->memory != V4L2_MEMORY_MMAP) {
    r->capabilities = caps;
    return fail(EINVAL);
  }
  if (owner_ >= 0 && owner_ != fd) return fail(EBUSY);
  if (streaming_) return fail(EBUSY);
  std::memset(r->reserved, 0, sizeof(r->reserved));
  r->capabilities = caps;
  r->flags = 0;
  free_buffers();
  if (r->count == 0) {
    owner_ = -1;
    return 0;
  }
  r->count = std::clamp(r->count, 2u, kMaxBuffers);
  const size_t page = size_t(sysconf(_SC_PAGESIZE));
  const size_t length = (fmt_.sizeimage + page - 1) / page * page;
  for (unsigned i = 0; i < r->count; ++i) {
    Buffer b;
    b.memfd = memfd_create("orthoface-fake-v4l2", MFD_CLOEXEC);
    if (b.memfd < 0 || ftruncate(b.memfd, off_t(length)) != 0) return fail(ENOMEM);
    b.length = length;
    b.data = ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, b.memfd, 0);
    if (b.data == MAP_FAILED) return fail(ENOMEM);
    buffers_.push_back(b);
  }
  owner_ = fd;
  return 0;
}

void Device::fill_buf(unsigned index, v4l2_buffer* b) const {
  const Buffer& buf = buffers_[index];
  const unsigned type = b->type;
  std::memset(b, 0, sizeof(*b));
  b->index = index;
  b->type = type;
  b->memory = V4L2_MEMORY_MMAP;
  b->length = unsigned(buf.length);
  b->m.offset = index * 0x100000u;  // a cookie for mmap, unique per buffer
  b->field = V4L2_FIELD_NONE;
  b->flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_EOF | buf.flags;
  if (buf.state == Buffer::Queued) b->flags |= V4L2_BUF_FLAG_QUEUED;
  if (buf.state == Buffer::Done) b->flags |= V4L2_BUF_FLAG_DONE;
  b->bytesused = buf.bytesused;
  b->sequence = buf.sequence;
  b->timestamp = buf.timestamp;
}

int Device::querybuf(v4l2_buffer* b) {
  if (!valid_type(b->type) || b->index >= buffers_.size()) return fail(EINVAL);
  fill_buf(b->index, b);
  return 0;
}

int Device::qbuf(int fd, v4l2_buffer* b) {
  if (!valid_type(b->type) || b->memory != V4L2_MEMORY_MMAP || b->index >= buffers_.size())
    return fail(EINVAL);
  if (owner_ != fd) return fail(EBUSY);
  Buffer& buf = buffers_[b->index];
  if (buf.state != Buffer::Dequeued) return fail(EINVAL);
  if (output_) {  // the application filled it: bytesused 0 means the whole image
    const unsigned used = b->bytesused ? b->bytesused : fmt_.sizeimage;
    if (used != fmt_.sizeimage) return fail(EINVAL);
    buf.bytesused = used;
  }
  buf.state = Buffer::Queued;
  buf.flags = 0;
  queued_.push_back(b->index);
  if (output_ && streaming_) consume_queued_locked();
  fill_buf(b->index, b);
  cv_.notify_all();
  return 0;
}

int Device::dqbuf(int fd, v4l2_buffer* b, std::unique_lock<std::mutex>& lock) {
  if (!valid_type(b->type) || b->memory != V4L2_MEMORY_MMAP) return fail(EINVAL);
  if (owner_ != fd) return fail(EBUSY);
  const std::string eio = ctl_file(path_, "eio");
  if (file_exists(eio)) {
    ::unlink(eio.c_str());
    return fail(EIO);
  }
  const bool nonblock = fcntl(fd, F_GETFL) & O_NONBLOCK;
  while (done_.empty()) {
    if (!streaming_) return fail(EINVAL);
    if (nonblock) return fail(EAGAIN);
    cv_.wait_for(lock, std::chrono::milliseconds(100));
    if (gone()) return fail(ENODEV);
  }
  const unsigned index = done_.front();
  done_.pop_front();
  buffers_[index].state = Buffer::Dequeued;  // DONE is cleared once dequeued
  fill_buf(index, b);
  if (done_.empty()) unsignal_locked();
  return 0;
}

int Device::streamon(int fd, const int* type) {
  if (!valid_type(unsigned(*type))) return fail(EINVAL);
  if (owner_ != fd || buffers_.empty()) return fail(EINVAL);
  if (streaming_) return 0;
  streaming_ = true;
  sequence_ = 0;
  if (output_) {  // no producer: queued frames go out now, later ones as they are queued
    consume_queued_locked();
    return 0;
  }
  run_ = true;
  producer_ = std::thread([this] { produce(); });
  return 0;
}

int Device::streamoff(int fd, const int* type) {
  if (!valid_type(unsigned(*type))) return fail(EINVAL);
  if (owner_ >= 0 && owner_ != fd) return fail(EBUSY);
  m_.unlock();
  stop_streaming();
  m_.lock();
  return 0;
}

void Device::stop_streaming() {
  run_ = false;
  cv_.notify_all();
  if (producer_.joinable()) producer_.join();
  std::lock_guard<std::mutex> lock(m_);
  streaming_ = false;
  queued_.clear();
  done_.clear();
  for (Buffer& b : buffers_) b.state = Buffer::Dequeued, b.flags = 0;
  unsignal_locked();
}

void Device::free_buffers() {
  for (Buffer& b : buffers_) {
    ::munmap(b.data, b.length);
    ::close(b.memfd);
  }
  buffers_.clear();
  queued_.clear();
  done_.clear();
}

void* Device::mmap(void* addr, size_t length, int prot, int flags, off_t offset) {
  std::lock_guard<std::mutex> lock(m_);
  const unsigned index = unsigned(offset / 0x100000);
  if (offset % 0x100000 || index >= buffers_.size() || length == 0 ||
      length > buffers_[index].length || !(flags & MAP_SHARED))
    return errno = EINVAL, MAP_FAILED;
  return ::mmap(addr, length, prot, flags, buffers_[index].memfd, 0);
}

short Device::poll_events(int fd, short requested) {
  std::lock_guard<std::mutex> lock(m_);
  if (output_ && owner_ < 0) return short(requested & (POLLOUT | POLLWRNORM));  // write() I/O
  if (owner_ != fd || !streaming_) return POLLERR;
  if (!done_.empty())
    return short(requested & (output_ ? POLLOUT | POLLWRNORM : POLLIN | POLLRDNORM));
  if (queued_.empty()) return POLLERR;  // vb2: nothing queued, nothing will come
  return 0;
}

ssize_t Device::write(int /*fd*/, const void* buf, size_t count) {
  std::lock_guard<std::mutex> lock(m_);
  if (!output_) return fail(EINVAL);    // a capture node offers no write() I/O
  if (owner_ >= 0) return fail(EBUSY);  // vb2: no file I/O while streaming buffers exist
  if (!buf) return fail(EFAULT);
  if (count != fmt_.sizeimage) return fail(EINVAL);  // one whole frame per write
  consume_locked(buf, count);
  ++sequence_;
  return ssize_t(count);
}

// Raw system calls: the fake's own open/write/close wrappers take the registry lock.
void Device::consume_locked(const void* data, size_t bytes) {
  if (output_file_.empty()) return;
  const int fd = int(::syscall(SYS_openat, AT_FDCWD, output_file_.c_str(),
                               O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644));
  if (fd < 0) return;
  const int32_t dims[3] = {int32_t(fmt_.width), int32_t(fmt_.height), int32_t(bytes)};
  std::string frame = "OFW1";
  frame.append(reinterpret_cast<const char*>(dims), sizeof(dims));
  frame.append(static_cast<const char*>(data), bytes);
  for (size_t done = 0; done < frame.size();) {  // O_APPEND: one write, one frame
    const long k = ::syscall(SYS_write, fd, frame.data() + done, frame.size() - done);
    if (k <= 0) break;
    done += size_t(k);
  }
  ::syscall(SYS_close, fd);
}

void Device::consume_queued_locked() {
  while (!queued_.empty()) {
    const unsigned index = queued_.front();
    queued_.pop_front();
    Buffer& b = buffers_[index];
    consume_locked(b.data, b.bytesused);
    b.sequence = sequence_++;
    b.state = Buffer::Done;
    done_.push_back(index);
  }
  signal_locked();
  cv_.notify_all();
}

void Device::signal_locked() {
  if (signalled_ || owner_ < 0) return;
  signalled_ = eventfd_write(owner_, 1) == 0;
}

void Device::unsignal_locked() {
  if (!signalled_ || owner_ < 0) return;
  eventfd_t v;
  signalled_ = eventfd_read(owner_, &v) != 0;  // not read(): that is interposed
}

// One frame per period into the oldest queued buffer; a tick with no queued buffer is a drop
// (the sequence number still advances, as in videobuf2 drivers).
void Device::produce() {
  const double period = 1.0 / fps_;
  double next = now_s() + period;
  while (run_) {
    std::unique_lock<std::mutex> lock(m_);
    cv_.wait_for(lock, std::chrono::duration<double>(std::max(0.0, next - now_s())),
                 [&] { return !run_; });
    if (!run_) break;
    if (gone()) {
      signal_locked();  // wake epoll / select waiters: the next ioctl says ENODEV
      break;
    }
    // The frame's capture instant on the device's own period grid (a driver stamps the
    // hardware's frame time, not when software got round to it); a tick this thread woke too
    // late for is a dropped frame: its sequence number passes, no burst follows.
    const double tick = next;
    const unsigned seq = sequence_++;
    next += period;
    while (next < now_s()) next += period, ++sequence_;
    if (queued_.empty()) continue;
    const unsigned index = queued_.front();
    queued_.pop_front();
    Buffer& b = buffers_[index];
    const v4l2_pix_format fmt = fmt_;
    lock.unlock();  // encoding takes milliseconds; the app may QBUF meanwhile
    const size_t n = source_.fill(fmt.pixelformat, fmt.width, fmt.height, seq,
                                  static_cast<unsigned char*>(b.data), b.length);
    lock.lock();
    const double whole = std::floor(tick);
    b.timestamp = {time_t(whole), suseconds_t((tick - whole) * 1e6)};
    b.bytesused = unsigned(n);
    b.flags = n ? 0 : V4L2_BUF_FLAG_ERROR;
    b.sequence = seq;
    b.state = Buffer::Done;
    done_.push_back(index);
    signal_locked();
    cv_.notify_all();
  }
}

}  // namespace fake_v4l2
