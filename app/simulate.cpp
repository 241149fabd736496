// orthoface simulate: render a ground-truth head through the simulated two-camera rig and write
// the photos, the true mesh, the landmarks and the rig file.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <opencv2/core.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "app/sim_args.h"
#include "io/image_file.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "sim/sim_folder.h"

namespace orthoface::app {
namespace {

Command simulate_command() {
  return {
      "simulate",
      "Render a simulated head (or the Lee Perry-Smith scan) from the front and side cameras "
      "and write front.png side.png (+ _mask.png) truth.obj (+ .mtl, .png) landmarks.json "
      "rig.yaml background.png background_side.png. rig.yaml holds the NOMINAL rig a station would "
      "believe; landmarks.json holds the true cameras too.",
      "orthoface simulate --subject N --out DIR [options]",
      {{"subject", true, "N  head seed, 0..1000000 (not with --scan)"},
       {"scan", true, "NAME  a real scan instead: lee-perry-smith"},
       {"data", true, "DIR  data folder holding the scans (default: the build's ../shared/data)"},
       {"out", true, "DIR  output folder (created; files in it are replaced)"},
       {"rig", true, "KIND  ideal (orthographic, seed 004) or perspective (default ideal)"},
       {"size", true, "WxH  image size, each side 1..8192 (default 640x480)"},
       {"px-per-mm", true, "S  ideal rig scale (default 1.6)"},
       {"focal", true, "PX  perspective focal length in pixels (default 1600)"},
       {"distance", true, "MM  perspective camera distance (default 1000)"},
       {"noise", true, "SIGMA  sensor noise, grey levels (default 0)"},
       {"blur", true, "SIGMA  optical blur, pixels (default 0)"},
       {"background", true,
        "KIND  plain, cluttered (a drawn room) or photo:FILE (each camera sees its own part of "
        "a scene photograph; default plain)"},
       {"light", true,
        "A,D[,X,Y,Z]  ambient, diffuse and light travel direction (default 0.6,0.5)"},
       {"misalign", true, "DEG[,MM]  random true-camera pose errors up to DEG degrees / MM mm"},
       {"seed", true, "N  noise / clutter / misalignment seed (default: the subject)"},
       {"mouth", true, "MM  the mouth open: the chin lowered MM mm, 0..20 (default 0)"}},
      0};
}

// Comma-separated numbers, each checked like --flag values.
std::vector<double> to_list(const std::string& flag, const std::string& text, double lo,
                            double hi) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(to_double(flag, item, lo, hi));
  if (text.empty() || text.back() == ',')
    throw std::invalid_argument("--" + flag + ": expected comma-separated numbers, got '" + text +
                                "'");
  return out;
}

sim::RigOptions rig_options(const Args& a, int default_seed) {
  sim::RigOptions o;
  const std::string kind = a.get("rig", "ideal");
  if (kind != "ideal" && kind != "perspective")
    throw std::invalid_argument("--rig: expected ideal or perspective, got '" + kind + "'");
  o.kind = kind == "ideal" ? sim::RigKind::Ideal : sim::RigKind::Perspective;
  if (a.has("size")) std::tie(o.width, o.height) = to_size("size", a.get("size"), 8192);
  if (a.has("px-per-mm")) o.px_per_mm = to_double("px-per-mm", a.get("px-per-mm"), 0.01, 1000);
  if (a.has("focal")) o.focal_px = to_double("focal", a.get("focal"), 1, 1e6);
  if (a.has("distance")) o.distance_mm = to_double("distance", a.get("distance"), 200, 1e5);
  if (a.has("noise")) o.noise_sigma = to_double("noise", a.get("noise"), 0, 100);
  if (a.has("blur")) o.blur_sigma = to_double("blur", a.get("blur"), 0, 50);
  const std::string bg = a.get("background", "plain");
  if (bg.rfind("photo:", 0) == 0) {
    o.background = sim::BackgroundKind::Photo;
    o.background_photo = bg.substr(6);
    if (!io::accepted_image_file(o.background_photo))
      throw std::invalid_argument("--background: '" + o.background_photo +
                                  "' is not a readable image (" + io::kAcceptedImageTypes + ")");
  } else if (bg == "plain" || bg == "cluttered") {
    o.background = bg == "plain" ? sim::BackgroundKind::Plain : sim::BackgroundKind::Cluttered;
  } else {
    throw std::invalid_argument("--background: expected plain, cluttered or photo:FILE, got '" +
                                bg + "'");
  }
  o.seed = a.has("seed") ? to_int("seed", a.get("seed"), 0, 1000000000) : default_seed;
  if (a.has("light")) {
    const std::vector<double> l = to_list("light", a.get("light"), -1e3, 1e3);
    if (l.size() != 2 && l.size() != 5)
      throw std::invalid_argument("--light: expected A,D or A,D,X,Y,Z, got '" + a.get("light") +
                                  "'");
    o.ambient = l[0];
    o.diffuse = l[1];
    if (l.size() == 5) o.light_direction = Eigen::Vector3d(l[2], l[3], l[4]);
  }
  if (a.has("misalign")) {
    const std::vector<double> m = to_list("misalign", a.get("misalign"), 0, 100);
    if (m.size() > 2 || m[0] > 15)
      throw std::invalid_argument("--misalign: expected DEG[,MM] with DEG <= 15, got '" +
                                  a.get("misalign") + "'");
    cv::RNG rng(o.seed * 31u + 7u);
    auto draw = [&](double r) { return r > 0 ? rng.uniform(-r, r) : 0.0; };
    for (sim::PoseError* e : {&o.front_error, &o.side_error}) {
      e->roll_deg = draw(m[0]), e->yaw_deg = draw(m[0]), e->pitch_deg = draw(m[0]);
      const double mm = m.size() > 1 ? m[1] : 0.0;
      e->offset_mm = Eigen::Vector3d(draw(mm), draw(mm), draw(mm));
    }
  }
  try {
    o.check();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("simulate: ") + e.what());
  }
  return o;
}

}  // namespace

