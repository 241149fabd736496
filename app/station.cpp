// orthoface station: two live cameras, synchronized pairs on request, a fitted face model
// tracked in the live front frames, and its turned view re-textured from the live frames where
// the head is, every frame (the conferencing use). With one camera (--camera, --model) the model
// is an enrolment's (orthoface enrol) and the side texture its profile photo.
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <iostream>
#include <memory>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>

#include <nlohmann/json.hpp>
#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "app/station_http.h"
#include "app/station_output.h"
#include "capture/pair_capture.h"
#include "io/atomic_file.h"
#include "reconstruct/live_view.h"
#include "reconstruct/reconstruction.h"
#include "render/new_view.h"
#include "sim/sim_camera.h"

namespace orthoface::app {
namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

Command station_command() {
  return {
      "station",
      "Live two-camera station: shows both cameras and the head, tracked in every live front "
      "frame, turned by --yaw / --pitch and re-textured from the live frames where it is, drawn "
      "into the live frame; takes a synchronized pair on a key press ('c') or "
      "POST /capture, refits the model on 'r', POST /refit or every --refit-every frames; in the "
      "window 'a' / 'd' turn the view by 5 deg and 'w' / 's' tilt it. "
      "Ctrl-C / SIGTERM stop cleanly; every pair taken is saved in OUT/pairs/. With one camera "
      "(--camera DEV --model DIR): the model of DIR (orthoface enrol or reconstruct) tracked "
      "and re-textured in that camera's frames, the side texture from DIR's side photo; no "
      "pairs or refits.",
      "orthoface station (--front DEV --side DEV | --camera DEV --model DIR) [--yaw DEG] "
      "[--output window|http:PORT|v4l2:/dev/videoN]",
      {{"front", true,
        "DEV  front camera: /dev/videoN, libcamera:ID, sim:N/front or file:VIDEO[?loop&fps=N]"},
       {"side", true, "DEV  side camera"},
       {"camera", true, "DEV  the one camera, instead of --front and --side (needs --model)"},
       {"model", true,
        "DIR  with --camera: the reconstruction folder to track (its front photo taken by that "
        "camera at its size, as orthoface enrol makes it)"},
       {"yaw", true,
        "DEG  rotated view yaw, -90..90 (default 30); with --output http: the page's sliders "
        "and POST /view?yaw=DEG&pitch=DEG change it while running"},
       {"pitch", true, "DEG  rotated view pitch, -60..60 (default 0)"},
       {"output", true, "window|http:PORT|v4l2:/dev/videoN  (default http:8080)"},
       {"bind", true, "ADDR  http address (default 127.0.0.1)"},
       {"duration", true, "S  stop after S seconds (default: until Ctrl-C)"},
       {"size", true, "WxH  capture size (default 640x480; with --model its photo's size)"},
       {"fps", true, "N  capture frame rate (default 30)"},
       {"rig", true, "rig.yaml  calibrated rig (sim: cameras use the simulated rig)"},
       {"retexture-every", true,
        "N  re-texture from the live frames every N output frames (default 1)"},
       {"refit-every", true, "N  refit the model every N output frames (default 0 = on request)"},
       {"out", true, "DIR  pairs and the run summary (default station_out)"},
       {"no-tracking", false,
        "draw the head where it was fitted instead of tracking it in the live frames"},
       {"live-mask", true,
        "N  a live pixel within N grey levels of the scene behind the head (the fit's photo "
        "without the head), joined to the frame's border by such pixels, gives the model no "
        "colour: 0..255, 0 off (default 8; raise it for a noisy camera, 0 when the scene moves)"},
       front_background_flag(),
       side_background_flag()},
      0};
}

struct Settings {
  std::string front, side, output = "http:8080", bind = "127.0.0.1", out = "station_out", rig_file;
  std::string camera, model_dir;  // one camera: its id and the model's folder
  std::shared_ptr<const reconstruct::Reconstruction> model;  // read from model_dir
  double yaw_deg = 30, pitch_deg = 0, duration_s = 0, fps = 30;
  int width = 640, height = 480, refit_every = 0, retexture_every = 1;
  int live_mask = reconstruct::LiveViewOptions{}.scene_difference;
  bool tracking = true;
  vision::ObserveOptions observe;              // the clean plates for the refits
  std::optional<capture::RigCalibration> rig;  // --rig, or the simulated rig for sim: cameras
};

// --camera DEV --model DIR: checked and the model read before anything is opened or written.
void one_camera_settings(const Args& a, Settings& s) {
  for (const char* flag :
       {"front", "side", "rig", "refit-every", "front-background", "side-background"})
    if (a.has(flag))
      throw std::invalid_argument(std::string("station: --") + flag +
                                  " needs two cameras, not --camera");
  if (!a.has("model"))
    throw std::invalid_argument("station: --camera needs --model DIR (orthoface enrol makes one)");
  s.camera = a.get("camera");
  s.model_dir = a.get("model");
  s.model = std::make_shared<const reconstruct::Reconstruction>(
      reconstruct::read_reconstruction(s.model_dir));
  const cv::Size photo = s.model->front.size();
  if (a.has("size") && (photo.width != s.width || photo.height != s.height))
    throw std::invalid_argument("station: --size " + a.get("size") + " is not the size of " +
                                s.model_dir + "'s front photo (" + std::to_string(photo.width) +
                                "x" + std::to_string(photo.height) +
                                "): the camera must give frames of the model's photos");
  s.width = photo.width;
  s.height = photo.height;
}

Settings settings_from(const Args& a) {
  Settings s;
  if (a.has("model") && !a.has("camera"))
    throw std::invalid_argument("station: --model needs --camera DEV (one camera)");
  if (!a.has("camera")) {
    for (const char* flag : {"front", "side"})
      if (!a.has(flag))
        throw std::invalid_argument(std::string("station: --") + flag +
                                    " is required (or --camera DEV --model DIR)");
    s.front = a.get("front");
    s.side = a.get("side");
    if (capture::same_device(s.front, s.side))
      throw std::invalid_argument("station: --front and --side are the same device (" + s.front +
                                  ")");
  }
  if (a.has("yaw")) s.yaw_deg = to_double("yaw", a.get("yaw"), -90, 90);
  if (a.has("pitch")) s.pitch_deg = to_double("pitch", a.get("pitch"), -60, 60);
  if (a.has("duration")) s.duration_s = to_double("duration", a.get("duration"), 0.1, 1e7);
  if (a.has("fps")) s.fps = to_double("fps", a.get("fps"), 1, 240);
  if (a.has("size")) std::tie(s.width, s.height) = to_size("size", a.get("size"), 8192);
  if (a.has("camera")) one_camera_settings(a, s);
  if (a.has("retexture-every"))
    s.retexture_every = to_int("retexture-every", a.get("retexture-every"), 1, 1000000);
  if (a.has("refit-every")) s.refit_every = to_int("refit-every", a.get("refit-every"), 0, 1000000);
  s.tracking = !a.has("no-tracking");
  if (a.has("live-mask")) s.live_mask = to_int("live-mask", a.get("live-mask"), 0, 255);
  s.output = a.get("output", s.output);
  s.bind = a.get("bind", s.bind);
  s.out = a.get("out", s.out);
  if (a.has("rig")) require_file(a.get("rig"), "--rig"), s.rig_file = a.get("rig");
  // Read here, before a port is bound, the output folder made or a camera opened: a bad rig
  // file costs nothing and leaves nothing behind.
  if (s.camera.empty()) {
    s.rig = station_rig(s.rig_file, s.front, s.side, s.width, s.height);
    read_clean_plates(a, s.observe, s.width, s.height);
  }
  const bool ok =
      s.output == "window" || s.output.rfind("http:", 0) == 0 || s.output.rfind("v4l2:", 0) == 0;
  if (!ok)
    throw std::invalid_argument("--output: expected window, http:PORT or v4l2:/dev/videoN, got '" +
                                s.output + "'");
  return s;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p * (v.size() - 1) + 0.5))];
}

