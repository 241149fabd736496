#include <iostream>

#include <Eigen/Core>
#include <opencv2/core/version.hpp>

#include "app/cli.h"
#include "app/commands.h"

namespace orthoface::app {

int run_version(int argc, char** argv) {
  const Command command{"version",
                        "Print the orthoface version and the library versions it uses.",
                        "orthoface version",
                        {},
                        0};
  const Args args = parse_args(command, argc, argv);
  if (args.help) {
    print_help(command);
    return 0;
  }
  std::cout << "orthoface " << ORTHOFACE_VERSION << "\n"
            << "OpenCV " << CV_VERSION << ", Eigen " << EIGEN_WORLD_VERSION << "."
            << EIGEN_MAJOR_VERSION << "." << EIGEN_MINOR_VERSION << "\n";
  return 0;
}

}  // namespace orthoface::app
