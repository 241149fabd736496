// Reconstructs a simulated head from its front and side photos with the installed orthoface
// libraries, writes the reconstruction folder and renders one turned view into it.
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

#include <orthoface/reconstruct/reconstruction.h>
#include <orthoface/reconstruct/views.h>
#include <orthoface/sim/head.h>
#include <orthoface/sim/rig.h>
#include <opencv2/imgcodecs.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: orthoface_consumer OUT_DIR\n");
    return 2;
  }
  try {
    namespace of = orthoface;
    // Subject 3 of the simulated population on the ideal orthographic rig.
    const of::sim::Head head = of::sim::make_head(3);
    const of::sim::RigOptions rig;
    const of::sim::Capture shot = of::sim::simulate_capture(head, rig);

    of::reconstruct::ReconstructOptions options;
    options.rig = shot.nominal_rig;
    const of::reconstruct::Reconstruction r =
        of::reconstruct::from_photos(shot.front, shot.side, options);
    of::reconstruct::write_reconstruction(r, argv[1]);

    // Turned 30 degrees toward the subject's left, composited into the front photo's scene.
    const cv::Mat view = of::reconstruct::view_image(r, {}, 30.0, 0.0);
    const std::string view_path = std::string(argv[1]) + "/view_yaw30.png";
    if (!cv::imwrite(view_path, view)) throw std::runtime_error("cannot write " + view_path);
    std::printf("reconstructed %zu vertices, %zu landmarks; wrote %s and %s\n",
                r.mesh.vertices.size(), r.landmarks.size(), argv[1], view_path.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