class Station {
 public:
  explicit Station(const Settings& s);
  int run();

 private:
  void start_fit(const capture::FramePair& pair);
  void finish_fit();
  void take_pair();
  void handle(const std::string& action);
  void render_view(const capture::Frame& front, const capture::Frame& side);
  void report_status(bool final_line);
  void write_summary();
  capture::PairStats stats() const;
  // One camera: its next frame drawn with the model's side photo; false when it has ended.
  bool one_camera_frame();
  // " | head tracked (yaw Y pitch P)", " | HEAD LOST: why" or " | tracking off".
  std::string tracking_state() const;

  Settings s_;
  std::unique_ptr<capture::PairCapture> pc_;  // two cameras
  std::unique_ptr<capture::Camera> camera_;   // or one (null while it is gone)
  capture::CameraFormat one_format_;          // the one camera's mode, asked again on reopening
  double next_reopen_ = 0;                    // when to try reopening it next (monotonic s)
  capture::PairStats one_stats_;              // the one camera's counters
  std::vector<double> one_times_;             // its frames' timestamps (the last second's fps)
  std::optional<capture::RigCalibration> rig_;
  std::unique_ptr<StationHttp> http_;
  std::unique_ptr<V4l2Output> v4l2_;
  std::unique_ptr<reconstruct::LiveView> live_;  // the fitted head, tracked and drawn
  std::future<reconstruct::Reconstruction> fit_;
  cv::Mat view_;
  std::vector<double> latency_s_, out_times_;
  std::vector<std::string> pairs_saved_, events_;
  double t0_ = 0, texture_time_ = 0;
  std::vector<double> retexture_ms_, draw_ms_, track_ms_;
  int frames_out_ = 0, fits_ = 0, frames_tracked_ = 0, frames_lost_ = 0;
  std::uint64_t last_sequence_ = 0;  // the one camera's last frame
  bool sequence_known_ = false;      // last_sequence_ is this device instance's
  reconstruct::TrackResult track_;   // the last frame's
  bool was_tracked_ = true;          // the last frame's tracked state (true before the first)
};

