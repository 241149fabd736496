// vision benchmarks, JSON on stdout:
//   vision_bench speed [reps]          observe() on a 640x480 sim front + side pair (median ms)
//   vision_bench stages [reps]         median CPU ms of each vision stage on the same pair
//   (VISION_THREADS=N sets cv::setNumThreads for speed / stages)
//   vision_bench sim [subjects] [filters|network|consensus]  accuracy over sim subjects, ideal rig,
//   4
//                                      conditions, with that front landmarker
//   vision_bench simshow SEED OUT [COND]  one sim subject: truth (green) vs detection overlays,
//                                      per-landmark truth / detected px and error
//   vision_bench frmdb DIR OUT         real FRMDB pairs (Img_33 front, Img_53 side), overlays in
//   OUT, observe() wall ms per pair (after a warm-up pair)
//   vision_bench ibug DIR              eye / nose / mouth centre error / inter-ocular distance
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/head.h"
#include "sim/rig.h"
#include "tests/vision/sim_eval.h"
#include "vision/edges.h"
#include "vision/foreground.h"
#include "vision/front_boundary.h"
#include "vision/front_features.h"
#include "vision/image_prep.h"
#include "vision/observe.h"
#include "vision/overlay.h"
#include "vision/side_profile.h"

namespace ov = orthoface::vision;
namespace sim = orthoface::sim;
namespace ot = orthoface::testing;
using nlohmann::json;

