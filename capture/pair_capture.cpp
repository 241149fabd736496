#include "capture/pair_capture.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace orthoface::capture {
namespace {

// Online mutual-nearest pairing of two time-sorted streams (0 = front, 1 = side).
class Pairer {
 public:
  Pairer(double max_skew_s, size_t max_queue) : max_skew_(max_skew_s), max_queue_(max_queue) {}

  std::vector<FramePair> push(int camera, Frame frame) {
    q_[camera].push_back(std::move(frame));
    if (q_[camera].size() > max_queue_) drop(camera);  // the other camera is silent
    return drain(false);
  }
  std::vector<FramePair> flush() { return drain(true); }
  std::uint64_t unpaired() const { return unpaired_; }

 private:
  void drop(int camera) {
    q_[camera].pop_front();
    ++unpaired_;
  }
  // The earlier head x (queue a) has its nearest partner in the other queue's head y (later
  // frames are further). x pairs with y unless a's next frame is nearer to y; without a next
  // frame we wait for it (or pair now when flushing).
  std::vector<FramePair> drain(bool flushing) {
    std::vector<FramePair> out;
    while (!q_[0].empty() && !q_[1].empty()) {
      const int a = q_[0].front().timestamp_s <= q_[1].front().timestamp_s ? 0 : 1;
      const int b = 1 - a;
      const double tx = q_[a].front().timestamp_s, ty = q_[b].front().timestamp_s;
      if (ty - tx > max_skew_) {
        drop(a);
        continue;
      }
      if (q_[a].size() < 2 && !flushing) break;
      if (q_[a].size() >= 2 && std::abs(q_[a][1].timestamp_s - ty) < ty - tx) {
        drop(a);
        continue;
      }
      FramePair p;
      p.front = std::move(q_[0].front());
      p.side = std::move(q_[1].front());
      p.skew_s = std::abs(p.front.timestamp_s - p.side.timestamp_s);
      q_[0].pop_front();
      q_[1].pop_front();
      out.push_back(std::move(p));
    }
    return out;
  }

  double max_skew_;
  size_t max_queue_;
  std::deque<Frame> q_[2];
  std::uint64_t unpaired_ = 0;
};

double rate(const std::deque<double>& t) {
  return t.size() < 2 || t.back() <= t.front() ? 0.0 : (t.size() - 1) / (t.back() - t.front());
}

void push_window(std::deque<double>& t, double now) {
  t.push_back(now);
  while (!t.empty() && t.front() < now - 1.0) t.pop_front();
}

CameraFormat pick_format(Camera& cam, const PairCaptureOptions& o) {
  const std::vector<CameraFormat> formats = cam.formats();
  if (o.fourcc.empty()) return choose_format(formats, o.width, o.height, o.fps, cam.name());
  for (const CameraFormat& f : formats)
    if (f.fourcc == o.fourcc && f.width == o.width && f.height == o.height &&
        std::abs(f.fps - o.fps) < 0.01)
      return f;
  throw std::runtime_error("camera " + cam.name() + ": does not offer " + o.fourcc + " " +
                           std::to_string(o.width) + "x" + std::to_string(o.height) + " at " +
                           std::to_string(o.fps) + " fps");
}

}  // namespace

void PairCaptureOptions::check() const {
  if (width <= 0 || height <= 0 || width > 8192 || height > 8192)
    throw std::invalid_argument("PairCaptureOptions: width/height must be in 1..8192");
  if (!(fps > 0 && fps <= 1000))
    throw std::invalid_argument("PairCaptureOptions: fps must be in (0, 1000]");
  if (!(max_skew_s > 0)) throw std::invalid_argument("PairCaptureOptions: max_skew_s must be > 0");
  if (!(reopen_interval_s > 0))
    throw std::invalid_argument("PairCaptureOptions: reopen_interval_s must be > 0");
  if (keep_recent < 2) throw std::invalid_argument("PairCaptureOptions: keep_recent must be >= 2");
  if (!fourcc.empty() && fourcc.size() != 4)
    throw std::invalid_argument("PairCaptureOptions: fourcc must have 4 characters");
}

