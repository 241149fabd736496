// The live station's view on a moving sim head (issue 18): the simulated cameras play a head
// that turns (+-25 deg) and nods (+-15 deg) at 30 fps with sensor noise; the station's live view
// (reconstruct::LiveView: tracking, re-texturing, a pitch correction, compositing) runs on each
// pair as it arrives. Scored against the truth of every frame: the pose error, the PSNR over the
// head against the true corrected frame, the output rate, glass-to-output latency, and at rest
// the jitter of the model's landmarks in the output.
//
// The head talks: its mouth opens up to MOUTH mm at the chin and closes three times a loop
// (sim::SimCameraOptions::mouth_mm), and the mouth is scored on its own.
//
//   live_bench [SUBJECTS] [OUT_DIR] [MOUTH_MM] [KEEP_BAND] [SCENE_DIFFERENCE]
//   (default 3 subjects: 1, 2, 3; mouth 8 mm; KEEP_BAND: LiveViewOptions::keep_live_band, the
//   share of the frame's width beside the drawn head where the live frame stays, default the
//   station's; SCENE_DIFFERENCE: LiveViewOptions::scene_difference, 0 = no live mask)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/bench_report.h"
#include "capture/camera.h"
#include "reconstruct/live_view.h"
#include "render/image_metrics.h"
#include "render/renderer.h"
#include "sim/face_mask.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "sim/sim_camera.h"

