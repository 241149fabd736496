// orthoface demo: the whole pipeline on the simulated rig. Simulated heads (and the Lee
// Perry-Smith scan when the data is present) -> front / side photos -> vision -> adapted model
// -> new views at 0..90 degrees by texture inheritance, each scored against the true view ->
// one contact sheet and a summary. Each stage is one function.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "app/sim_args.h"
#include "model/evaluate.h"
#include "reconstruct/reconstruction.h"
#include "render/contact_sheet.h"
#include "render/image_metrics.h"
#include "render/new_view.h"
#include "render/renderer.h"
#include "sim/face_mask.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "sim/sim_folder.h"
#include "vision/overlay.h"

namespace orthoface::app {
namespace {

constexpr int kDemoSeeds[] = {0, 1, 2};
constexpr double kViewYawsDeg[] = {0, 15, 30, 45, 60, 75, 90};
constexpr double kHeadlineYawDeg = 45;

// One subject through the pipeline; each stage fills its part.
struct DemoSubject {
  std::string label;   // "seed 0", "Lee Perry-Smith scan"
  std::string folder;  // output subfolder name
  sim::Head head;
  sim::Capture capture;
  std::vector<render::RenderResult> truth_views;     // one per kViewYawsDeg
  std::optional<reconstruct::Reconstruction> model;  // empty when reconstruction failed
  std::string failure;                               // why, when it failed
  std::vector<cv::Mat> views;                        // synthesized, one per kViewYawsDeg
  std::vector<double> psnr_db, ssim;                 // view vs truth inside the face mask
  double relative_error = -1;                        // seed 002 §4.1, -1 when not measured
};

// Stage timings, seconds.
struct DemoTimes {
  double heads = 0, rig = 0, truth = 0, model = 0, synth = 0, write = 0;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Stage 1: the heads. The scan is optional: skipped (with a note) when its data is absent.
std::vector<DemoSubject> make_subjects(const std::string& data) {
  std::vector<DemoSubject> subjects;
  for (int seed : kDemoSeeds) {
    DemoSubject s;
    s.label = "seed " + std::to_string(seed);
    s.folder = "subject_" + std::to_string(seed);
    s.head = sim::make_head(seed);
    subjects.push_back(std::move(s));
  }
  if (std::filesystem::is_directory(std::filesystem::path(data) / "lee_perry_smith_head")) {
    try {
      DemoSubject s;
      s.label = "Lee Perry-Smith scan";
      s.folder = "lee_perry_smith";
      s.head = load_scan("lee-perry-smith", data);
      subjects.push_back(std::move(s));
    } catch (const std::runtime_error& e) {
      std::cerr << "note: scan skipped: " << e.what() << "\n";
    }
  }
  return subjects;
}

// Stage 2: front and side photos through the rig.
void capture_stage(std::vector<DemoSubject>& subjects, const sim::RigOptions& options,
                   render::Renderer& renderer) {
  for (DemoSubject& s : subjects) s.capture = sim::simulate_capture(s.head, options, renderer);
}

// Stage 3: the true views the pipeline's rotated views will be scored against.
void truth_view_stage(std::vector<DemoSubject>& subjects, const sim::RigOptions& options,
                      render::Renderer& renderer) {
  for (DemoSubject& s : subjects)
    for (double yaw : kViewYawsDeg)
      s.truth_views.push_back(sim::true_view(s.head, options, yaw * M_PI / 180, 0, renderer));
}

// Stage 4: vision + model. The rig the station believes (nominal) is what reconstruct gets,
// exactly as `reconstruct --rig rig.yaml` would from the simulate folder.
void model_stage(std::vector<DemoSubject>& subjects) {
  for (DemoSubject& s : subjects) {
    reconstruct::ReconstructOptions o;
    o.rig = s.capture.nominal_rig;
    try {
      s.model = reconstruct::from_photos(s.capture.front, s.capture.side, o);
    } catch (const std::exception& e) {
      s.failure = e.what();
      std::cerr << "warning: " << s.label << ": reconstruction failed: " << e.what() << "\n";
      continue;
    }
    if (!s.head.landmarks.count("forehead_top") || !s.head.landmarks.count("chin_bottom")) continue;
    const model::FaceRegion region = model::face_region(s.head.landmarks);
    s.relative_error = model::reconstruction_error(s.model->mesh, s.head.mesh, region).relative;
  }
}

// Stage 5: new views by texture inheritance, scored inside the true face mask.
void synth_stage(std::vector<DemoSubject>& subjects, const sim::RigOptions& options,
                 render::Renderer& renderer) {
  render::SynthesisOptions so;
  so.background = options.background_bgr;
  so.depth = false;  // the views are scored and written as images
  for (DemoSubject& s : subjects) {
    if (!s.model) continue;
    const auto synth = reconstruct::view_synthesizer(*s.model);
    // The whole head drawn into the front photo's scene, as `render` does (the sim's truth
    // turns about the head frame's origin, so the views do too).
    const reconstruct::ViewScene scene = reconstruct::view_scene(*s.model, *synth);
    for (size_t i = 0; i < std::size(kViewYawsDeg); ++i) {
      const capture::CameraModel camera =
          sim::true_view_camera(options, kViewYawsDeg[i] * M_PI / 180, 0);
      s.views.push_back(scene.composite(synth->render(camera, so).view));
      cv::Mat mask = sim::has_face_landmarks(s.head) ? sim::face_mask(s.head, camera, renderer)
                                                     : s.truth_views[i].mask;
      s.psnr_db.push_back(render::psnr(s.truth_views[i].image, s.views.back(), mask));
      s.ssim.push_back(render::ssim(s.truth_views[i].image, s.views.back(), mask));
    }
  }
}

// One crop for all of a subject's tiles (same scale in every view): the union of the head
// masks, padded, widened to 4:3 and clipped to the image.
cv::Rect subject_crop(const DemoSubject& s) {
  cv::Rect box = cv::boundingRect(s.capture.front_mask) | cv::boundingRect(s.capture.side_mask);
  for (const auto& v : s.truth_views) box |= cv::boundingRect(v.mask);
  const cv::Rect image(0, 0, s.capture.front.cols, s.capture.front.rows);
  if (box.area() == 0) return image;
  const double pad = 0.06 * std::max(box.width, box.height);
  double w = box.width + 2 * pad, h = box.height + 2 * pad;
  if (w < h * 4 / 3)
    w = h * 4 / 3;
  else
    h = w * 3 / 4;
  const cv::Point2d c(box.x + box.width / 2.0, box.y + box.height / 2.0);
  return cv::Rect(cv::Point(int(c.x - w / 2), int(c.y - h / 2)), cv::Size(int(w), int(h))) & image;
}

// Final stage: two rows per subject. Top: the two photos, then the true views; bottom: what
// vision found in each photo, then the synthesized views at the same angles.
cv::Mat sheet_stage(const std::vector<DemoSubject>& subjects) {
  std::vector<render::Tile> tiles;
  char label[160];
  for (const DemoSubject& s : subjects) {
    const cv::Rect crop = subject_crop(s);
    tiles.push_back({s.capture.front(crop), s.label + ": front photo"});
    tiles.push_back({s.capture.side(crop), s.label + ": side photo"});
    for (size_t i = 0; i < s.truth_views.size(); ++i)
      tiles.push_back(
          {s.truth_views[i].image(crop), "truth yaw " + std::to_string(int(kViewYawsDeg[i]))});
    if (s.model) {
      tiles.push_back(
          {vision::overlay_front(s.capture.front, s.model->observation)(crop), "found in front"});
      tiles.push_back(
          {vision::overlay_side(s.capture.side, s.model->observation)(crop), "found in side"});
    } else {
      tiles.push_back({cv::Mat(), "reconstruction failed"});
      tiles.push_back({cv::Mat(), ""});
    }
    for (size_t i = 0; i < std::size(kViewYawsDeg); ++i) {
      if (i < s.views.size()) {
        std::snprintf(label, sizeof label, "yaw %d: %.1f dB, SSIM %.3f", int(kViewYawsDeg[i]),
                      s.psnr_db[i], s.ssim[i]);
        tiles.push_back({s.views[i](crop), label});
      } else {
        tiles.push_back({cv::Mat(), ""});
      }
    }
  }
  render::ContactSheetOptions o;
  o.columns = 2 + int(std::size(kViewYawsDeg));
  o.tile_width = 240;
  o.tile_height = 180;
  o.font_scale = 0.4;
  o.title =
      "orthoface demo: photos and true views (top), found features and synthesized views "
      "(bottom)";
  return render::contact_sheet(tiles, o);
}

size_t headline_index() {
  for (size_t i = 0; i < std::size(kViewYawsDeg); ++i)
    if (kViewYawsDeg[i] == kHeadlineYawDeg) return i;
  return 0;
}

// Per-subject outputs: the simulation folder, the reconstruction folder, the views.
void write_stage(const std::vector<DemoSubject>& subjects, const sim::RigOptions& options,
                 const std::string& out) {
  for (const DemoSubject& s : subjects) {
    const std::filesystem::path dir = std::filesystem::path(out) / s.folder;
    prepare_output_dir((dir / "sim").string());
    sim::write_simulation((dir / "sim").string(), s.head, s.capture, options);
    if (!s.model) continue;
    const std::filesystem::path model_dir = dir / "model";
    std::filesystem::remove_all(model_dir);
    reconstruct::write_reconstruction(*s.model, model_dir.string());
    prepare_output_dir((dir / "views").string());
    for (size_t i = 0; i < s.views.size(); ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "yaw_%02d.png", int(kViewYawsDeg[i]));
      render::write_png(s.views[i], (dir / "views" / name).string());
    }
  }
}

// One line per subject and the mean, in the units the design measures.
void print_summary(const std::vector<DemoSubject>& subjects) {
  const size_t h = headline_index();
  double sum_err = 0, sum_psnr = 0, sum_ssim = 0;
  int n_err = 0, n_view = 0;
  for (const DemoSubject& s : subjects) {
    if (!s.model) {
      std::printf("  %-22s reconstruction failed: %s\n", s.label.c_str(), s.failure.c_str());
      continue;
    }
    std::printf("  %-22s relative error %s   yaw %d: PSNR %.1f dB, SSIM %.3f\n", s.label.c_str(),
                s.relative_error >= 0
                    ? (std::to_string(s.relative_error * 100).substr(0, 4) + " %").c_str()
                    : "n/a   ",
                int(kHeadlineYawDeg), s.psnr_db[h], s.ssim[h]);
    if (s.relative_error >= 0) sum_err += s.relative_error, ++n_err;
    sum_psnr += s.psnr_db[h], sum_ssim += s.ssim[h], ++n_view;
  }
  if (n_view > 0)
    std::printf("  %-22s relative error %.2f %%   yaw %d: PSNR %.1f dB, SSIM %.3f\n", "mean",
                n_err ? 100 * sum_err / n_err : 0.0, int(kHeadlineYawDeg), sum_psnr / n_view,
                sum_ssim / n_view);
}

}  // namespace

int run_demo(int argc, char** argv) {
  const Command command{
      "demo",
      "The whole pipeline on the simulated rig: heads (seeds 0-2, and the Lee Perry-Smith scan "
      "when "
      "../shared/data has it) -> front/side photos -> vision -> model -> new views at 0..90 deg, "
      "scored against the true views; writes per subject sim/, model/, views/ and "
      "contact_sheet.png.",
      "orthoface demo [--out DIR]",
      {{"out", true, "DIR  output folder (default ./orthoface-demo)"},
       {"data", true, "DIR  data folder holding the scans (default: the build's ../shared/data)"}},
      0};
  const Args args = parse_args(command, argc, argv);
  if (args.help) {
    print_help(command);
    return 0;
  }
  const std::string out = args.get("out", "orthoface-demo");
  if (std::filesystem::exists(out) && !std::filesystem::is_directory(out))
    throw std::runtime_error("output folder " + out + ": exists and is not a folder");
  const auto t0 = std::chrono::steady_clock::now();
  DemoTimes times;
  auto t = std::chrono::steady_clock::now();
  std::vector<DemoSubject> subjects = make_subjects(data_dir(args.get("data")));
  times.heads = seconds_since(t);
  render::Renderer renderer;
  const sim::RigOptions options;  // ideal seed 004 rig, 640x480
  t = std::chrono::steady_clock::now();
  capture_stage(subjects, options, renderer);
  times.rig = seconds_since(t);
  t = std::chrono::steady_clock::now();
  truth_view_stage(subjects, options, renderer);
  times.truth = seconds_since(t);
  t = std::chrono::steady_clock::now();
  model_stage(subjects);
  times.model = seconds_since(t);
  t = std::chrono::steady_clock::now();
  synth_stage(subjects, options, renderer);
  times.synth = seconds_since(t);
  t = std::chrono::steady_clock::now();
  const cv::Mat sheet = sheet_stage(subjects);
  prepare_output_dir(out);
  write_stage(subjects, options, out);
  const std::string sheet_path = (std::filesystem::path(out) / "contact_sheet.png").string();
  render::write_png(sheet, sheet_path);
  times.write = seconds_since(t);
  std::printf(
      "demo: %zu subjects -> %s in %.2f s (heads %.2f, rig %.2f, truth views %.2f, "
      "vision+model %.2f, new views %.2f, write %.2f s)\n",
      subjects.size(), sheet_path.c_str(), seconds_since(t0), times.heads, times.rig, times.truth,
      times.model, times.synth, times.write);
  print_summary(subjects);
  for (const DemoSubject& s : subjects)
    if (!s.model) return 1;
  return 0;
}

}  // namespace orthoface::app