int run_simulate(int argc, char** argv) {
  const Command command = simulate_command();
  const Args args = parse_args(command, argc, argv);
  if (args.help) {
    print_help(command);
    return 0;
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (!args.has("out")) throw std::invalid_argument("simulate: --out DIR is required");
  if (args.has("subject") == args.has("scan"))
    throw std::invalid_argument("simulate: give exactly one of --subject N and --scan NAME");
  const int subject = args.has("subject") ? to_int("subject", args.get("subject"), 0, 1000000) : 0;
  const sim::RigOptions options = rig_options(args, subject);
  const std::string out = args.get("out");
  if (std::filesystem::exists(out) && !std::filesystem::is_directory(out))
    throw std::runtime_error("output folder " + out + ": exists and is not a folder");
  sim::Head head = args.has("scan") ? load_scan(args.get("scan"), data_dir(args.get("data")))
                                    : sim::make_head(subject);
  if (args.has("mouth"))
    head = sim::open_mouth(head, to_double("mouth", args.get("mouth"), 0, sim::kMaxMouthOpenMm));
  const sim::Capture cap = sim::simulate_capture(head, options);
  prepare_output_dir(out);
  sim::write_simulation(out, head, cap, options);
  int vis_front = 0, vis_side = 0;
  for (const auto& [name, t] : cap.landmarks)
    vis_front += t.visible_front, vis_side += t.visible_side;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "simulate: %s -> %s (%s rig %dx%d, %zu landmarks, %d visible front, %d side) in %.2f s\n",
      head.name.c_str(), out.c_str(), args.get("rig", "ideal").c_str(), options.width,
      options.height, cap.landmarks.size(), vis_front, vis_side, s);
  return 0;
}

}  // namespace orthoface::app
