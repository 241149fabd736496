// orthoface calibrate: intrinsics of both cameras and their 90 deg pose from checkerboard views,
// written as the rig.yaml `reconstruct --rig` reads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "app/station_output.h"
#include "capture/calibration.h"
#include "capture/pair_capture.h"
#include "io/image_file.h"
#include "sim/sim_camera.h"

namespace orthoface::app {
namespace {

Command calibrate_command() {
  return {"calibrate",
          "Calibrate the two-camera rig from checkerboard views: pairs of images taken at the same "
          "moment (front/NNN.png with side/NNN.png, by sorted name), or live from two cameras. "
          "Show the board to each camera at several angles, and hold it at about 45 deg so both "
          "see it in some pairs.",
          "orthoface calibrate (--front-images DIR --side-images DIR | --front DEV --side DEV) "
          "--out rig.yaml",
          {{"front-images", true, "DIR  front camera images"},
           {"side-images", true, "DIR  side camera images (same count, same order)"},
           {"front", true, "DEV  live front camera"},
           {"side", true, "DEV  live side camera"},
           {"views", true, "N  live: pairs to take, one every --interval s (default 20)"},
           {"interval", true, "S  live: seconds between pairs (default 1.5)"},
           {"board", true, "CxR  inner corners (default 9x6; C + R odd)"},
           {"square", true, "MM  square side (default 25)"},
           {"out", true, "rig.yaml  output file"},
           {"rig-format", true,
            "orthoface|opencv  the file's form: ours (default) or an OpenCV stereo calibration "
            "(K1 D1 K2 D2 R T, image_size; docs/formats.md); --rig reads both"}},
          0};
}

std::vector<cv::Mat> read_folder(const std::string& dir, const std::string& flag) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(dir)) throw std::runtime_error(flag + " " + dir + ": not a folder");
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") names.push_back(e.path().string());
  }
  std::sort(names.begin(), names.end());
  std::vector<cv::Mat> images;
  for (const std::string& n : names) {
    images.push_back(io::imread_accepted(n, cv::IMREAD_COLOR));
    if (images.back().empty()) throw std::runtime_error(flag + " " + n + ": not a readable image");
  }
  return images;
}

void live_views(const Args& a, std::vector<cv::Mat>& front, std::vector<cv::Mat>& side) {
  sim::register_sim_cameras();
  const int views = a.has("views") ? to_int("views", a.get("views"), 1, 500) : 20;
  const double interval =
      a.has("interval") ? to_double("interval", a.get("interval"), 0.1, 60) : 1.5;
  capture::PairCapture pc(a.get("front"), a.get("side"));
  for (int i = 0; i < views; ++i) {
    std::this_thread::sleep_for(std::chrono::duration<double>(i ? interval : 0.0));
    auto p = pc.take_pair(3.0);
    if (!p) throw std::runtime_error("calibrate: no synchronized pair within 3 s");
    front.push_back(p->front.image);
    side.push_back(p->side.image);
    std::fprintf(stderr, "\rpair %d/%d", i + 1, views);
  }
  std::fprintf(stderr, "\n");
}

}  // namespace

int run_calibrate(int argc, char** argv) {
  const Command command = calibrate_command();
  const Args a = parse_args(command, argc, argv);
  if (a.help) {
    print_help(command);
    return 0;
  }
  if (!a.has("out")) throw std::invalid_argument("calibrate: --out rig.yaml is required");
  const bool files = a.has("front-images") || a.has("side-images");
  const bool live = a.has("front") || a.has("side");
  if (files == live || (files && !(a.has("front-images") && a.has("side-images"))) ||
      (live && !(a.has("front") && a.has("side"))))
    throw std::invalid_argument(
        "calibrate: give --front-images and --side-images, or --front and --side");
  capture::RigFormat format = capture::RigFormat::Orthoface;
  try {
    format = capture::parse_rig_format(a.get("rig-format", "orthoface"));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--rig-format: ") + e.what());
  }
  capture::CalibrationOptions o;
  if (a.has("board")) std::tie(o.board.cols, o.board.rows) = to_size("board", a.get("board"), 64);
  if (a.has("square")) o.board.square_mm = to_double("square", a.get("square"), 0.1, 999);
  o.check();
  std::vector<cv::Mat> front, side;
  if (files) {
    front = read_folder(a.get("front-images"), "--front-images");
    side = read_folder(a.get("side-images"), "--side-images");
  } else {
    if (capture::same_device(a.get("front"), a.get("side")))
      throw std::invalid_argument("calibrate: --front and --side are the same device");
    live_views(a, front, side);
  }
  const capture::RigCalibrationReport r = capture::calibrate_rig(front, side, o);
  capture::write_rig(r.rig, a.get("out"), format);
  std::printf(
      "rig written: %s\nviews: front %d, side %d, both %d\nreprojection rms: front %.3f px, side "
      "%.3f px, "
      "stereo %.3f px\nfocal: front %.1f px, side %.1f px\nbaseline %.1f mm, angle between cameras "
      "%.2f deg\n"
      "predicted translation sd: %.2f %.2f %.2f mm\n",
      a.get("out").c_str(), r.views_front, r.views_side, r.views_shared, r.rms_front_px,
      r.rms_side_px, r.rms_stereo_px, r.rig.front.fx, r.rig.side.fx,
      r.side_from_front.translation().norm(),
      Eigen::AngleAxisd(r.side_from_front.linear()).angle() * 180 / M_PI, r.translation_sd_mm.x(),
      r.translation_sd_mm.y(), r.translation_sd_mm.z());
  for (const std::string& w : r.warnings) std::printf("warning: %s\n", w.c_str());
  return 0;
}

}  // namespace orthoface::app