namespace {

using namespace orthoface;

constexpr double kCorrectionPitchDeg = 10;  // a camera above the screen
constexpr int kWidth = 640, kHeight = 480;

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

using bench::mean;

struct Cameras {
  std::unique_ptr<capture::Camera> front, side;
  Cameras(const sim::SimCameraOptions& o) {
    sim::SimCameraOptions f = o, s = o;
    s.side = true;
    front = sim::open_sim_camera(f);
    side = sim::open_sim_camera(s);
    for (auto* c : {front.get(), side.get()}) c->start({"BGR3", kWidth, kHeight, 30});
  }
  ~Cameras() {
    front->stop();
    side->stop();
  }
  // The next pair of the same sequence number (the side frame comes 7 ms after the front).
  std::pair<capture::Frame, capture::Frame> next() {
    for (;;) {
      auto f = front->next_frame(1.0), s = side->next_frame(1.0);
      if (f.status != capture::FrameStatus::Ok || s.status != capture::FrameStatus::Ok)
        throw std::runtime_error("sim camera: " + f.message + s.message);
      while (s.frame.sequence < f.frame.sequence) s = side->next_frame(1.0);
      if (s.frame.sequence == f.frame.sequence) return {f.frame, s.frame};
    }
  }
};

// The mouth in the true view: the box around the lips and mouth corners, 4 px beyond.
cv::Mat mouth_mask(const sim::Head& head, const capture::CameraModel& camera, cv::Size size) {
  cv::Rect2d box;
  bool first = true;
  for (const char* n : {"mouth_left", "mouth_right", "lip_upper", "lip_lower"}) {
    const Eigen::Vector2d p = capture::project(camera, head.landmarks.at(n));
    const cv::Rect2d r(p.x(), p.y(), 0, 0);
    box = first ? r : (box | r);
    first = false;
  }
  cv::Mat m(size, CV_8U, cv::Scalar(0));
  cv::rectangle(m,
                cv::Rect(cv::Point(int(box.x) - 4, int(box.y) - 4),
                         cv::Point(int(box.br().x) + 5, int(box.br().y) + 5)),
                cv::Scalar(255), cv::FILLED);
  return m;
}

nlohmann::json run_subject(int subject, double mouth_mm,
                           const reconstruct::LiveViewOptions& live_options,
                           const std::string& out_dir, std::ostringstream& md) {
  sim::SimCameraOptions o;
  o.subject = subject;
  o.motion_deg = 25;
  o.pitch_deg = 15;
  o.cycle_frames = 120;  // one turn in 4 s, a nod in 2 s
  o.noise_sigma = 2;
  o.mouth_mm = mouth_mm;
  const sim::Head head = sim::make_head(subject);
  render::Renderer renderer;
  sim::RigOptions rig_options;  // the lighting of the truth renders
  rig_options.width = kWidth;
  rig_options.height = kHeight;

  Cameras cams(o);
  // The fit from the first pair at rest (frame 0 of the loop), as the station fits.
  std::pair<capture::Frame, capture::Frame> pair;
  do pair = cams.next();
  while (pair.first.sequence % o.cycle_frames != 0);
  reconstruct::ReconstructOptions ro;
  ro.rig = sim::sim_camera_rig(o, kWidth, kHeight, 0);
  const reconstruct::Reconstruction fit =
      reconstruct::from_photos(pair.first.image, pair.second.image, ro);
  reconstruct::LiveView live(fit, live_options);

  std::vector<double> err, err_raw, psnr, psnr_face, psnr_mouth, latency, track_ms, texture_ms,
      draw_ms, out_t;
  int lost = 0;
  std::vector<std::string> lost_why;  // the first few
  struct Scored {
    int k;
    std::uint64_t sequence;
    cv::Mat live, output;
    reconstruct::HeadPose truth;
  };
  std::vector<Scored> scored;
  const int frames = 2 * o.cycle_frames;
  for (int k = 0; k < frames; ++k) {
    const auto [f, s] = cams.next();
    const reconstruct::LiveFrame lf =
        live.update(f.image, s.image, f.timestamp_s, 0, kCorrectionPitchDeg);
    const double now = capture::monotonic_now_s();
    latency.push_back((now - f.timestamp_s) * 1e3);
    out_t.push_back(now);
    track_ms.push_back(lf.track_ms);
    texture_ms.push_back(lf.texture_ms);
    draw_ms.push_back(lf.draw_ms);
    if (!lf.track.tracked && ++lost <= 5)
      lost_why.push_back(
          "frame " + std::to_string(k) + " (yaw " +
          std::to_string(std::lround(sim::sim_head_rotation(o, f.sequence).eulerAngles(1, 0, 2)[0] *
                                     57.29578)) +
          "): " + lf.track.reason);
    reconstruct::HeadPose truth;
    truth.rotation = sim::sim_head_rotation(o, f.sequence);
    err.push_back(lf.track.pose.angle_to_deg(truth));
    if (lf.track.tracked) err_raw.push_back(lf.track.raw.angle_to_deg(truth));
    if (k % 8 == 0) scored.push_back({k, f.sequence, f.image.clone(), lf.image.clone(), truth});
  }
  const double fps = (out_t.size() - 1) / (out_t.back() - out_t.front());
  // Scored after the run, so the truth renders do not slow the live loop.
  for (const auto& [k, sequence, live_frame, output, truth] : scored) {
    const sim::Head talking = sim::open_mouth(head, sim::sim_mouth_open_mm(o, sequence));
    // The true corrected frame: the true head at this frame's pose, turned by the correction
    // about the same neck point the view turns it about.
    const capture::CameraModel turned = capture::turned_camera(
        ro.rig->front, 0, kCorrectionPitchDeg, truth.apply(live.model().pivot));
    const render::RenderResult t = sim::render_head(
        talking, rig_options, capture::posed_camera(turned, truth.rotation, truth.translation_mm),
        renderer);
    psnr.push_back(render::psnr(t.image, output, t.mask));
    // The face alone: inside the hull of the true landmarks (brows to chin, cheek to cheek).
    const capture::CameraModel truth_camera =
        capture::posed_camera(turned, truth.rotation, truth.translation_mm);
    const cv::Mat face = sim::landmark_hull_mask(talking, truth_camera, t.mask.size());
    psnr_face.push_back(render::psnr(t.image, output, face & t.mask));
    psnr_mouth.push_back(
        render::psnr(t.image, output, mouth_mask(talking, truth_camera, t.mask.size()) & t.mask));
    if (!out_dir.empty() && k % 40 == 16) {  // the mouth about half open
      // live frame | output | true corrected frame, for a person to look at.
      cv::Mat row;
      cv::hconcat(std::vector<cv::Mat>{live_frame, output, t.image}, row);
      cv::imwrite(out_dir + "/live_" + std::to_string(subject) + "_" + std::to_string(k) + ".png",
                  row);
    }
  }

  // At rest with sensor noise: how much the model's landmarks shake in the output.
  sim::SimCameraOptions still = o;
  still.motion_deg = still.pitch_deg = still.mouth_mm = 0;
  still.cycle_frames = 30;
  Cameras rest(still);
  reconstruct::LiveView steady(fit, live_options);
  std::vector<std::vector<Eigen::Vector2d>> tracks;
  for (int k = 0; k < 90; ++k) {
    const auto [f, s] = rest.next();
    const reconstruct::LiveFrame lf =
        steady.update(f.image, s.image, f.timestamp_s, 0, kCorrectionPitchDeg);
    if (k < 15) continue;  // the filter settles
    std::vector<Eigen::Vector2d> px;
    for (const auto& [name, x] : fit.landmarks) px.push_back(capture::project(lf.camera, x));
    tracks.push_back(px);
  }
  double sq = 0;
  int n = 0;
  for (size_t i = 0; i < tracks.front().size(); ++i) {
    Eigen::Vector2d m = Eigen::Vector2d::Zero();
    for (const auto& t : tracks) m += t[i];
    m /= tracks.size();
    for (const auto& t : tracks) sq += (t[i] - m).squaredNorm(), ++n;
  }
  const double jitter = std::sqrt(sq / n);

  const nlohmann::json j = {
      {"subject", subject},
      {"frames", frames},
      {"pose_error_deg", {{"median", percentile(err, 0.5)}, {"p95", percentile(err, 0.95)}}},
      {"pose_error_raw_deg",
       {{"median", percentile(err_raw, 0.5)}, {"p95", percentile(err_raw, 0.95)}}},
      {"frames_lost", lost},
      {"lost_first", lost_why},
      {"psnr_head_db", {{"mean", mean(psnr)}, {"min", percentile(psnr, 0)}}},
      {"psnr_face_db", {{"mean", mean(psnr_face)}, {"min", percentile(psnr_face, 0)}}},
      {"psnr_mouth_db", {{"mean", mean(psnr_mouth)}, {"min", percentile(psnr_mouth, 0)}}},
      {"fps_out", fps},
      {"latency_ms", {{"median", percentile(latency, 0.5)}, {"p95", percentile(latency, 0.95)}}},
      {"track_ms_median", percentile(track_ms, 0.5)},
      {"texture_ms_median", percentile(texture_ms, 0.5)},
      {"draw_ms_median", percentile(draw_ms, 0.5)},
      {"rest_jitter_px_rms", jitter}};
  char line[300];
  std::snprintf(line, sizeof(line),
                "| %d | %.2f / %.2f | %d | %.1f (%.1f) | %.1f (%.1f) | %.1f (%.1f) | %.1f | %.1f / "
                "%.1f | %.1f + %.1f + %.1f | %.3f |\n",
                subject, percentile(err, 0.5), percentile(err, 0.95), lost, mean(psnr),
                percentile(psnr, 0), mean(psnr_face), percentile(psnr_face, 0), mean(psnr_mouth),
                percentile(psnr_mouth, 0), fps, percentile(latency, 0.5), percentile(latency, 0.95),
                percentile(track_ms, 0.5), percentile(texture_ms, 0.5), percentile(draw_ms, 0.5),
                jitter);
  md << line;
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const int subjects = argc > 1 ? std::stoi(argv[1]) : 3;
    const std::string out_dir = argc > 2 ? argv[2] : "";
    const double mouth_mm = argc > 3 ? std::stod(argv[3]) : 8.0;
    orthoface::reconstruct::LiveViewOptions live_options;
    if (argc > 4) live_options.keep_live_band = std::stod(argv[4]);
    if (argc > 5) live_options.scene_difference = std::stoi(argv[5]);
    if (subjects < 1 || subjects > 50) throw std::invalid_argument("SUBJECTS must be in 1..50");
    if (!(mouth_mm >= 0 && mouth_mm <= 15))
      throw std::invalid_argument("MOUTH_MM must be in 0..15");
    orthoface::bench::make_out_dir(out_dir);  // the frames go there during the run
    std::ostringstream md;
    md << "| subject | pose error median / p95 deg | frames lost | PSNR head dB mean (min) | PSNR "
          "face dB mean (min) | PSNR mouth dB mean (min) | fps out | latency median / p95 ms | "
          "track + texture + draw ms | rest jitter px RMS |\n|---|---|---|---|---|---|---|---|---|"
          "---|\n";
    nlohmann::json runs = nlohmann::json::array();
    std::vector<double> err, psnr, psnr_face, psnr_mouth, fps, lat, jit;
    for (int s = 1; s <= subjects; ++s) {
      runs.push_back(run_subject(s, mouth_mm, live_options, out_dir, md));
      const auto& r = runs.back();
      err.push_back(r["pose_error_deg"]["median"]);
      psnr.push_back(r["psnr_head_db"]["mean"]);
      psnr_face.push_back(r["psnr_face_db"]["mean"]);
      psnr_mouth.push_back(r["psnr_mouth_db"]["mean"]);
      fps.push_back(r["fps_out"]);
      lat.push_back(r["latency_ms"]["median"]);
      jit.push_back(r["rest_jitter_px_rms"]);
    }
    const nlohmann::json j = {{"benchmark", "live_bench"},
                              {"correction_pitch_deg", kCorrectionPitchDeg},
                              {"motion", "yaw +-25 deg, pitch +-15 deg, 4 s loop, noise 2"},
                              {"mouth_mm", mouth_mm},
                              {"keep_live_band", live_options.keep_live_band},
                              {"scene_difference", live_options.scene_difference},
                              {"subjects", runs},
                              {"mean",
                               {{"pose_error_median_deg", mean(err)},
                                {"psnr_head_db", mean(psnr)},
                                {"psnr_face_db", mean(psnr_face)},
                                {"psnr_mouth_db", mean(psnr_mouth)},
                                {"fps_out", mean(fps)},
                                {"latency_median_ms", mean(lat)},
                                {"rest_jitter_px_rms", mean(jit)}}}};
    orthoface::bench::write_report(out_dir, "live_bench", j, md.str());
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
