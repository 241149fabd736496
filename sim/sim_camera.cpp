#include "sim/sim_camera.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <random>
#include <regex>
#include <stdexcept>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "sim/head.h"
#include "sim/rig.h"

namespace orthoface::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The head's yaw and pitch in frame `sequence` (degrees; sim/sim_camera.h).
std::pair<double, double> frame_pose(const SimCameraOptions& o, std::uint64_t sequence) {
  const double k = static_cast<double>(sequence % static_cast<std::uint64_t>(o.cycle_frames));
  if (o.turn) return {o.motion_deg * k / std::max(1, o.cycle_frames - 1), 0.0};
  return {o.motion_deg * std::sin(2 * kPi * k / o.cycle_frames),
          o.pitch_deg * std::sin(4 * kPi * k / o.cycle_frames)};
}

// How far the mouth is open in frame `sequence` (mm the chin is lowered; sim/sim_camera.h).
double frame_mouth(const SimCameraOptions& o, std::uint64_t sequence) {
  const double k = static_cast<double>(sequence % static_cast<std::uint64_t>(o.cycle_frames));
  return o.mouth_mm * 0.5 * (1 - std::cos(2 * kPi * kMouthCycles * k / o.cycle_frames));
}

// A turn past -45 degrees is beyond what the rig's cameras turn (sim::PoseError, +-45): the front
// camera's frame is then the side camera's, whose nominal view is the head turned by -90, turned
// by the rest (yaw + 90). Same intrinsics, same light (fixed to the head), so the same image.
constexpr double kMaxCameraTurnDeg = 45;
bool front_from_side(const SimCameraOptions& o, std::uint64_t sequence) {
  return o.turn && frame_pose(o, sequence).first < -kMaxCameraTurnDeg;
}

// The RigOptions that render frame `sequence` of a width x height mode: the ideal rig scaled
// with the width, the head's turn played as both cameras turning about it (sim/sim_camera.h).
RigOptions frame_rig_options(const SimCameraOptions& o, int width, int height,
                             std::uint64_t sequence) {
  RigOptions rig;
  rig.width = width;
  rig.height = height;
  rig.px_per_mm *= width / 640.0;
  const auto [yaw, pitch] = frame_pose(o, sequence);
  // Head yaw = both cameras yawing about their image y axes (level rig). Head pitch = the front
  // camera pitching about its image x axis = the side camera rolling about its view axis by
  // -pitch (its view axis is -x of the head frame, its image x is -z).
  rig.front_error.yaw_deg = rig.side_error.yaw_deg = front_from_side(o, sequence) ? yaw + 90 : yaw;
  rig.front_error.pitch_deg = pitch;
  rig.side_error.roll_deg = -pitch;
  rig.noise_sigma = o.noise_sigma;
  rig.seed = sequence % static_cast<std::uint64_t>(o.cycle_frames);  // a new draw every frame
  return rig;
}

// The rendered loop of one subject at one size: both views of each pose. Shared by the front
// and side cameras of a subject (same motion) so the pair is rendered once.
struct Loop {
  std::vector<cv::Mat> front, side;
};

std::shared_ptr<const Loop> render_loop(const SimCameraOptions& o, int width, int height) {
  static std::mutex m;
  static std::map<std::tuple<int, int, int, int, double, double, double, bool, double>,
                  std::weak_ptr<const Loop>>
      cache;
  std::lock_guard<std::mutex> lock(m);
  const auto key = std::make_tuple(o.subject, width, height, o.cycle_frames, o.motion_deg,
                                   o.pitch_deg, o.noise_sigma, o.turn, o.mouth_mm);
  if (auto hit = cache[key].lock()) return hit;
  const Head head = make_head(o.subject);
  render::Renderer renderer;
  auto loop = std::make_shared<Loop>();
  for (int k = 0; k < o.cycle_frames; ++k) {
    const double mouth = frame_mouth(o, static_cast<std::uint64_t>(k));
    const Capture c = simulate_capture(
        mouth > 0 ? open_mouth(head, mouth) : head,
        frame_rig_options(o, width, height, static_cast<std::uint64_t>(k)), renderer);
    loop->front.push_back(front_from_side(o, static_cast<std::uint64_t>(k)) ? c.side : c.front);
    loop->side.push_back(c.side);
  }
  cache[key] = loop;
  return loop;
}