Station::Station(const Settings& s) : s_(s) {
  sim::register_sim_cameras();
  if (s_.output == "window") require_display("--output window");
  if (s_.output.rfind("http:", 0) == 0) {
    http_ = std::make_unique<StationHttp>(s_.bind, to_int("output", s_.output.substr(5), 1, 65535));
    http_->set_view(s_.yaw_deg, s_.pitch_deg);
  }
  if (s_.output.rfind("v4l2:", 0) == 0)
    v4l2_ = std::make_unique<V4l2Output>(s_.output.substr(5), s_.width, s_.height);
  prepare_output_dir(s_.out);
  rig_ = s_.rig;
  if (s_.model) {
    camera_ = capture::open_camera(s_.camera);
    one_format_ =
        capture::choose_format(camera_->formats(), s_.width, s_.height, s_.fps, s_.camera);
    camera_->start(one_format_);
    one_stats_.front_connected = true;
    reconstruct::LiveViewOptions o;
    o.tracking = s_.tracking;
    o.scene_difference = s_.live_mask;
    o.still_side = true;  // the side texture is the model's own profile photo
    live_ = std::make_unique<reconstruct::LiveView>(*s_.model, o);
    events_.push_back("model read from " + s_.model_dir + " (" +
                      std::to_string(s_.model->mesh.vertices.size()) + " vertices)");
    return;
  }
  capture::PairCaptureOptions o;
  o.width = s_.width;
  o.height = s_.height;
  o.fps = s_.fps;
  pc_ = std::make_unique<capture::PairCapture>(s_.front, s_.side, o);
}

capture::PairStats Station::stats() const {
  if (pc_) return pc_->stats();
  capture::PairStats st = one_stats_;
  size_t first = one_times_.size();
  while (first > 0 && one_times_[first - 1] > one_times_.back() - 1.0) --first;
  const size_t n = one_times_.size() - first;
  st.fps_front = n > 1 ? (n - 1) / (one_times_.back() - one_times_[first]) : 0.0;
  return st;
}

