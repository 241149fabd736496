// orthoface devices: the cameras this machine offers (V4L2, libcamera, simulated) and their modes.
#include <cstdio>
#include <map>
#include <string>

#include "app/cli.h"
#include "app/commands.h"
#include "capture/camera.h"
#include "sim/sim_camera.h"

namespace orthoface::app {

int run_devices(int argc, char** argv) {
  const Command command{"devices",
                        "List the cameras (V4L2 /dev/video*, libcamera, sim:N) and their modes.",
                        "orthoface devices",
                        {},
                        0};
  const Args args = parse_args(command, argc, argv);
  if (args.help) {
    print_help(command);
    return 0;
  }
  sim::register_sim_cameras();
  const auto devices = capture::list_devices();
  for (const capture::DeviceInfo& d : devices) {
    std::printf("%s  (%s)\n", d.id.c_str(), d.label.c_str());
    // One line per fourcc and size, the frame rates together.
    std::map<std::string, std::string> modes;
    for (const capture::CameraFormat& f : d.formats) {
      const std::string key =
          f.fourcc + " " + std::to_string(f.width) + "x" + std::to_string(f.height);
      char fps[32];
      std::snprintf(fps, sizeof(fps), "%s%g", modes[key].empty() ? "" : "/", f.fps);
      modes[key] += fps;
    }
    for (const auto& [mode, rates] : modes)
      std::printf("    %s @ %s fps\n", mode.c_str(), rates.c_str());
  }
  std::printf(
      "%zu camera(s)%s\n", devices.size(),
      devices.size() <= 2 ? "; no V4L2 or libcamera camera found besides the simulated rig" : "");
  return 0;
}

}  // namespace orthoface::app
