// orthoface detect: front + side photos -> observation.json and overlay PNGs (vision layer).
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "io/atomic_file.h"
#include "vision/face_detect.h"
#include "vision/image_prep.h"
#include "vision/observation_io.h"
#include "vision/observe.h"
#include "vision/overlay.h"
#include "vision/pair_check.h"
#include "vision/pts_io.h"

namespace orthoface::app {

namespace {

const Command kDetect{
    "detect",
    "Find the face silhouette, side profile, centre line and facial features (seed 004 §4).",
    "orthoface detect --front F --side S --out DIR [options]",
    {{"front", true, "F  front photo (any size; grey / 16-bit / RGBA are converted)"},
     {"side", true, "S  side photo, 90 deg from the front, same height"},
     {"out", true, "DIR  output folder: observation.json, overlay_front.png, overlay_side.png"},
     {"background-front", true, "F  empty-scene frame of the front camera (background difference)"},
     {"background-side", true, "F  empty-scene frame of the side camera"},
     {"side-camera", true,
      "left|right  where the side camera stands (default: decided from the image)"},
     {"landmarker", true,
      "filters|network|consensus  the front features' detector: the seed's "
      "filters placed by the profile's rows, a trained 68-point network "
      "(MIT weights, vision/models), or both (default: the filters' points "
      "the network confirms, else the network's; the profile's midline)"},
     {"haar", false, "also run OpenCV Haar cascades (opencv-data) to check / fill the eyes"},
     {"pts", true,
      "F.pts  also write the front landmarks as iBUG 68 points (docs/formats.md): all 68 when "
      "the trained network found the face, else the found features that are iBUG points, the "
      "rest -1 -1 (missing)"}},
    0};

// The front landmarks in the iBUG layout: the trained network's 68 points when it found the
// face, else the detected features (confidence > 0: not position-model guesses) that are iBUG
// points.
vision::Ibug68 front_pts(const vision::FaceObservation& obs) {
  vision::Ibug68 pts;
  if (obs.front_points68.size() == pts.size()) {
    std::copy(obs.front_points68.begin(), obs.front_points68.end(), pts.begin());
    return pts;
  }
  std::map<std::string, vision::Feature2d> found;
  for (const auto& [name, f] : obs.front.features)
    if (f.confidence > 0) found[name] = f;
  return vision::ibug68_from_named(found);
}

}  // namespace

int run_detect(int argc, char** argv) {
  const Args args = parse_args(kDetect, argc, argv);
  if (args.help) {
    print_help(kDetect);
    return 0;
  }
  for (const char* f : {"front", "side", "out"})
    if (!args.has(f)) throw std::invalid_argument(std::string("detect: --") + f + " is required");
  vision::ObserveOptions options;
  try {
    options.side_camera = vision::parse_side_camera(args.get("side-camera", "auto"));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--side-camera: ") + e.what());
  }
  options.use_haar = args.has("haar");
  try {
    options.landmarker = vision::parse_front_landmarker(args.get("landmarker", "consensus"));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--landmarker: ") + e.what());
  }
  const cv::Mat front = vision::read_image(args.get("front"));
  const cv::Mat side = vision::read_image(args.get("side"));
  if (args.has("background-front"))
    options.background_front = vision::read_image(args.get("background-front"));
  if (args.has("background-side"))
    options.background_side = vision::read_image(args.get("background-side"));
  options.check();
  if (args.has("pts")) {  // before the work: a wrong folder should not cost the detection
    namespace fs = std::filesystem;
    const fs::path parent = fs::weakly_canonical(fs::absolute(args.get("pts"))).parent_path();
    const fs::path out_dir = fs::weakly_canonical(fs::absolute(args.get("out")));
    if (!fs::is_directory(parent) && parent != out_dir)
      throw std::runtime_error("--pts " + args.get("pts") + ": folder " + parent.string() +
                               " does not exist");
  }
  const vision::FaceObservation obs = vision::observe(front, side, options);
  // No face in a photo is an error, as in reconstruct and capture, and nothing is written: the
  // front needs a head and a face the detector finds (as reconstruct's input check front_face),
  // the side a head.
  const bool front_faceless = obs.front.boundary.empty() || vision::detect_faces(front).empty();
  std::string faceless;
  for (const auto& [view, empty] :
       {std::pair{"front", front_faceless}, std::pair{"side", obs.side.boundary.empty()}}) {
    if (!empty) continue;
    const std::string plate = std::string("background-") + view;
    faceless += std::string(faceless.empty() ? "" : " nor in ") + "the " + view + " photo '" +
                args.get(view) + "'" +
                (args.has(plate) ? " (clean plate '" + args.get(plate) + "')" : std::string());
  }
  if (!faceless.empty()) throw std::runtime_error("no face found in " + faceless);
  // A side photo whose subject has other colours than the front's is not this head in profile
  // (a skin-coloured blob passes the profile fit): the same check reconstruct refuses it with.
  const vision::PairCheck pair = vision::check_pair(vision::measure_pair(front, side, obs));
  for (const vision::InputCheck& c : pair.checks)
    if (c.name == "same_person_colours" && !c.passed)
      throw std::runtime_error("input check " + c.name + ": front '" + args.get("front") +
                               "', side '" + args.get("side") + "': " + c.problem);
  const std::filesystem::path out = args.get("out");
  io::FileGroup outputs;  // all of them or none (a full disk half-way)
  prepare_output_dir(out.string(), &outputs);
  vision::write_observation(obs, (out / "observation.json").string());
  io::write_image_atomically((out / "overlay_front.png").string(),
                             vision::overlay_front(front, obs));
  io::write_image_atomically((out / "overlay_side.png").string(), vision::overlay_side(side, obs));
  if (args.has("pts")) vision::write_pts(front_pts(obs), args.get("pts"));
  outputs.commit();
  std::string missing;
  const bool complete = vision::is_complete(obs, &missing);
  std::cout << "detect: front boundary " << obs.front.boundary.size() << " points, side profile "
            << obs.side.boundary.size() << " points, " << obs.front.features.size() << " + "
            << obs.side.features.size() << " features, " << obs.warnings.size() << " warnings -> "
            << (out / "observation.json").string()
            << (args.has("pts") ? " and " + args.get("pts") : std::string()) << "\n";
  for (const auto& w : obs.warnings) std::cout << "  warning: " << w << "\n";
  if (!complete) std::cout << "  incomplete: " << missing << "\n";
  return 0;
}

}  // namespace orthoface::app
