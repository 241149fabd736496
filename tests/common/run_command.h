#pragma once
// Running a built program from a test, as a user would from a shell: its exit code, stdout and
// stderr.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

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
#endif

}  // namespace orthoface::testing
