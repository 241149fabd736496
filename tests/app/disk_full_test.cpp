// A full disk through every command that writes files (issue 20, item 4): a non-zero exit,
// exactly one "error:" line naming the output, and nothing left in the output folder (no target,
// no temporary), wherever in its outputs the disk fills up.
//
// The full disk is a file size limit (RLIMIT_FSIZE, set in the child between fork and exec, with
// SIGXFSZ ignored so write() fails with EFBIG): it needs no root and no mount. The limits tried
// are one byte below the size of each file the command writes when the disk is not full, so the
// failure falls at every output in turn. With root, the same runs on a full 64 kB tmpfs (ENOSPC).
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mesh/mesh_io.h"
#include "sim/head.h"
#include "tests/common/run_command.h"
#include "tests/common/test_data.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;

const fs::path kBatch = fs::path(ORTHOFACE_BINARY).parent_path() / "orthoface-batch";

struct ChildRun {
  int code = -1;  // exit status; -1 for a signal
  std::string out, err;
};

// Runs `argv` (argv[0] the program) in `work` with files limited to `limit_bytes` (0: no limit).
// stdout and stderr go through pipes, which the limit does not apply to. Killed after 300 s.
ChildRun run_limited(const std::vector<std::string>& argv, const fs::path& work, long limit_bytes) {
  int out_pipe[2], err_pipe[2];
  if (::pipe(out_pipe) != 0 || ::pipe(err_pipe) != 0) return {};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(out_pipe[1], 1);
    ::dup2(err_pipe[1], 2);
    for (int fd : {out_pipe[0], out_pipe[1], err_pipe[0], err_pipe[1]}) ::close(fd);
    if (::chdir(work.c_str()) != 0) ::_exit(126);
    if (limit_bytes > 0) {
      const rlimit limit{rlim_t(limit_bytes), rlim_t(limit_bytes)};
      if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(126);
    }
    ::signal(SIGXFSZ, SIG_IGN);  // kept across exec: the write fails with EFBIG instead
    // Open MPI's singleton start keeps its job data in shared-memory files, which the limit
    // would stop: kept in memory instead (they are not the batch's outputs).
    ::setenv("PMIX_MCA_gds", "hash", 1);
    ::alarm(300);  // a hang is a failure, not a stuck test
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);
  ChildRun r;
  pollfd fds[2] = {{out_pipe[0], POLLIN, 0}, {err_pipe[0], POLLIN, 0}};
  std::string* sinks[2] = {&r.out, &r.err};
  int open = 2;
  while (open > 0) {
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      char buf[4096];
      const ssize_t n = ::read(fds[k].fd, buf, sizeof buf);
      if (n > 0) {
        sinks[k]->append(buf, size_t(n));
      } else {
        ::close(fds[k].fd);
        fds[k].fd = -1;
        --open;
      }
    }
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Every file and folder under `dir`, relative to it, sorted.
std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  if (!fs::exists(dir)) return names;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    names.push_back(fs::relative(e.path(), dir).string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

// The inputs every case reads: a simulated pair with its rig and truth mesh, a reconstruction
// folder, a feature-point file and a folder of three meshes. Made once per binary build under
// a name shared by the test processes and moved into place whole.
fs::path fixture() {
  std::string why;
  const fs::path ready = testing::command_fixture(
      "disk_full_fixture", {"meshes/h2.ply"},
      [](const fs::path& work) {
        fs::create_directories(work / "meshes");
        sim::HeadOptions o;
        o.target_triangles = 2000;
        for (int s = 0; s < 3; ++s)
          mesh::write_mesh(sim::make_head(sim::head_params(s), o).mesh,
                           (work / "meshes" / ("h" + std::to_string(s) + ".ply")).string());
      },
      why);
  if (ready.empty()) ADD_FAILURE() << "fixture: " << why;
  return ready;
}

// One command: its arguments with IN (the fixture) and OUT (the output folder, which exists and
// starts empty) as placeholders.
struct Case {
  std::string name;
  std::vector<std::string> argv;  // argv[0]: "orthoface" or "orthoface-batch"
};

// What gtest prints for a case (not its bytes).
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<std::string> expand(const Case& c, const fs::path& in, const fs::path& out) {
  std::vector<std::string> argv;
  for (std::string a : c.argv) {
    if (a == "orthoface") a = ORTHOFACE_BINARY;
    if (a == "orthoface-batch") a = kBatch.string();
    for (const auto& [key, value] : {std::pair{"IN", in.string()}, {"OUT", out.string()}})
      for (size_t i = a.find(key); i != std::string::npos; i = a.find(key, i + value.size()))
        a.replace(i, std::strlen(key), value);
    argv.push_back(a);
  }
  return argv;
}

// The rules for one run that must fail: a plain exit, one "error:" line naming the output
// folder (the output that failed is in it), and an empty output folder.
std::vector<std::string> problems(const Case& c, const ChildRun& r, const fs::path& out) {
  std::vector<std::string> p;
  if (r.code == 0) p.push_back("exit 0");
  if (r.code < 0 || r.code >= 124) p.push_back("exit " + std::to_string(r.code) + " (signal)");
  std::vector<std::string> error_lines;
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("error:", 0) == 0) error_lines.push_back(line);
  if (error_lines.size() != 1)
    p.push_back(std::to_string(error_lines.size()) + " lines start with 'error:'");
  // orthoface prints nothing else on stderr; orthoface-batch also draws its progress bar.
  if (c.argv[0] == "orthoface" &&
      (std::count(r.err.begin(), r.err.end(), '\n') != 1 || r.err.rfind("error: ", 0) != 0))
    p.push_back("stderr is not one error line");
  if (error_lines.size() == 1 && error_lines[0].find(out.string()) == std::string::npos)
    p.push_back("the error does not name the output (" + out.string() + ")");
  const std::vector<std::string> left = listing(out);
  if (!left.empty()) p.push_back("left " + joined(left));
  return p;
}