class SimCamera : public capture::Camera {
 public:
  SimCamera(std::string id, const SimCameraOptions& o)
      : id_(std::move(id)), o_(o), rng_(o.subject) {
    if (o_.phase_s < 0) o_.phase_s = o_.side ? 0.007 : 0.0;
  }
  std::string name() const override { return id_; }
  std::vector<capture::CameraFormat> formats() const override {
    std::vector<capture::CameraFormat> f;
    for (auto [w, h] : {std::pair{320, 240}, {640, 480}, {1280, 720}})
      for (double fps : {30.0, 15.0}) f.push_back({"BGR3", w, h, fps});
    return f;
  }
  void start(const capture::CameraFormat& format) override {
    bool offered = false;
    for (const auto& f : formats())
      offered |= f.fourcc == format.fourcc && f.width == format.width &&
                 f.height == format.height && (format.fps <= 0 || f.fps == format.fps);
    if (!offered)
      throw std::runtime_error("camera " + id_ + ": does not offer " + format.fourcc + " " +
                               std::to_string(format.width) + "x" + std::to_string(format.height));
    loop_ = render_loop(o_, format.width, format.height);
    period_ = 1.0 / (format.fps > 0 ? format.fps : 30.0);
    k_ = static_cast<std::uint64_t>(std::ceil((capture::monotonic_now_s() - o_.phase_s) / period_));
  }
  capture::FrameResult next_frame(double timeout_s) override {
    if (!loop_) throw std::runtime_error("camera " + id_ + ": next_frame before start");
    std::uniform_real_distribution<double> jitter(-o_.jitter_s, o_.jitter_s);
    const double now = capture::monotonic_now_s();
    if (k_ * period_ + o_.phase_s < now - 2 * period_)  // consumer was away: frames lost
      k_ = static_cast<std::uint64_t>(std::ceil((now - o_.phase_s) / period_));
    const double t = k_ * period_ + o_.phase_s + jitter(rng_);
    if (t - now > timeout_s) {
      std::this_thread::sleep_for(std::chrono::duration<double>(timeout_s));
      return {capture::FrameStatus::Timeout, {}, "camera " + id_ + ": no frame in time"};
    }
    if (t > now) std::this_thread::sleep_for(std::chrono::duration<double>(t - now));
    const auto& images = o_.side ? loop_->side : loop_->front;
    capture::Frame f;
    f.image = images[k_ % images.size()].clone();
    f.timestamp_s = t;
    f.sequence = k_++;
    return {capture::FrameStatus::Ok, std::move(f), ""};
  }
  void stop() override { loop_.reset(); }

 private:
  std::string id_;
  SimCameraOptions o_;
  std::mt19937_64 rng_;
  std::shared_ptr<const Loop> loop_;
  double period_ = 1.0 / 30;
  std::uint64_t k_ = 0;
};

}  // namespace

void SimCameraOptions::check() const {
  if (subject < 0) throw std::invalid_argument("SimCameraOptions: subject must be >= 0");
  if (cycle_frames < 1 || cycle_frames > 240)
    throw std::invalid_argument("SimCameraOptions: cycle_frames must be in 1..240");
  if (!turn && !(std::abs(motion_deg) <= 30))
    throw std::invalid_argument("SimCameraOptions: motion_deg must be in [-30, 30]");
  if (turn && !(motion_deg >= -90 && motion_deg <= kMaxCameraTurnDeg))
    throw std::invalid_argument("SimCameraOptions: motion_deg of a turn must be in [-90, 45]");
  if (turn && (cycle_frames < 2 || pitch_deg != 0 || side))
    throw std::invalid_argument(
        "SimCameraOptions: a turn is the front camera's, without a nod, over cycle_frames >= 2");
  if (!(std::abs(pitch_deg) <= 20))
    throw std::invalid_argument("SimCameraOptions: pitch_deg must be in [-20, 20]");
  if (!(noise_sigma >= 0 && noise_sigma <= 20))
    throw std::invalid_argument("SimCameraOptions: noise_sigma must be in [0, 20]");
  if (!(jitter_s >= 0 && jitter_s < 0.01))
    throw std::invalid_argument("SimCameraOptions: jitter_s must be in [0, 0.01)");
  if (!std::isfinite(phase_s)) throw std::invalid_argument("SimCameraOptions: phase_s not finite");
  if (!(mouth_mm >= 0 && mouth_mm <= 15))
    throw std::invalid_argument("SimCameraOptions: mouth_mm must be in [0, 15]");
}