namespace {

// CPU time of the whole process (all threads), ms: less disturbed than wall time on a busy machine.
double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

int speed(int reps) {
  const sim::Capture cap = sim::simulate_capture(sim::make_head(sim::head_params(0)), {});
  std::vector<double> ms, cpu;
  ov::observe(cap.front, cap.side);  // warm-up (OpenCV colour tables)
  for (int i = 0; i < reps; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = process_cpu_ms();
    ov::observe(cap.front, cap.side);
    cpu.push_back(process_cpu_ms() - c0);
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  std::sort(cpu.begin(), cpu.end());
  std::cout << json{{"benchmark", "observe_640x480_pair"},
                    {"reps", reps},
                    {"median_ms", ms[ms.size() / 2]},
                    {"min_ms", ms.front()},
                    {"max_ms", ms.back()},
                    {"median_cpu_ms", cpu[cpu.size() / 2]},
                    {"target_ms", 8.0}}
                   .dump(1)
            << "\n";
  return 0;
}

// Median process CPU ms of `f` over `reps` runs (after one warm-up run).
template <class F>
double median_ms(int reps, F&& f) {
  f();
  std::vector<double> ms;
  for (int i = 0; i < reps; ++i) {
    const double c0 = process_cpu_ms();
    f();
    ms.push_back(process_cpu_ms() - c0);
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

// The stages of observe() one by one on the speed pair, to see where the time goes.
int stages(int reps) {
  const sim::Capture cap = sim::simulate_capture(sim::make_head(sim::head_params(0)), {});
  const cv::Mat front = ov::to_bgr8(cap.front, "front"), side = ov::to_bgr8(cap.side, "side");
  json t = json::object();
  cv::Mat fprob, fmask, sprob, smask;
  t["to_bgr8_pair"] =
      median_ms(reps, [&] { ov::to_bgr8(cap.front, "f"), ov::to_bgr8(cap.side, "s"); });
  t["foreground_probability_front"] =
      median_ms(reps, [&] { fprob = ov::foreground_probability(front, {}); });
  t["head_mask_front"] = median_ms(reps, [&] { fmask = ov::head_mask(fprob); });
  t["foreground_probability_side"] =
      median_ms(reps, [&] { sprob = ov::foreground_probability(side, {}); });
  t["head_mask_side"] = median_ms(reps, [&] { smask = ov::head_mask(sprob); });
  t["edge_image_prob"] = median_ms(reps, [&] { ov::edge_image(fprob, {0.7, 0.1}); });
  t["profile_faces_left"] = median_ms(reps, [&] {
    double c;
    ov::profile_faces_left(smask, side, &c);
  });
  ov::SideProfile sp;
  t["side_profile"] = median_ms(reps, [&] { sp = ov::side_profile(side, sprob, smask); });
  ov::FrontBoundary fb;
  t["front_boundary"] = median_ms(reps, [&] { fb = ov::front_boundary(fprob, fmask, -1); });
  std::map<std::string, double> rows;
  for (const auto& [n, f] : sp.features) rows[n] = f.px.y;
  t["front_features"] =
      median_ms(reps, [&] { ov::front_features(front, fb, rows, sp.head_height_px); });
  t["observe"] = median_ms(reps, [&] { ov::observe(cap.front, cap.side); });
  std::cout << json{{"benchmark", "observe_stages_median_ms"}, {"reps", reps}, {"stages", t}}.dump(
                   1)
            << "\n";
  return 0;
}

sim::RigOptions condition(const std::string& name, int seed) {
  sim::RigOptions o;
  o.seed = std::uint64_t(seed);
  if (name == "noise_blur") o.noise_sigma = 4, o.blur_sigma = 0.8;
  if (name == "roll_yaw")
    o.front_error.roll_deg = 1.0, o.front_error.yaw_deg = 2.0, o.side_error.yaw_deg = 2.0;
  if (name == "all")
    o.noise_sigma = 4, o.blur_sigma = 0.8, o.front_error.roll_deg = 1.0, o.side_error.yaw_deg = 2.0;
  return o;
}

int accuracy(int subjects, ov::FrontLandmarker landmarker) {
  ov::ObserveOptions oo;
  oo.landmarker = landmarker;
  json out = json::object();
  orthoface::render::Renderer renderer;
  for (const std::string cond : {"ideal", "noise_blur", "roll_yaw", "all"}) {
    std::map<std::string, std::vector<double>> per;
    std::vector<double> all, bnd, prof;
    json subj = json::array();
    double worst = -1;
    int worst_seed = -1;
    for (int seed = 0; seed < subjects; ++seed) {
      const sim::Capture cap = sim::simulate_capture(sim::make_head(sim::head_params(seed)),
                                                     condition(cond, seed), renderer);
      const ov::FaceObservation obs = ov::observe(cap.front, cap.side, oo);
      const ot::SimScore s = ot::score(obs, cap);
      for (const auto& [n, e] : s.front_err) per["front:" + n].push_back(e), all.push_back(e);
      for (const auto& [n, e] : s.side_err) per["side:" + n].push_back(e), all.push_back(e);
      bnd.push_back(s.boundary_err);
      prof.push_back(s.profile_err);
      const double med = ot::median(ot::all_errors(s));
      subj.push_back({{"seed", seed},
                      {"median_px", med},
                      {"boundary_px", s.boundary_err},
                      {"profile_px", s.profile_err},
                      {"missing", s.missing.size()},
                      {"warnings", obs.warnings}});
      if (med > worst) worst = med, worst_seed = seed;
    }
    json lm = json::object();
    for (const auto& [n, v] : per)
      lm[n] = {{"median_px", ot::median(v)}, {"max_px", *std::max_element(v.begin(), v.end())}};
    double mb = 0, mp = 0;
    for (double b : bnd) mb += b / bnd.size();
    for (double p : prof) mp += p / prof.size();
    out[cond] = {{"subjects", subjects},        {"median_landmark_px", ot::median(all)},
                 {"boundary_mean_px", mb},      {"profile_mean_px", mp},
                 {"worst_subject", worst_seed}, {"worst_median_px", worst},
                 {"per_landmark", lm},          {"per_subject", subj}};
  }
  std::cout << out.dump(1) << "\n";
  return 0;
}

// One subject in detail: overlays (front, side) with the truth drawn as green crosses, x3.
int simshow(int seed, const std::string& outdir, const std::string& cond) {
  std::filesystem::create_directories(outdir);
  const sim::Capture cap =
      sim::simulate_capture(sim::make_head(sim::head_params(seed)), condition(cond, seed));
  const ov::FaceObservation obs = ov::observe(cap.front, cap.side);
  cv::Mat f = ov::overlay_front(cap.front, obs), s = ov::overlay_side(cap.side, obs);
  const double k = 3;
  cv::resize(f, f, {}, k, k, cv::INTER_NEAREST);
  cv::resize(s, s, {}, k, k, cv::INTER_NEAREST);
  json out = json::object();
  const auto cross = [&](cv::Mat& m, const Eigen::Vector2d& p) {
    const cv::Point2d c((p.x() - 0.5) * k, (p.y() - 0.5) * k);
    cv::line(m, c - cv::Point2d(6, 6), c + cv::Point2d(6, 6), cv::Scalar(0, 255, 0), 2);
    cv::line(m, c - cv::Point2d(6, -6), c + cv::Point2d(6, -6), cv::Scalar(0, 255, 0), 2);
  };
  // One view's truth cross on its overlay and truth / found / error / method in `r`.
  const auto score = [&](json& r, const std::string& view, cv::Mat& overlay,
                         const Eigen::Vector2d& truth, const ov::ViewObservation& found,
                         const std::string& name) {
    cross(overlay, truth);
    r[view + "_truth"] = {truth.x(), truth.y()};
    const auto it = found.features.find(name);
    if (it == found.features.end()) return;
    r[view + "_found"] = {it->second.px.x, it->second.px.y};
    r[view + "_err"] = std::hypot(it->second.px.x - truth.x(), it->second.px.y - truth.y());
    r[view + "_method"] = it->second.method;
  };
  for (const auto& [name, t] : cap.landmarks) {
    json r = json::object();
    if (t.visible_front) score(r, "front", f, t.front_px, obs.front, name);
    if (t.visible_side) score(r, "side", s, t.side_px, obs.side, name);
    out[name] = r;
  }
  const std::string base = outdir + "/sim" + std::to_string(seed) + "_" + cond;
  cv::imwrite(base + "_front.png", f);
  cv::imwrite(base + "_side.png", s);
  // Close-ups around the face (front) and the profile below the brows (side).
  const auto crop = [&](const cv::Mat& m, cv::Rect r) {
    return m(r & cv::Rect(0, 0, m.cols, m.rows));
  };
  if (cap.landmarks.count("nose_tip")) {
    const Eigen::Vector2d tf = cap.landmarks.at("nose_tip").front_px,
                          ts = cap.landmarks.at("nose_tip").side_px;
    cv::imwrite(base + "_frontcrop.png",
                crop(f, cv::Rect(int((tf.x() - 80) * k), int((tf.y() - 70) * k), int(160 * k),
                                 int(150 * k))));
    cv::Mat raw;
    cv::resize(cap.front, raw, {}, k, k, cv::INTER_NEAREST);
    cv::imwrite(base + "_frontraw.png",
                crop(raw, cv::Rect(int((tf.x() - 80) * k), int((tf.y() - 70) * k), int(160 * k),
                                   int(150 * k))));
    cv::imwrite(base + "_sidecrop.png",
                crop(s, cv::Rect(int((ts.x() - 30) * k), int((ts.y() - 70) * k), int(110 * k),
                                 int(160 * k))));
  }
  json sil = json::array();  // first head column of each side-mask row (the true silhouette)
  for (int r = 0; r < cap.side_mask.rows; ++r) {
    int c = 0;
    while (c < cap.side_mask.cols && !cap.side_mask.at<uchar>(r, c)) ++c;
    sil.push_back(c);
  }
  std::cout << json{{"seed", seed},
                    {"condition", cond},
                    {"landmarks", out},
                    {"side_mask_first_col", sil},
                    {"warnings", obs.warnings}}
                   .dump(1)
            << "\n";
  return 0;
}

// The front photo with the front features as small dots (red found, magenta mirrored, yellow
// position model) and no labels, for close-ups.
cv::Mat points_only(const cv::Mat& front, const ov::FaceObservation& obs) {
  cv::Mat m = ov::to_bgr8(front, "front");
  for (const auto& [name, f] : obs.front.features) {
    const cv::Scalar col = f.mirrored ? cv::Scalar(255, 0, 255)
                           : f.method.find("position-model") != std::string::npos
                               ? cv::Scalar(0, 255, 255)
                               : cv::Scalar(0, 0, 255);
    cv::circle(m, f.px - cv::Point2d(0.5, 0.5), 1, col, cv::FILLED);
  }
  return m;
}

int frmdb(const std::string& dir, const std::string& outdir) {
  json res = json::array();
  int complete = 0, total = 0;
  std::vector<std::string> people;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.is_directory()) people.push_back(e.path().filename().string());
  std::sort(people.begin(), people.end());
  std::filesystem::create_directories(outdir);  // only once the input folder was read
  // observe() per pair, wall ms, after one warm-up pair (the first call decodes dlib's detector
  // and reads the network's weights): what a station's refit from real photos spends in vision.
  std::vector<double> observe_ms;
  bool warm = false;
  for (const auto& p : people) {
    const std::string f = dir + "/" + p + "/Img_33.JPG", s = dir + "/" + p + "/Img_53.JPG";
    if (!std::filesystem::exists(f) || !std::filesystem::exists(s)) continue;
    ++total;
    json r = {{"subject", p}};
    try {
      const cv::Mat front = ov::read_image(f), side = ov::read_image(s);
      if (!warm) {
        ov::observe(front, side);
        warm = true;
      }
      const auto t0 = std::chrono::steady_clock::now();
      const ov::FaceObservation obs = ov::observe(front, side);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      observe_ms.push_back(ms);
      r["observe_ms"] = ms;
      std::string missing;
      const bool ok = ov::is_complete(obs, &missing);
      complete += ok;
      r["complete"] = ok;
      r["missing"] = missing;
      r["side_faces_left"] = obs.side_faces_left;
      r["warnings"] = obs.warnings;
      cv::imwrite(outdir + "/" + p + ".png", ov::overlay_pair(front, side, obs));
      cv::imwrite(outdir + "/" + p + "_points.png", points_only(front, obs));
    } catch (const std::exception& e) {
      r["complete"] = false;
      r["error"] = e.what();
    }
    res.push_back(r);
  }
  json out = {{"pairs", total}, {"complete", complete}, {"results", res}};
  if (!observe_ms.empty()) {
    std::sort(observe_ms.begin(), observe_ms.end());
    out["observe_ms"] = {{"median", observe_ms[observe_ms.size() / 2]},
                         {"min", observe_ms.front()},
                         {"max", observe_ms.back()}};
    std::fprintf(stderr, "observe() on %zu real pairs: median %.1f ms (min %.1f, max %.1f)\n",
                 observe_ms.size(), observe_ms[observe_ms.size() / 2], observe_ms.front(),
                 observe_ms.back());
  }
  std::cout << out.dump(1) << "\n";
  return 0;
}

std::vector<cv::Point2d> read_pts(const std::string& path) {
  std::ifstream f(path);
  std::string line;
  std::vector<cv::Point2d> p;
  bool in = false;
  while (std::getline(f, line)) {
    if (line.find('{') != std::string::npos) {
      in = true;
      continue;
    }
    if (line.find('}') != std::string::npos) break;
    double x, y;
    if (in && std::sscanf(line.c_str(), "%lf %lf", &x, &y) == 2)
      p.emplace_back(x - 1 + 0.5, y - 1 + 0.5);
  }
  return p;
}

cv::Point2d mean_of(const std::vector<cv::Point2d>& p, int a, int b) {
  cv::Point2d m(0, 0);
  for (int i = a; i <= b; ++i) m += p[i];
  return m / double(b - a + 1);
}

// The iBUG photos have no side view: observe_front() alone (midline rows from the position
// model), scoring the front filters.
int ibug(const std::string& dir) {
  json res = json::array();
  for (const std::string name : {"image_0010", "einstein"}) {
    const std::string img = dir + "/" + name + (name == "einstein" ? ".jpg" : ".png");
    const auto pts = read_pts(dir + "/" + name + ".pts");
    if (pts.size() != 68) continue;
    json r = {{"image", name}};
    try {
      const cv::Mat im = ov::read_image(img);
      const ov::FaceObservation obs = ov::observe_front(im);
      const cv::Point2d er = mean_of(pts, 36, 41),
                        el = mean_of(pts, 42, 47);  // image-left, image-right
      const double iod = cv::norm(el - er);
      const auto err = [&](const char* n, cv::Point2d t) {
        const auto it = obs.front.features.find(n);
        return it == obs.front.features.end() ? -1.0 : cv::norm(it->second.px - t) / iod;
      };
      r["eye_right_center"] = err("eye_right_center", er);
      r["eye_left_center"] = err("eye_left_center", el);
      r["nose_tip"] = err("nose_tip", pts[30]);
      const auto ml = obs.front.features.find("mouth_left"),
                 mr = obs.front.features.find("mouth_right");
      r["mouth_centre"] =
          (ml == obs.front.features.end() || mr == obs.front.features.end())
              ? -1.0
              : cv::norm((ml->second.px + mr->second.px) / 2 - mean_of(pts, 48, 67)) / iod;
      r["inter_ocular_px"] = iod;
      r["warnings"] = obs.warnings;
      cv::imwrite("/tmp/vision_ibug_" + name + ".png", ov::overlay_front(im, obs));
    } catch (const std::exception& e) {
      r["error"] = e.what();
    }
    res.push_back(r);
  }
  std::cout << res.dump(1) << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (const char* t = std::getenv("VISION_THREADS")) cv::setNumThreads(std::atoi(t));
  const std::string mode = argc > 1 ? argv[1] : "speed";
  try {
    if (mode == "speed") return speed(argc > 2 ? std::stoi(argv[2]) : 50);
    if (mode == "stages") return stages(argc > 2 ? std::stoi(argv[2]) : 30);
    if (mode == "sim")
      return accuracy(argc > 2 ? std::stoi(argv[2]) : 20,
                      ov::parse_front_landmarker(argc > 3 ? argv[3] : "filters"));
    if (mode == "simshow" && argc > 3)
      return simshow(std::stoi(argv[2]), argv[3], argc > 4 ? argv[4] : "ideal");
    if (mode == "frmdb" && argc > 3) return frmdb(argv[2], argv[3]);
    if (mode == "ibug" && argc > 2) return ibug(argv[2]);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  std::cerr << "usage: vision_bench speed [reps] | stages [reps] | sim [subjects] "
               "[filters|network|consensus] | simshow SEED OUT [COND] | frmdb DIR OUT | ibug DIR\n";
  return 2;
}