const std::vector<Case>& cases() {
  static const std::vector<Case> all = {
      {"RenderView", {"orthoface", "render", "IN/rec", "--yaw", "20", "-o", "OUT/view.png"}},
      {"RenderTurntable",
       {"orthoface", "render", "IN/rec", "--turntable", "3", "--size", "160x120", "-o",
        "OUT/sheet.png"}},
      {"RenderExportGlb", {"orthoface", "render", "IN/rec", "--export", "OUT/head.glb"}},
      {"RenderExportObj", {"orthoface", "render", "IN/rec", "--export", "OUT/head.obj"}},
      {"RenderExportAndView",
       {"orthoface", "render", "IN/rec", "--export", "OUT/head.ply", "--yaw", "30", "-o",
        "OUT/view.jpg"}},
      {"Detect",
       {"orthoface", "detect", "--front", "IN/sim/front.png", "--side", "IN/sim/side.png", "--out",
        "OUT/det", "--pts", "OUT/front.pts"}},
      {"Features", {"orthoface", "features", "IN/sim/truth.obj", "-o", "OUT/feat"}},
      {"Segment",
       {"orthoface", "segment", "IN/sim/truth.obj", "--points", "IN/points.json", "--smooth", "20",
        "-o", "OUT/seg"}},
      {"Similarity",
       {"orthoface", "similarity", "IN/meshes/h0.ply", "IN/meshes/h1.ply", "IN/meshes/h2.ply", "-o",
        "OUT/sim"}},
      {"Reconstruct",
       {"orthoface", "reconstruct", "--front", "IN/sim/front.png", "--side", "IN/sim/side.png",
        "--rig", "IN/sim/rig.yaml", "--out", "OUT/rec"}},
      {"BatchSimilarity", {"orthoface-batch", "similarity", "IN/meshes", "-o", "OUT"}},
  };
  return all;
}

