// Feeds the fake V4L2 device with the simulated rig: renders sim:N/front and sim:N/side and
// writes their frames into the frame files the fake serves (ORTHOFACE_FAKE_V4L2=path=file).
// Usage: fake_v4l2_feed SUBJECT FRONT_FILE SIDE_FILE SECONDS
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "capture/camera.h"
#include "frame_source.h"
#include "sim/sim_camera.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: fake_v4l2_feed SUBJECT FRONT_FILE SIDE_FILE SECONDS\n");
    return 2;
  }
  orthoface::sim::register_sim_cameras();
  const std::string subject = argv[1];
  const double seconds = std::atof(argv[4]);
  auto feed = [&](const std::string& view, const std::string& file) {
    auto cam = orthoface::capture::open_camera("sim:" + subject + "/" + view);
    cam->start({"BGR3", 640, 480, 30});
    const double end = orthoface::capture::monotonic_now_s() + seconds;
    while (orthoface::capture::monotonic_now_s() < end) {
      auto r = cam->next_frame(1.0);
      if (r.status == orthoface::capture::FrameStatus::Ok)
        fake_v4l2::write_frame_file(file, r.frame.image);
    }
  };
  std::thread a(feed, "front", argv[2]), b(feed, "side", argv[3]);
  a.join();
  b.join();
  return 0;
}