bool same_device(const std::string& a, const std::string& b) {
  if (a == b) return true;
  if (a.empty() || b.empty() || a[0] != '/' || b[0] != '/') return false;
  std::error_code ea, eb;
  const auto ca = std::filesystem::weakly_canonical(a, ea);
  const auto cb = std::filesystem::weakly_canonical(b, eb);
  return !ea && !eb && ca == cb;
}

std::vector<FramePair> pair_frames(const std::vector<Frame>& front, const std::vector<Frame>& side,
                                   double max_skew_s) {
  if (!(max_skew_s > 0)) throw std::invalid_argument("pair_frames: max_skew_s must be > 0");
  Pairer p(max_skew_s, front.size() + side.size() + 2);
  std::vector<FramePair> out;
  size_t i = 0, j = 0;
  auto take = [&out](std::vector<FramePair> v) {
    for (FramePair& f : v) out.push_back(std::move(f));
  };
  while (i < front.size() || j < side.size()) {  // merge in time order, as frames arrive
    const bool f =
        j >= side.size() || (i < front.size() && front[i].timestamp_s <= side[j].timestamp_s);
    take(f ? p.push(0, front[i++]) : p.push(1, side[j++]));
  }
  take(p.flush());
  return out;
}

struct PairCapture::Impl {
  struct Cam {
    std::string id, role;
    std::unique_ptr<Camera> camera;
    CameraFormat format;
    std::thread thread;
    std::deque<double> window;
    std::int64_t last_sequence = -1;
    std::optional<Frame> latest;
  };
  PairCaptureOptions options;
  Cam cams[2];
  mutable std::mutex m;
  std::condition_variable cv;
  std::atomic<bool> running{true};
  Pairer pairer{0.025, 8};
  std::deque<FramePair> recent;
  std::deque<double> pair_window;
  std::vector<FramePair> taken;
  std::vector<std::string> events;
  PairStats stats;
  double skew_sum = 0;

  void run(int k);
  bool reopen(int k);
  void on_frame(int k, Frame frame);
  void on_lost(int k, const std::string& message);
};

bool PairCapture::Impl::reopen(int k) {
  Cam& c = cams[k];
  if (auto cam = reopen_camera(c.id, c.format)) {
    std::lock_guard<std::mutex> lock(m);
    c.camera = std::move(cam);
    c.last_sequence = -1;
    (k == 0 ? stats.front_connected : stats.side_connected) = true;
    ++stats.reconnects;
    events.push_back(c.role + " camera " + c.id + " is back");
    return true;
  }
  std::unique_lock<std::mutex> lock(m);  // still gone: wait, but wake up on stop()
  cv.wait_for(lock, std::chrono::duration<double>(options.reopen_interval_s),
              [this] { return !running; });
  return false;
}

void PairCapture::Impl::on_frame(int k, Frame frame) {
  std::lock_guard<std::mutex> lock(m);
  Cam& c = cams[k];
  const auto seq = static_cast<std::int64_t>(frame.sequence);
  if (c.last_sequence >= 0 && seq > c.last_sequence + 1)
    (k == 0 ? stats.dropped_front : stats.dropped_side) += seq - c.last_sequence - 1;
  c.last_sequence = seq;
  ++(k == 0 ? stats.frames_front : stats.frames_side);
  push_window(c.window, frame.timestamp_s);
  c.latest = frame;
  for (FramePair& p : pairer.push(k, std::move(frame))) {
    ++stats.pairs;
    stats.skew_last_s = p.skew_s;
    stats.skew_max_s = std::max(stats.skew_max_s, p.skew_s);
    skew_sum += p.skew_s;
    push_window(pair_window, std::max(p.front.timestamp_s, p.side.timestamp_s));
    recent.push_back(std::move(p));
    if (recent.size() > size_t(options.keep_recent)) recent.pop_front();
  }
  stats.unpaired = pairer.unpaired();
  cv.notify_all();
}

