// `cmake --install` into a fresh prefix, and what a user's project does with it.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/common/run_command.h"
#include "tests/common/test_data.h"

namespace {

namespace fs = std::filesystem;
using orthoface::testing::run_in;
using orthoface::testing::temp_dir;

// A fresh prefix with this build installed into it.
fs::path installed(const std::string& name) {
  const fs::path dir = temp_dir(name), prefix = dir / "prefix";
  const auto r = run_in(dir, std::string("'") + ORTHOFACE_CMAKE + "' --install '" +
                                 ORTHOFACE_BUILD_DIR + "' --prefix '" + prefix.string() + "'");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  return prefix;
}

std::string consumer_source() { return std::string(ORTHOFACE_SOURCE_DIR) + "/examples/consumer"; }

TEST(Install, PrefixHoldsLibrariesHeadersPackageBinariesAndWeights) {
  const fs::path p = installed("install_layout");
  const fs::path lib = p / ORTHOFACE_LIBDIR;
  for (const char* layer :
       {"io", "capture", "vision", "mesh", "model", "analysis", "render", "reconstruct", "sim"}) {
    EXPECT_TRUE(fs::exists(lib / ("liborthoface_" + std::string(layer) + ".a"))) << layer;
    EXPECT_FALSE(fs::is_empty(p / "include/orthoface" / layer)) << layer;
  }
  EXPECT_TRUE(fs::exists(p / "include/orthoface/reconstruct/reconstruction.h"));
  EXPECT_TRUE(fs::exists(lib / "cmake/orthoface/orthofaceConfig.cmake"));
  EXPECT_TRUE(fs::exists(lib / "cmake/orthoface/orthofaceConfigVersion.cmake"));
  EXPECT_TRUE(fs::exists(lib / "cmake/orthoface/orthofaceTargets.cmake"));
  EXPECT_TRUE(fs::exists(lib / "pkgconfig/orthoface.pc"));
  EXPECT_TRUE(fs::exists(p / "share/orthoface/models/face_landmark_68_model.bin"));
  // No source-tree path leaks into the package: it must work once the sources are gone.
  const std::string targets =
      orthoface::testing::slurp(lib / "cmake/orthoface/orthofaceTargets.cmake");
  EXPECT_EQ(targets.find(ORTHOFACE_SOURCE_DIR), std::string::npos);
  EXPECT_EQ(targets.find(ORTHOFACE_BUILD_DIR), std::string::npos);
  const auto r = run_in(p, "bin/orthoface version");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find(ORTHOFACE_VERSION), std::string::npos) << r.out;
}

// examples/consumer through find_package(orthoface): configure, build, reconstruct a sim pair.
TEST(Install, ConsumerProjectBuildsAndReconstructsASimPair) {
  const fs::path p = installed("install_consumer");
  const fs::path work = p.parent_path(), build = work / "consumer-build", out = work / "model";
  const std::string cmake = std::string("'") + ORTHOFACE_CMAKE + "'";
  auto r =
      run_in(work, cmake + " -S '" + consumer_source() + "' -B '" + build.string() +
                       "' -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH='" + p.string() + "'");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  r = run_in(work, cmake + " --build '" + build.string() + "'");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  r = run_in(work, "'" + (build / "orthoface_consumer").string() + "' '" + out.string() + "'");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("reconstructed"), std::string::npos) << r.out;
  for (const char* f : {"head.obj", "front.png", "side.png", "rig.yaml", "landmarks.json",
                        "report.json", "view_yaw30.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  // The installed CLI reads the consumer's folder as its own.
  r = run_in(work, "'" + (p / "bin/orthoface").string() + "' render '" + out.string() +
                       "' --yaw -20 -o cli_view.png");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
}

// The same program built with pkg-config alone.
TEST(Install, PkgConfigGivesFlagsThatBuildTheConsumer) {
  const fs::path p = installed("install_pkgconfig");
  const fs::path work = p.parent_path();
  const std::string pc = "PKG_CONFIG_PATH='" + (p / ORTHOFACE_LIBDIR / "pkgconfig").string() + "' ";
  auto r = run_in(work, pc + "pkg-config --modversion orthoface");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, std::string(ORTHOFACE_VERSION) + "\n");
  r = run_in(work, std::string("'") + ORTHOFACE_CXX + "' -O1 '" + consumer_source() +
                       "/main.cpp' -o consumer $(" + pc + "pkg-config --cflags --libs orthoface)");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  r = run_in(work, "./consumer model");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_TRUE(fs::exists(work / "model/head.obj"));
}

// A project asking for a version the package is not, or for a target it does not have, is told
// so at configure time.
TEST(Install, PackageRefusesAnotherMajorVersionAndUnknownTargets) {
  const fs::path p = installed("install_refuses");
  const fs::path work = p.parent_path(), src = work / "asks";
  fs::create_directories(src);
  {
    std::ofstream f(src / "CMakeLists.txt");
    f << "cmake_minimum_required(VERSION 3.22)\nproject(asks LANGUAGES CXX)\n"
         "find_package(orthoface 9 REQUIRED)\n";
  }
  const std::string cmake = std::string("'") + ORTHOFACE_CMAKE + "'";
  auto r = run_in(work, cmake + " -S asks -B asks-build -DCMAKE_PREFIX_PATH='" + p.string() + "'");
  EXPECT_NE(r.code, 0);
  EXPECT_NE((r.out + r.err).find("orthoface"), std::string::npos);
  EXPECT_NE((r.out + r.err).find(ORTHOFACE_VERSION), std::string::npos) << r.out << r.err;
  {
    std::ofstream f(src / "CMakeLists.txt");
    f << "cmake_minimum_required(VERSION 3.22)\nproject(asks LANGUAGES CXX)\n"
         "find_package(orthoface REQUIRED)\nfile(WRITE ${CMAKE_BINARY_DIR}/m.cpp \"int "
         "main(){}\")\n"
         "add_executable(m ${CMAKE_BINARY_DIR}/m.cpp)\n"
         "target_link_libraries(m PRIVATE orthoface::nosuchlayer)\n";
  }
  r = run_in(work, cmake + " -S asks -B asks-build2 -DCMAKE_PREFIX_PATH='" + p.string() + "'");
  EXPECT_NE(r.code, 0);
  EXPECT_NE((r.out + r.err).find("orthoface::nosuchlayer"), std::string::npos) << r.out << r.err;
}

#ifdef ORTHOFACE_PYTHON
// The Python module from the prefix, not the build tree.
TEST(Install, PythonModuleImportsFromThePrefix) {
  const fs::path p = installed("install_python");
  const std::string path = "PYTHONPATH='" + (p / "lib/python3/dist-packages").string() + "' ";
  auto r = run_in(
      p, path + "'" + ORTHOFACE_PYTHON + "' -c 'import orthoface; print(orthoface.__file__)'");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find(p.string()), std::string::npos) << r.out;
}
#endif

}  // namespace