// Limits just below each distinct size among the files a successful run wrote (so the write of
// that file, and of every larger one, fails near its end), at most `most` of them spread over
// the range, the smallest and the largest always in. 16 bytes below, not 1: a report that
// holds timings can come out a few bytes shorter on the limited run than on this one.
std::vector<long> limits_for(const fs::path& done, size_t most) {
  std::set<long> sizes;
  for (const auto& e : fs::recursive_directory_iterator(done))
    if (e.is_regular_file() && e.file_size() > 1) {
      const long size = long(e.file_size());
      sizes.insert(size > 32 ? size - 16 : size / 2);
    }
  const std::vector<long> all(sizes.begin(), sizes.end());
  if (all.size() <= most) return all;
  std::vector<long> picked;
  for (size_t k = 0; k < most; ++k) picked.push_back(all[k * (all.size() - 1) / (most - 1)]);
  picked.erase(std::unique(picked.begin(), picked.end()), picked.end());
  return picked;
}

class DiskFull : public ::testing::TestWithParam<Case> {};

TEST_P(DiskFull, OneErrorLineNamingTheOutputAndNothingLeft) {
  const Case& c = GetParam();
  if (c.argv[0] == "orthoface-batch" && !fs::exists(kBatch))
    GTEST_SKIP() << "orthoface-batch not built (no MPI)";
  const fs::path in = fixture();
  ASSERT_FALSE(in.empty());
  const fs::path work = testing::temp_dir("disk_full_" + c.name);
  // The run with room: it succeeds, and what it writes gives the limits.
  const fs::path done = work / "done";
  fs::create_directories(done);
  const ChildRun ok = run_limited(expand(c, in, done), work, 0);
  ASSERT_EQ(ok.code, 0) << ok.err;
  ASSERT_FALSE(listing(done).empty());
  for (const std::string& name : listing(done))
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
  const std::vector<long> limits = limits_for(done, 5);
  ASSERT_FALSE(limits.empty());
  for (const long limit : limits) {
    SCOPED_TRACE(c.name + " with files limited to " + std::to_string(limit) + " bytes");
    const fs::path out = work / ("out_" + std::to_string(limit));
    fs::create_directories(out);
    const ChildRun r = run_limited(expand(c, in, out), work, limit);
    for (const std::string& p : problems(c, r, out))
      ADD_FAILURE() << p << "\nexit " << r.code << ", stderr:\n" << r.err;
  }
  if (!HasFailure()) fs::remove_all(work);
}

INSTANTIATE_TEST_SUITE_P(Commands, DiskFull, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

// A real full disk: a 64 kB tmpfs as the output folder (ENOSPC rather than EFBIG). Needs root
// and a kernel that lets this process mount; skipped otherwise.
TEST(DiskFullTmpfs, EveryCommandOnAFull64kTmpfs) {
  if (::geteuid() != 0) GTEST_SKIP() << "not root: cannot mount a tmpfs";
  const fs::path in = fixture();
  ASSERT_FALSE(in.empty());
  const fs::path work = testing::temp_dir("disk_full_tmpfs");
  const fs::path disk = work / "tmpfs", out = disk / "out";
  fs::create_directories(disk);
  if (::mount("tmpfs", disk.c_str(), "tmpfs", MS_NOSUID | MS_NODEV, "size=64k") != 0)
    GTEST_SKIP() << "mount -t tmpfs -o size=64k failed: " << std::strerror(errno);
  {  // filled up to the last byte, beside the output folder
    std::ofstream filler(disk / "filler", std::ios::binary);
    const std::string block(4096, 'x');
    for (int i = 0; i < 64 && filler; ++i) filler << block << std::flush;
  }
  EXPECT_GT(fs::file_size(disk / "filler"), 0u);
  fs::create_directories(out);
  for (const Case& c : cases()) {
    if (c.argv[0] == "orthoface-batch" && !fs::exists(kBatch)) continue;
    SCOPED_TRACE(c.name + " on a full 64 kB tmpfs");
    const ChildRun r = run_limited(expand(c, in, out), work, 0);
    for (const std::string& p : problems(c, r, out))
      ADD_FAILURE() << p << "\nexit " << r.code << ", stderr:\n" << r.err;
    for (const std::string& name : listing(out)) fs::remove_all(out / name);  // the next one
  }
  ::umount(disk.c_str());
  if (!HasFailure()) fs::remove_all(work);
}

}  // namespace
}  // namespace orthoface::app
