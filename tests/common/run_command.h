#pragma once
// Running a built program from a test, as a user would from a shell: its exit code, stdout and
// stderr.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "tests/common/test_data.h"

namespace orthoface::testing {

// A whole file as text ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

struct CommandResult {
  int code = -1;  // exit status; -1 when the program did not exit (a signal)
  std::string out, err;
};

// Runs the shell command line `command` in folder `work`, stdout and stderr captured in
// work/out.txt and work/err.txt (tests may read them again).
inline CommandResult run_in(const std::filesystem::path& work, const std::string& command) {
  const std::filesystem::path o = work / "out.txt", e = work / "err.txt";
  const std::string line =
      "cd '" + work.string() + "' && " + command + " >'" + o.string() + "' 2>'" + e.string() + "'";
  const int status = std::system(line.c_str());
  CommandResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(o);
  r.err = slurp(e);
  return r;
}

#ifdef ORTHOFACE_BINARY
// `orthoface <args>` (the build's binary) run in `work`.
inline CommandResult run_orthoface(const std::string& args, const std::filesystem::path& work) {
  return run_in(work, "'" + std::string(ORTHOFACE_BINARY) + "' " + args);
}

// The inputs of the tests that run command after command, shared by the test processes of one
// build: in the temp folder `name`, a simulated pair (sim/: subject 0 with its rig and truth
// mesh), its reconstruction (rec/), three MPEG-4 feature points (points.json) and whatever
// `extra` adds. Made again when the orthoface binary is newer or a `required` file (relative)
// is missing, and moved into place whole (publish_fixture). Returns {} and the failing
// command's stderr in `why` when a command fails.
inline std::filesystem::path command_fixture(
    const std::string& name, const std::vector<std::string>& required,
    const std::function<void(const std::filesystem::path& work)>& extra, std::string& why) {
  namespace fs = std::filesystem;
  const fs::path ready = fs::temp_directory_path() / ("orthoface_test_" + name);
  const auto binary_time = fs::last_write_time(ORTHOFACE_BINARY);
  const auto fresh = [&] {
    if (!fs::exists(ready / "rec" / "head.obj")) return false;
    for (const std::string& r : required)
      if (!fs::exists(ready / r)) return false;
    return fs::last_write_time(ready) > binary_time;
  };
  if (fresh()) return ready;
  const fs::path work = temp_dir(name);
  const CommandResult sim = run_orthoface("simulate --subject 0 --out sim", work);
  const CommandResult rec = run_orthoface(
      "reconstruct --front sim/front.png --side sim/side.png --rig sim/rig.yaml --out rec", work);
  if (sim.code != 0 || rec.code != 0) {
    why = sim.err + rec.err;
    return {};
  }
  std::ofstream(work / "points.json")
      << R"({"9.3": [0, -20, 110], "10.1": [80, 0, 0], "10.2": [-80, 0, 0]})";
  extra(work);
  return publish_fixture(work, ready, fresh);
}
#endif

}  // namespace orthoface::testing
