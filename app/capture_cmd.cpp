// orthoface capture: one synchronized pair from two cameras, saved before anything else
// happens, then reconstructed.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "app/cli.h"
#include "app/commands.h"
#include "app/station_output.h"
#include "capture/pair_capture.h"
#include "reconstruct/reconstruction.h"
#include "sim/sim_camera.h"

namespace orthoface::app {
namespace {

Command capture_command() {
  return {"capture",
          "Take one synchronized front + side pair (nearest timestamps), save it to OUT/pair/ "
          "(front.png, side.png, pair.json), then reconstruct it into OUT/model/.",
          "orthoface capture --front DEV --side DEV --out DIR [options]",
          {{"front", true,
            "DEV  front camera: /dev/videoN, libcamera:ID, sim:N/front or file:VIDEO[?loop&fps=N]"},
           {"side", true, "DEV  side camera"},
           {"out", true, "DIR  output folder"},
           {"size", true, "WxH  capture size (default 640x480)"},
           {"fps", true, "N  frame rate (default 30)"},
           {"rig", true, "rig.yaml  calibrated rig (sim: cameras use the simulated rig)"},
           {"timeout", true, "S  how long to wait for a pair (default 5)"},
           {"no-reconstruct", false, "only save the pair"},
           front_background_flag(),
           side_background_flag(),
           {"force", false, "model the pair even when the input check fails (exit 3 without)"}},
          0};
}

// " (clean plates 'P')" when plates were given: a modelling failure may come from them.
std::string plates_used(const Args& a) {
  std::string plates;
  for (const char* flag : {"front-background", "side-background"})
    if (a.has(flag)) plates += (plates.empty() ? "'" : ", '") + a.get(flag) + "'";
  return plates.empty() ? "" : " (clean plates " + plates + ")";
}

}  // namespace

int run_capture(int argc, char** argv) {
  const Command command = capture_command();
  const Args a = parse_args(command, argc, argv);
  if (a.help) {
    print_help(command);
    return 0;
  }
  for (const char* flag : {"front", "side", "out"})
    if (!a.has(flag))
      throw std::invalid_argument(std::string("capture: --") + flag + " is required");
  if (capture::same_device(a.get("front"), a.get("side")))
    throw std::invalid_argument("capture: --front and --side are the same device (" +
                                a.get("front") + ")");
  capture::PairCaptureOptions o;
  if (a.has("size")) std::tie(o.width, o.height) = to_size("size", a.get("size"), 8192);
  if (a.has("fps")) o.fps = to_double("fps", a.get("fps"), 1, 240);
  const double timeout = a.has("timeout") ? to_double("timeout", a.get("timeout"), 0.1, 600) : 5.0;
  if (a.has("rig")) require_file(a.get("rig"), "--rig");
  // The rig is read (and refused) before anything is captured or written.
  const std::optional<capture::RigCalibration> rig =
      station_rig(a.get("rig"), a.get("front"), a.get("side"), o.width, o.height);
  vision::ObserveOptions plates;  // read before anything is captured
  read_clean_plates(a, plates, o.width, o.height);
  const std::string out = a.get("out");
  const bool out_existed = std::filesystem::exists(out);
  prepare_output_dir(out);
  const std::string pair_dir = out + "/pair";
  if (std::filesystem::exists(pair_dir))
    throw std::runtime_error("capture: " + pair_dir + " already exists (choose a new --out)");
  sim::register_sim_cameras();
  std::optional<capture::FramePair> pair;
  try {
    capture::PairCapture pc(a.get("front"), a.get("side"), o);
    pair = pc.take_pair(timeout);
    if (!pair)
      throw std::runtime_error("capture: no synchronized pair within " + std::to_string(timeout) +
                               " s");
  } catch (...) {
    // Nothing was captured: a folder made for it goes again (remove() leaves a non-empty one).
    std::error_code ec;
    if (!out_existed) std::filesystem::remove(out, ec);
    throw;
  }
  save_pair(*pair, pair_dir);
  std::printf("pair saved: %s (skew %.1f ms)\n", pair_dir.c_str(), pair->skew_s * 1e3);
  if (a.has("no-reconstruct")) return 0;
  reconstruct::ReconstructOptions ro;
  ro.force = a.has("force");
  ro.observe = plates;
  ro.rig = rig;
  try {
    const reconstruct::Reconstruction r =
        reconstruct::from_photos(pair->front.image, pair->side.image, ro);
    reconstruct::write_reconstruction(r, out + "/model");
  } catch (const reconstruct::InputRefused& e) {
    throw reconstruct::InputRefused(
        e.check(), e.problem() + plates_used(a) + "; the captured pair is kept in " + pair_dir);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string(e.what()) + plates_used(a) +
                             " (the captured pair is kept in " + pair_dir + ")");
  }
  std::printf("model written: %s/model\n", out.c_str());
  return 0;
}

}  // namespace orthoface::app
