// orthoface: front + side photos -> textured 3D face model -> views from any angle.
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <string>

#include <opencv2/core/utils/logger.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "reconstruct/reconstruction.h"

namespace {

struct Entry {
  const char* name;
  int (*run)(int, char**);
  const char* summary;
};

constexpr Entry kCommands[] = {
    {"version", orthoface::app::run_version, "print the version and the libraries in use"},
    {"demo", orthoface::app::run_demo,
     "simulated heads through the rig, true views, contact sheet"},
    {"detect", orthoface::app::run_detect,
     "find silhouette, profile and facial features in a front + side pair"},
    {"simulate", orthoface::app::run_simulate,
     "render a simulated head through the two-camera rig, with its truth"},
    {"reconstruct", orthoface::app::run_reconstruct,
     "front + side photos -> textured 3D face (mesh, landmarks, report)"},
    {"eval", orthoface::app::run_eval,
     "compare a reconstruction with a ground truth (relative error, landmarks)"},
    {"render", orthoface::app::run_render,
     "new views of a reconstruction folder at any yaw / pitch (texture inheritance)"},
    {"devices", orthoface::app::run_devices,
     "list cameras (V4L2, libcamera, simulated) and their modes"},
    {"capture", orthoface::app::run_capture,
     "take one synchronized front + side pair, save it, reconstruct it"},
    {"enrol", orthoface::app::run_enrol,
     "one webcam: look at it, turn to a side; the best frontal + profile frames -> a model"},
    {"calibrate", orthoface::app::run_calibrate,
     "calibrate the two-camera rig from checkerboard views -> rig.yaml"},
    {"station", orthoface::app::run_station,
     "live station (two cameras, or one and an enrolled model) with the rotated view"},
    {"features", orthoface::app::run_features,
     "MPEG-4 feature points, ears, nose tip, axes of a head mesh (seed 000)"},
    {"segment", orthoface::app::run_segment,
     "weight-motion areas around feature points (seed 001)"},
    {"similarity", orthoface::app::run_similarity,
     "face similarity from geodesic network + curvatures (seed 003)"},
};

void print_usage() {
  std::cout << "usage: orthoface <command> [options]   (orthoface <command> --help for details)\n\n"
               "commands:\n";
  for (const Entry& e : kCommands) std::printf("  %-12s %s\n", e.name, e.summary);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    print_usage();
    return argc < 2 ? 1 : 0;
  }
  // OpenCV's own warnings (a decoder's "[ WARN ...]") would be lines beside our one error line.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  for (const Entry& e : kCommands) {
    if (std::strcmp(argv[1], e.name) != 0) continue;
    try {
      return e.run(argc, argv);
    } catch (const orthoface::reconstruct::InputRefused& ex) {  // a wrong pair: exit 3 (README)
      std::cerr << "error: " << orthoface::app::one_line(ex.what()) << "\n";
      return orthoface::reconstruct::kExitInputRefused;
    } catch (const std::exception& ex) {
      std::cerr << "error: " << orthoface::app::one_line(ex.what()) << "\n";
      return 1;
    }
  }
  std::cerr << "error: unknown command '" << argv[1] << "' (orthoface --help lists them)\n";
  return 2;
}