bool Station::one_camera_frame() {
  // A camera that vanished (unplugged, its driver reset) is reopened by id every half second, as
  // the two-camera station does; a file that ended ends the run (its summary is written).
  if (!camera_) {
    const double now = capture::monotonic_now_s();
    if (now < next_reopen_) {
      std::this_thread::sleep_for(
          std::chrono::duration<double>(std::min(0.05, next_reopen_ - now)));
      return true;
    }
    next_reopen_ = now + capture::kReopenIntervalS;
    camera_ = capture::reopen_camera(s_.camera, one_format_);
    if (!camera_) return true;  // still gone
    one_stats_.front_connected = true;
    ++one_stats_.reconnects;
    sequence_known_ = false;  // a new device instance counts its frames afresh
    events_.push_back("camera " + s_.camera + " is back after " +
                      std::to_string(one_stats_.frames_front) + " frames");
  }
  capture::FrameResult r;
  try {
    r = camera_->next_frame(0.25);
  } catch (const std::exception& e) {
    r = {capture::FrameStatus::Disconnected, {}, e.what()};
  }
  if (r.status == capture::FrameStatus::Disconnected) {
    one_stats_.front_connected = false;
    ++one_stats_.disconnects;
    if (s_.camera.rfind("file:", 0) == 0) {
      events_.push_back("camera ended: " + r.message);
      return false;
    }
    events_.push_back("camera lost: " + r.message + "; reopening it");
    try {
      camera_->stop();
    } catch (const std::exception&) {  // a vanished device may refuse even that
    }
    camera_.reset();
    next_reopen_ = capture::monotonic_now_s() + capture::kReopenIntervalS;
    return true;
  }
  if (r.status != capture::FrameStatus::Ok) return true;
  if (sequence_known_ && r.frame.sequence > last_sequence_ + 1)
    one_stats_.dropped_front += r.frame.sequence - last_sequence_ - 1;
  last_sequence_ = r.frame.sequence;
  sequence_known_ = true;
  ++one_stats_.frames_front;
  one_times_.push_back(r.frame.timestamp_s);
  if (one_times_.size() > 512)  // only the last second is used
    one_times_.erase(one_times_.begin(), one_times_.begin() + 256);
  capture::Frame side;  // the enrolment's profile, as if taken with this frame
  side.image = s_.model->side;
  side.timestamp_s = r.frame.timestamp_s;
  render_view(r.frame, side);
  return true;
}

void Station::start_fit(const capture::FramePair& pair) {
  if (fit_.valid()) return;  // one fit at a time
  reconstruct::ReconstructOptions o;
  o.rig = rig_;
  o.observe = s_.observe;
  fit_ = std::async(std::launch::async, [pair, o] {
    return reconstruct::from_photos(pair.front.image, pair.side.image, o);
  });
}

