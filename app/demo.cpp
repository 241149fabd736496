// orthoface demo: simulated heads (and the Lee Perry-Smith scan when the data is present) ->
// front / side photos from the two-camera rig -> true views at 30 / 45 / 60 degrees -> one
// contact sheet. Each stage is one function so later stages (vision, model, new views) slot in.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <algorithm>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "app/sim_args.h"
#include "render/contact_sheet.h"
#include "render/renderer.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "sim/sim_folder.h"

namespace orthoface::app {
namespace {

constexpr int kDemoSeeds[] = {0, 1, 2};
constexpr double kViewYawsDeg[] = {30, 45, 60};

// One subject through the pipeline; each stage fills its part.
struct DemoSubject {
  std::string label;   // "seed 0", "Lee Perry-Smith scan"
  std::string folder;  // output subfolder name
  sim::Head head;
  sim::Capture capture;
  std::vector<render::RenderResult> truth_views;  // one per kViewYawsDeg
};

// Stage timings, seconds.
struct DemoTimes {
  double heads = 0, rig = 0, views = 0, write = 0;
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

// One crop for all of a subject's tiles (same scale in every view): the union of the head
// masks, padded, widened to 4:3 and clipped to the image.
cv::Rect subject_crop(const DemoSubject& s) {
  cv::Rect box = cv::boundingRect(s.capture.front_mask) | cv::boundingRect(s.capture.side_mask);
  for (const auto& v : s.truth_views) box |= cv::boundingRect(v.mask);
  const cv::Rect image(0, 0, s.capture.front.cols, s.capture.front.rows);
  if (box.area() == 0) return image;
  const double pad = 0.06 * std::max(box.width, box.height);
  double w = box.width + 2 * pad, h = box.height + 2 * pad;
  if (w < h * 4 / 3) w = h * 4 / 3;
  else h = w * 3 / 4;
  const cv::Point2d c(box.x + box.width / 2.0, box.y + box.height / 2.0);
  return cv::Rect(cv::Point(int(c.x - w / 2), int(c.y - h / 2)), cv::Size(int(w), int(h))) & image;
}

// Final stage: one row per subject: front, side, then the true views.
cv::Mat sheet_stage(const std::vector<DemoSubject>& subjects) {
  std::vector<render::Tile> tiles;
  for (const DemoSubject& s : subjects) {
    const cv::Rect crop = subject_crop(s);
    tiles.push_back({s.capture.front(crop), s.label + ": front photo"});
    tiles.push_back({s.capture.side(crop), s.label + ": side photo"});
    for (size_t i = 0; i < s.truth_views.size(); ++i)
      tiles.push_back({s.truth_views[i].image(crop),
                       s.label + ": truth yaw " + std::to_string(int(kViewYawsDeg[i]))});
  }
  render::ContactSheetOptions o;
  o.columns = 2 + int(std::size(kViewYawsDeg));
  o.tile_width = 320;
  o.tile_height = 240;
  o.title = "orthoface demo: simulated front / side photos and true views at 30, 45, 60 deg";
  return render::contact_sheet(tiles, o);
}

}  // namespace

int run_demo(int argc, char** argv) {
  const Command command{
      "demo",
      "Simulated heads (seeds 0-2, and the Lee Perry-Smith scan when ../shared/data has it) "
      "through the two-camera rig; writes each subject's simulation folder and contact_sheet.png.",
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
  times.views = seconds_since(t);
  t = std::chrono::steady_clock::now();
  const cv::Mat sheet = sheet_stage(subjects);
  prepare_output_dir(out);
  for (const DemoSubject& s : subjects) {
    const std::string dir = (std::filesystem::path(out) / s.folder).string();
    prepare_output_dir(dir);
    sim::write_simulation(dir, s.head, s.capture, options);
  }
  const std::string sheet_path = (std::filesystem::path(out) / "contact_sheet.png").string();
  render::write_png(sheet, sheet_path);
  times.write = seconds_since(t);
  std::printf("demo: %zu subjects -> %s in %.2f s (heads %.2f s, rig %.2f s, truth views %.2f s, "
              "sheet+write %.2f s)\n",
              subjects.size(), sheet_path.c_str(), seconds_since(t0), times.heads, times.rig,
              times.views, times.write);
  return 0;
}

}  // namespace orthoface::app