double sim_mouth_open_mm(const SimCameraOptions& options, std::uint64_t sequence) {
  options.check();
  return frame_mouth(options, sequence);
}

Eigen::Matrix3d sim_head_rotation(const SimCameraOptions& options, std::uint64_t sequence) {
  const capture::RigCalibration truth = sim_camera_rig(options, 640, 480, sequence);
  const capture::RigCalibration nominal =
      nominal_rig(frame_rig_options(options, 640, 480, sequence));
  return nominal.front.cam_from_head.linear().transpose() * truth.front.cam_from_head.linear();
}

capture::RigCalibration sim_camera_rig(const SimCameraOptions& options, int width, int height,
                                       std::uint64_t sequence) {
  options.check();
  capture::RigCalibration rig = true_rig(frame_rig_options(options, width, height, sequence));
  if (front_from_side(options, sequence)) rig.front = rig.side;
  return rig;
}

std::unique_ptr<capture::Camera> open_sim_camera(const SimCameraOptions& options) {
  options.check();
  const std::string id =
      "sim:" + std::to_string(options.subject) + (options.side ? "/side" : "/front");
  return std::make_unique<SimCamera>(id, options);
}

std::unique_ptr<capture::Camera> open_sim_camera(const std::string& id) {
  static const std::regex re(R"(sim:(\d{1,6})/(front|side)(?:\?(.*))?)");
  std::smatch m;
  if (!std::regex_match(id, m, re))
    throw std::runtime_error("camera " + id +
                             ": expected sim:N/front or sim:N/side (N = subject number), "
                             "optionally ?yaw=DEG&pitch=DEG&frames=N&noise=SIGMA&mouth=MM (or "
                             "turn=DEG instead of yaw)");
  SimCameraOptions o;
  o.subject = std::stoi(m[1]);
  o.side = m[2] == "side";
  const std::string query = m[3];
  bool motion_set = false;  // yaw= or turn= seen
  for (size_t begin = 0; begin <= query.size();) {
    size_t end = query.find('&', begin);
    if (end == std::string::npos) end = query.size();
    const std::string item = query.substr(begin, end - begin);
    begin = end + 1;
    if (item.empty()) continue;
    const size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    if (key != "yaw" && key != "pitch" && key != "frames" && key != "noise" && key != "turn" &&
        key != "mouth")
      throw std::runtime_error("camera " + id + ": unknown option '" + key +
                               "' (expected yaw, turn, pitch, frames, noise or mouth)");
    if (key == "yaw" || key == "turn") {
      if (motion_set) throw std::runtime_error("camera " + id + ": give one of yaw and turn, once");
      motion_set = true;
    }
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    double v = 0;
    size_t used = 0;
    try {
      v = std::stod(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (value.empty() || used != value.size() || !std::isfinite(v) ||
        (key == "frames" && v != std::floor(v)))
      throw std::runtime_error("camera " + id + ": " + key + " = '" + value + "' is not " +
                               (key == "frames"  ? "a whole number"
                                : key == "mouth" ? "a number (mm)"
                                                 : "a number (degrees)"));
    if (key == "yaw" || key == "turn") o.motion_deg = v;
    if (key == "turn") o.turn = true;
    if (key == "pitch") o.pitch_deg = v;
    if (key == "noise") o.noise_sigma = v;
    if (key == "mouth") o.mouth_mm = v;
    if (key == "frames") o.cycle_frames = std::abs(v) < 1e6 ? static_cast<int>(v) : -1;
  }
  try {
    o.check();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("camera " + id + ": " + e.what() +
                             " (query keys: yaw = motion_deg, turn = motion_deg of one turn, "
                             "pitch = pitch_deg, frames = cycle_frames, noise = noise_sigma, "
                             "mouth = mouth_mm)");
  }
  return std::make_unique<SimCamera>(id, o);
}

void register_sim_cameras() {
  capture::register_camera_backend(
      "sim:",
      {[](const std::string& id) { return open_sim_camera(id); },
       [] {
         std::vector<capture::DeviceInfo> out;
         for (const char* view : {"front", "side"}) {
           auto cam = open_sim_camera(std::string("sim:0/") + view);
           out.push_back({cam->name(),
                          std::string("simulated rig, subject N (any), ") + view + " camera",
                          cam->formats()});
         }
         return out;
       }});
}

}  // namespace orthoface::sim