void Station::finish_fit() {
  if (!fit_.valid() || fit_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  try {
    reconstruct::Reconstruction r = fit_.get();
    if (!live_) {
      reconstruct::LiveViewOptions o;
      o.tracking = s_.tracking;
      o.scene_difference = s_.live_mask;
      live_ = std::make_unique<reconstruct::LiveView>(r, o);
    } else {
      live_->refit(r);
    }
    ++fits_;
    events_.push_back("model fitted (" + std::to_string(r.mesh.vertices.size()) + " vertices)");
  } catch (const std::exception& e) {
    events_.push_back(std::string("fit failed: ") + e.what());
  }
}

void Station::take_pair() {
  if (!pc_) return events_.push_back("no pairs with one camera");
  const auto pair = pc_->take_pair(1.5);
  if (!pair) return events_.push_back("no synchronized pair within 1.5 s (is a camera gone?)");
  char name[32];
  std::snprintf(name, sizeof(name), "pair_%03zu", pairs_saved_.size() + 1);
  pairs_saved_.push_back(save_pair(*pair, s_.out + "/pairs/" + name));
  events_.push_back("pair saved: " + pairs_saved_.back());
}

void Station::handle(const std::string& action) {
  if (action == "capture") take_pair();
  if (action == "refit" && pc_) {
    if (auto p = pc_->latest_pair()) start_fit(*p);
  }
}

void Station::render_view(const capture::Frame& front, const capture::Frame& side) {
  // The page's sliders set the view whether or not the fit has finished yet.
  if (http_) std::tie(s_.yaw_deg, s_.pitch_deg) = http_->view();
  if (live_) {
    const bool retexture = frames_out_ % s_.retexture_every == 0 || texture_time_ == 0;
    const reconstruct::LiveFrame lf = live_->update(front.image, side.image, front.timestamp_s,
                                                    s_.yaw_deg, s_.pitch_deg, retexture);
    if (retexture) {
      texture_time_ = std::min(front.timestamp_s, side.timestamp_s);
      retexture_ms_.push_back(lf.texture_ms);
    }
    draw_ms_.push_back(lf.draw_ms);
    if (s_.tracking) {
      track_ms_.push_back(lf.track_ms);
      // An event when the tracked state changes; was_tracked_ starts true, so a first frame
      // that is lost is a loss and a first frame that is tracked is no recovery.
      if (lf.track.tracked != was_tracked_)
        events_.push_back(lf.track.tracked ? "head tracking recovered"
                                           : "head tracking lost: " + lf.track.reason);
      was_tracked_ = lf.track.tracked;
      ++(lf.track.tracked ? frames_tracked_ : frames_lost_);
    }
    track_ = lf.track;
    view_ = lf.image;
  } else {
    view_ = cv::Mat(front.image.size(), CV_8UC3, cv::Scalar(40, 40, 40));
    cv::putText(view_, "fitting the model...", {20, view_.rows / 2}, cv::FONT_HERSHEY_SIMPLEX, 1.0,
                cv::Scalar(220, 220, 220), 2);
  }
  const double now = capture::monotonic_now_s();
  // Capture-to-output: from the older frame whose pixels the view shows (the texture source).
  latency_s_.push_back(now -
                       (live_ ? texture_time_ : std::min(front.timestamp_s, side.timestamp_s)));
  out_times_.push_back(now);
  ++frames_out_;
  if (v4l2_) v4l2_->write(view_);
  if (http_) {
    http_->publish("front", front.image);
    http_->publish("side", side.image);
    http_->publish("view", view_);
  }
  if (s_.output == "window") {
    cv::Mat row, side_shown = side.image;
    if (side_shown.rows != front.image.rows)  // a model's side photo of another size
      cv::resize(side_shown, side_shown,
                 {side_shown.cols * front.image.rows / side_shown.rows, front.image.rows});
    cv::hconcat(std::vector<cv::Mat>{front.image, side_shown, view_}, row);
    cv::imshow("orthoface station", row);
    const int key = cv::waitKey(1);
    if (key == 'c' || key == ' ') take_pair();
    if (key == 'r') handle("refit");
    if (key == 'q' || key == 27) g_stop = 1;
    // a / d turn the view 5 deg to the subject's right / left, w / s look from above / below.
    if (key == 'a' || key == 'd')
      s_.yaw_deg = std::clamp(s_.yaw_deg + (key == 'd' ? 5 : -5), -90.0, 90.0);
    if (key == 'w' || key == 's')
      s_.pitch_deg = std::clamp(s_.pitch_deg + (key == 'w' ? 5 : -5), -60.0, 60.0);
  }
}

void Station::report_status(bool final_line) {
  const capture::PairStats st = stats();
  size_t k = out_times_.size();
  size_t first = k;
  while (first > 0 && out_times_[first - 1] > out_times_.back() - 1.0) --first;
  const double fps =
      k - first > 1 ? (k - first - 1) / (out_times_.back() - out_times_[first]) : 0.0;
  const double lat = latency_s_.empty() ? 0 : latency_s_.back();
  char line[400];
  std::snprintf(
      line, sizeof(line),
      "out %.1f fps | cams %.1f/%.1f fps | skew %.1f ms | latency %.0f ms | drops %llu/%llu "
      "| pairs %zu | %s/%s%s",
      fps, st.fps_front, st.fps_side, st.skew_last_s * 1e3, lat * 1e3,
      static_cast<unsigned long long>(st.dropped_front),
      static_cast<unsigned long long>(st.dropped_side), pairs_saved_.size(),
      st.front_connected ? "front ok" : "FRONT LOST",
      pc_ ? (st.side_connected ? "side ok" : "SIDE LOST") : "model side photo",
      !live_ ? " | no model yet" : tracking_state().c_str());
  std::fprintf(stderr, "\r%-118s%s", line, final_line ? "\n" : "");
  if (http_) {
    const nlohmann::json j = {{"fps_out", fps},
                              {"fps_front", st.fps_front},
                              {"fps_side", st.fps_side},
                              {"skew_ms", st.skew_last_s * 1e3},
                              {"latency_ms", lat * 1e3},
                              {"dropped_front", st.dropped_front},
                              {"dropped_side", st.dropped_side},
                              {"pairs", pairs_saved_.size()},
                              {"tracking", live_ ? tracking_state().substr(3) : "no model yet"}};
    http_->set_status(j.dump());
  }
}

std::string Station::tracking_state() const {
  if (!s_.tracking) return " | tracking off";
  if (frames_tracked_ + frames_lost_ == 0) return " | tracking starts";
  if (!track_.tracked)
    return " | HEAD LOST: " + (track_.reason.empty() ? "not yet" : track_.reason);
  char text[96];
  std::snprintf(text, sizeof(text), " | head tracked (yaw %.1f pitch %.1f)", track_.pose.yaw_deg(),
                track_.pose.pitch_deg());
  return text;
}

void Station::write_summary() {
  const capture::PairStats st = stats();
  const double span = out_times_.size() > 1 ? out_times_.back() - out_times_.front() : 0;
  // Skip the first second (model fit, caches) for the steady-state figures.
  std::vector<double> lat;
  for (size_t i = 0; i < latency_s_.size(); ++i)
    if (out_times_[i] > t0_ + 1.0) lat.push_back(latency_s_[i] * 1e3);
  const double mean_lat =
      lat.empty() ? 0 : std::accumulate(lat.begin(), lat.end(), 0.0) / lat.size();
  const nlohmann::json j = {
      {"duration_s", capture::monotonic_now_s() - t0_},
      {"frames_out", frames_out_},
      {"fps_out", span > 0 ? (out_times_.size() - 1) / span : 0.0},
      {"latency_ms",
       {{"mean", mean_lat}, {"p95", percentile(lat, 0.95)}, {"max", percentile(lat, 1.0)}}},
      {"skew_ms", {{"mean", st.skew_mean_s * 1e3}, {"max", st.skew_max_s * 1e3}}},
      {"frames_front", st.frames_front},
      {"frames_side", st.frames_side},
      {"pairs_formed", st.pairs},
      {"dropped_front", st.dropped_front},
      {"dropped_side", st.dropped_side},
      {"unpaired", st.unpaired},
      {"disconnects", st.disconnects},
      {"reconnects", st.reconnects},
      {"fits", fits_},
      {"retexture_every", s_.retexture_every},
      {"live_mask", s_.live_mask},
      {"set_photos_ms_median", percentile(retexture_ms_, 0.5)},
      {"render_ms_median", percentile(draw_ms_, 0.5)},
      {"tracking",
       {{"enabled", s_.tracking},
        {"frames_tracked", frames_tracked_},
        {"frames_lost", frames_lost_},
        {"track_ms_median", percentile(track_ms_, 0.5)},
        {"state", live_ ? tracking_state().substr(3) : "no model"},
        {"last_pose_deg",
         {{"yaw", track_.pose.yaw_deg()},
          {"pitch", track_.pose.pitch_deg()},
          {"roll", track_.pose.roll_deg()}}}}},
      {"cameras", pc_ ? nlohmann::json{{"front", s_.front}, {"side", s_.side}}
                      : nlohmann::json{{"camera", s_.camera}, {"model", s_.model_dir}}},
      {"view_yaw_deg", s_.yaw_deg},
      {"view_pitch_deg", s_.pitch_deg},
      {"pairs_saved", pairs_saved_},
      {"events", events_}};
  const std::string text = j.dump(2) + "\n";
  io::write_text_atomically(s_.out + "/station_summary.json", text);
  std::cout << text;
}

int Station::run() {
  t0_ = capture::monotonic_now_s();
  if (s_.model) {  // one camera
    double next_status = t0_;
    while (!g_stop && (s_.duration_s <= 0 || capture::monotonic_now_s() - t0_ < s_.duration_s)) {
      if (http_)
        for (const std::string& a : http_->take_actions()) handle(a);
      if (!one_camera_frame()) break;
      if (capture::monotonic_now_s() >= next_status) report_status(false), next_status += 0.5;
    }
    report_status(true);
    if (camera_) camera_->stop();
    write_summary();
    return 0;
  }
  if (auto first = pc_->take_pair(5.0)) start_fit(*first);
  std::uint64_t last_front = ~0ull, last_side = ~0ull;
  double next_status = t0_;
  while (!g_stop && (s_.duration_s <= 0 || capture::monotonic_now_s() - t0_ < s_.duration_s)) {
    finish_fit();
    for (std::string& e : pc_->events()) events_.push_back(std::move(e));
    if (http_)
      for (const std::string& a : http_->take_actions()) handle(a);
    const auto f = pc_->latest_front();
    const auto s = pc_->latest_side();
    const bool fresh = f && s && (f->sequence != last_front || s->sequence != last_side);
    if (!fresh) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      continue;
    }
    last_front = f->sequence;
    last_side = s->sequence;
    render_view(*f, *s);
    if (s_.refit_every > 0 && frames_out_ % s_.refit_every == 0) handle("refit");
    if (capture::monotonic_now_s() >= next_status) report_status(false), next_status += 0.5;
  }
  report_status(true);
  pc_->stop();
  if (fit_.valid()) fit_.wait();
  write_summary();
  return 0;
}

}  // namespace

int run_station(int argc, char** argv) {
  const Command command = station_command();
  const Args args = parse_args(command, argc, argv);
  if (args.help) {
    print_help(command);
    return 0;
  }
  const Settings settings = settings_from(args);
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  Station station(settings);
  return station.run();
}

}  // namespace orthoface::app