void PairCapture::Impl::on_lost(int k, const std::string& message) {
  std::unique_ptr<Camera> dead;
  {
    std::lock_guard<std::mutex> lock(m);
    dead = std::move(cams[k].camera);
    (k == 0 ? stats.front_connected : stats.side_connected) = false;
    ++stats.disconnects;
    events.push_back(cams[k].role + " camera lost: " + message);
  }
  try {
    dead.reset();  // closes the dead device
  } catch (...) {
  }
}

void PairCapture::Impl::run(int k) {
  while (running) {
    if (!cams[k].camera && !reopen(k)) continue;
    FrameResult r;
    try {
      r = cams[k].camera->next_frame(0.2);
    } catch (const std::exception& e) {
      r = {FrameStatus::Disconnected, {}, e.what()};
    }
    if (r.status == FrameStatus::Ok) on_frame(k, std::move(r.frame));
    if (r.status == FrameStatus::Disconnected) on_lost(k, r.message);
  }
  if (cams[k].camera) cams[k].camera->stop();
}

PairCapture::PairCapture(const std::string& front_id, const std::string& side_id,
                         const PairCaptureOptions& options)
    : impl_(std::make_unique<Impl>()) {
  options.check();
  if (same_device(front_id, side_id))
    throw std::invalid_argument("front and side are the same device: " + front_id);
  impl_->options = options;
  impl_->pairer = Pairer(options.max_skew_s, size_t(options.keep_recent));
  const std::string ids[2] = {front_id, side_id};
  for (int k = 0; k < 2; ++k) {
    Impl::Cam& c = impl_->cams[k];
    c.id = ids[k];
    c.role = k == 0 ? "front" : "side";
    c.camera = open_camera(c.id);
    c.format = pick_format(*c.camera, options);
  }
  for (int k = 0; k < 2; ++k) impl_->cams[k].camera->start(impl_->cams[k].format);
  impl_->stats.front_connected = impl_->stats.side_connected = true;
  for (int k = 0; k < 2; ++k) impl_->cams[k].thread = std::thread([this, k] { impl_->run(k); });
}

PairCapture::~PairCapture() { stop(); }

void PairCapture::stop() {
  impl_->running = false;
  impl_->cv.notify_all();
  for (auto& c : impl_->cams)
    if (c.thread.joinable()) c.thread.join();
}

std::optional<FramePair> PairCapture::latest_pair() const {
  std::lock_guard<std::mutex> lock(impl_->m);
  if (impl_->recent.empty()) return std::nullopt;
  return impl_->recent.back();
}

std::optional<Frame> PairCapture::latest_front() const {
  std::lock_guard<std::mutex> lock(impl_->m);
  return impl_->cams[0].latest;
}

std::optional<Frame> PairCapture::latest_side() const {
  std::lock_guard<std::mutex> lock(impl_->m);
  return impl_->cams[1].latest;
}

std::optional<FramePair> PairCapture::take_pair(double timeout_s) {
  const double asked = monotonic_now_s();
  std::unique_lock<std::mutex> lock(impl_->m);
  std::optional<FramePair> found;
  impl_->cv.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
    for (const FramePair& p : impl_->recent)
      if (p.front.timestamp_s >= asked && p.side.timestamp_s >= asked) return found = p, true;
    return !impl_->running.load();
  });
  if (found) impl_->taken.push_back(*found);
  return found;
}

std::vector<FramePair> PairCapture::taken() const {
  std::lock_guard<std::mutex> lock(impl_->m);
  return impl_->taken;
}

PairStats PairCapture::stats() const {
  std::lock_guard<std::mutex> lock(impl_->m);
  PairStats s = impl_->stats;
  s.fps_front = rate(impl_->cams[0].window);
  s.fps_side = rate(impl_->cams[1].window);
  s.fps_pairs = rate(impl_->pair_window);
  s.skew_mean_s = s.pairs ? impl_->skew_sum / double(s.pairs) : 0.0;
  return s;
}

std::vector<std::string> PairCapture::events() {
  std::lock_guard<std::mutex> lock(impl_->m);
  std::vector<std::string> out;
  out.swap(impl_->events);
  return out;
}

}  // namespace orthoface::capture
