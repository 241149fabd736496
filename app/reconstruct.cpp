// orthoface reconstruct: front + side photos -> adapted, textured face mesh and its report.
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "reconstruct/reconstruction.h"
#include "vision/image_prep.h"
#include "vision/pts_io.h"

namespace orthoface::app {
namespace {

Command reconstruct_command() {
  return {"reconstruct",
          "Reconstruct a textured 3D face from a front and a side photo (seed 004 + NNWA, seed "
          "002) and write head.obj/.mtl/.png, the photos, rig.yaml, landmarks.json, "
          "observation.json and report.json. Without --rig the scale is estimated from an "
          "average head and report.json says so.",
          "orthoface reconstruct --front F --side S --out DIR [options]",
          {{"front", true, "F  front photo"},
           {"side", true, "S  side photo (profile)"},
           {"out", true, "DIR  output folder (created; files of the same name are replaced)"},
           {"rig", true,
            "rig.yaml  calibrated or simulated rig (true scale): ours, or an OpenCV stereo "
            "calibration file (K1 D1 K2 D2 R T, image size; docs/formats.md)"},
           {"front-landmarks", true,
            "F.pts  iBUG 68-point landmarks of the front photo (dlib, OpenFace; "
            "docs/formats.md): they replace the detected features, -1 -1 points are left to "
            "detection"},
           {"side-camera", true, "left|right  where the side camera stood (default: detect)"},
           {"landmarker", true,
            "filters|network|consensus  the front features' detector: the seed's "
            "filters placed by the profile's rows, a trained 68-point network "
            "(MIT weights, vision/models), or both (default: the filters' points "
            "the network confirms, else the network's; the profile's midline)"},
           {"method", true, "nnwa|interpolate  how free vertices move (default interpolate)"},
           {"k", true, "K  NNWA neighbours, 1..landmark count (default 5)"},
           {"head-turn", true,
            "DEG  a head turned away from the side camera by at least DEG degrees in the front "
            "photo is modelled facing front and turned back (default 5; -1 never; "
            "report.json head_yaw_deg, head_turn_corrected)"},
           {"turn-toward-side", false,
            "turn back a head turned toward the side camera too: right when the two photos were "
            "taken at once (a station; sim heads 1.01 -> 0.79 %); worse on FRMDB's real pairs, "
            "whose person seems to move between the shots (docs/views_accuracy.md)"},
           front_background_flag(),
           side_background_flag(),
           {"check-identity", false,
            "also refuse a side photo of someone else: the front photo's face against the "
            "model's views at 45-65 degrees (face recognition; about 0.9 s more; its weights: "
            "scripts/fetch-face-model.sh; docs/input_check.md)"},
           {"force", false,
            "model the pair even when the input check fails (the failures go to report.json's "
            "warnings); without it a failed check exits 3 (docs/input_check.md)"}},
          0};
}

cv::Mat read_photo(const std::string& path, const std::string& flag) {
  require_file(path, flag);
  try {
    return vision::read_image(path);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(flag + ": " + e.what());
  }
}

reconstruct::ReconstructOptions options_from(const Args& a) {
  reconstruct::ReconstructOptions o;
  if (a.has("rig")) {
    require_file(a.get("rig"), "--rig");
    o.rig = capture::read_rig(a.get("rig"));
  }
  try {
    o.observe.side_camera = vision::parse_side_camera(a.get("side-camera", "auto"));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--side-camera: ") + e.what());
  }
  try {
    o.observe.landmarker = vision::parse_front_landmarker(a.get("landmarker", "consensus"));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--landmarker: ") + e.what());
  }
  const std::string method = a.get("method", "interpolate");
  if (method != "nnwa" && method != "interpolate")
    throw std::invalid_argument("--method: expected nnwa or interpolate, got '" + method + "'");
  o.adapt.method = method == "nnwa" ? model::AdaptMethod::Nnwa : model::AdaptMethod::Interpolate;
  if (a.has("k")) o.adapt.k = to_int("k", a.get("k"), 1, 100000);
  if (a.has("head-turn")) o.min_head_turn_deg = to_double("head-turn", a.get("head-turn"), -1, 90);
  o.turn_toward_side = a.has("turn-toward-side");
  o.force = a.has("force");
  o.check_identity = a.has("check-identity");
  read_clean_plates(a, o.observe);
  o.check();
  return o;
}

// The named front landmarks of a .pts file that must fit the front photo.
std::map<std::string, cv::Point2d> front_landmarks(const std::string& path, const cv::Mat& front) {
  require_file(path, "--front-landmarks");
  const vision::Ibug68 pts = vision::read_pts(path);
  vision::check_pts_in_image(pts, front.cols, front.rows,
                             "--front-landmarks " + path + " (front photo)");
  return vision::named_from_ibug68(pts);
}

// "front 'F', side 'S' (clean plates 'P'): ", the files a failure of the pair is about.
std::string pair_names(const Args& a) {
  std::string s = "front '" + a.get("front") + "', side '" + a.get("side") + "'";
  std::string plates;
  for (const char* flag : {"front-background", "side-background"})
    if (a.has(flag)) plates += (plates.empty() ? "'" : ", '") + a.get(flag) + "'";
  return s + (plates.empty() ? "" : " (clean plates " + plates + ")") + ": ";
}

}  // namespace

int run_reconstruct(int argc, char** argv) {
  const Command command = reconstruct_command();
  const Args args = parse_args(command, argc, argv);
  if (args.help) {
    print_help(command);
    return 0;
  }
  for (const char* flag : {"front", "side", "out"})
    if (!args.has(flag))
      throw std::invalid_argument(std::string("reconstruct: --") + flag + " is required");
  reconstruct::ReconstructOptions options = options_from(args);
  const std::string out = args.get("out");
  if (std::filesystem::exists(out) && !std::filesystem::is_directory(out))
    throw std::runtime_error("output folder " + out + ": exists and is not a folder");
  const cv::Mat front = read_photo(args.get("front"), "--front");
  const cv::Mat side = read_photo(args.get("side"), "--side");
  if (args.has("front-landmarks"))
    options.observe.front_landmarks = front_landmarks(args.get("front-landmarks"), front);
  reconstruct::Reconstruction r;
  try {  // the library speaks of "the front photo": say which files the pair was
    r = reconstruct::from_photos(front, side, options);
  } catch (const reconstruct::InputRefused& e) {
    throw reconstruct::InputRefused(e.check(), pair_names(args) + e.problem());
  } catch (const std::exception& e) {
    throw std::runtime_error(pair_names(args) + e.what());
  }
  reconstruct::write_reconstruction(r, out);
  double total = 0;
  for (const auto& [stage, ms] : r.report.stage_ms) total += ms;
  std::printf(
      "reconstruct: %s + %s -> %s (%zu vertices, %zu features, %zu warnings) in %.0f ms%s\n",
      args.get("front").c_str(), args.get("side").c_str(), out.c_str(), r.mesh.vertices.size(),
      r.report.features_found.size(), r.report.warnings.size(), total,
      options.rig ? "" : "; scale estimated (no --rig)");
  if (args.has("front-landmarks"))
    std::printf("  front landmarks: %zu given by %s replace detection\n",
                options.observe.front_landmarks.size(), args.get("front-landmarks").c_str());
  return 0;
}

}  // namespace orthoface::app
