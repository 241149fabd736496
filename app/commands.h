#pragma once

namespace orthoface::app {

// One function per subcommand, each in its own file: argv[1] is the command name.
// Each returns 0 on success; errors are thrown and reported by main() as one "error:" line.
int run_version(int argc, char** argv);
int run_detect(int argc, char** argv);
int run_simulate(int argc, char** argv);
int run_demo(int argc, char** argv);
int run_reconstruct(int argc, char** argv);
int run_eval(int argc, char** argv);
int run_render(int argc, char** argv);
int run_devices(int argc, char** argv);
int run_capture(int argc, char** argv);
int run_enrol(int argc, char** argv);
int run_calibrate(int argc, char** argv);
int run_station(int argc, char** argv);
int run_features(int argc, char** argv);
int run_segment(int argc, char** argv);
int run_similarity(int argc, char** argv);

}  // namespace orthoface::app
