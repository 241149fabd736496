// Textured exports: the inherited atlas, OBJ / GLB / PLY written and read back.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <opencv2/imgproc.hpp>

#include "capture/camera_model.h"
#include "mesh/mesh_io.h"
#include "render/image_metrics.h"
#include "render/renderer.h"
#include "render/shapes.h"
#include "render/textured_export.h"
#include "tests/common/test_data.h"

namespace orthoface::render {
namespace {

namespace fs = std::filesystem;

struct Photos {
  mesh::TriMesh textured, bare;
  capture::RigCalibration rig = capture::ideal_rig(640, 480, 2.0);
  cv::Mat front, side;
};

Photos photos() {
  Photos p;
  p.textured = uv_ellipsoid({0, 0, 0}, {70, 100, 85}, 32, 64, 512);
  p.bare.vertices = p.textured.vertices;
  p.bare.triangles = p.textured.triangles;
  Renderer r;
  p.front = r.render(p.textured, p.rig.front).image;
  p.side = r.render(p.textured, p.rig.side).image;
  return p;
}

capture::CameraModel yaw_view(const capture::CameraModel& front, double deg) {
  return capture::camera_at(front, deg * M_PI / 180, 0, 1000);
}

TEST(TexturedExport, TrianglesInheritFromThePhotoTheyFace) {
  const Photos p = photos();
  const InheritedMesh m = inherit_texture(p.bare, p.rig, p.front, p.side);
  int counts[3] = {0, 0, 0};
  for (size_t t = 0; t < p.bare.triangles.size(); ++t) {
    const auto& tri = p.bare.triangles[t];
    const Eigen::Vector3d c =
        (p.bare.vertices[tri[0]] + p.bare.vertices[tri[1]] + p.bare.vertices[tri[2]]) / 3;
    const Eigen::Vector3d dir(c.x() / 70, c.y() / 100, c.z() / 85);  // ~ outward
    const int s = m.source[t];
    ++counts[s + 1];
    if (dir.z() > 0.3 && dir.z() > dir.x() + 0.2) {
      EXPECT_EQ(s, 0) << t;
    }
    if (dir.x() > 0.3 && dir.x() > dir.z() + 0.2) {
      EXPECT_EQ(s, 1) << t;
    }
    if (dir.x() < -0.2 && dir.z() < -0.2) {
      EXPECT_EQ(s, -1) << t;
    }
  }
  EXPECT_GT(counts[0], 500);  // fill
  EXPECT_GT(counts[1], 500);  // front
  EXPECT_GT(counts[2], 300);  // side
  mesh::check_mesh(m.mesh, "inherited");
  EXPECT_EQ(m.mesh.triangles.size(), p.bare.triangles.size());
  EXPECT_GT(m.mesh.vertices.size(), p.bare.vertices.size());  // split at the source seams
}

TEST(TexturedExport, InheritedMeshRendersLikeTheTruth) {
  const Photos p = photos();
  const mesh::TriMesh m = inherit_texture(p.bare, p.rig, p.front, p.side).mesh;
  Renderer r;
  for (double yaw : {0.0, 30.0, 60.0}) {
    const capture::CameraModel cam = yaw_view(p.rig.front, yaw);
    const RenderResult truth = r.render(p.textured, cam), got = r.render(m, cam);
    const double v = psnr(truth.image, got.image, truth.mask);
    std::printf("inherited atlas, yaw %.0f: PSNR %.2f dB\n", yaw, v);
    EXPECT_GT(v, 30.0) << "yaw " << yaw;
  }
}

TEST(TexturedExport, ObjGlbAndPlyLoadBack) {
  const Photos p = photos();
  const mesh::TriMesh m = inherit_texture(p.bare, p.rig, p.front, p.side).mesh;
  const fs::path dir = testing::temp_dir("textured_export");
  mesh::write_mesh(m, (dir / "head.obj").string());
  write_glb(m, (dir / "head.glb").string());
  InheritOptions raw;
  raw.equalize = false;
  mesh::write_mesh(inherit_vertex_colours(p.bare, p.rig, p.front, p.side, raw),
                   (dir / "head.ply").string());
  for (const char* f : {"head.obj", "head.mtl", "head.png", "head.glb", "head.ply"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  EXPECT_FALSE(fs::exists(dir / "head.glb.tmp"));

  const capture::CameraModel cam = yaw_view(p.rig.front, 40);
  Renderer r;
  const RenderResult want = r.render(m, cam);
  const mesh::TriMesh obj = mesh::read_mesh((dir / "head.obj").string());
  EXPECT_GT(psnr(want.image, r.render(obj, cam).image, want.mask), 40.0);

  mesh::TriMesh glb = mesh::read_mesh((dir / "head.glb").string());
  ASSERT_EQ(glb.vertices.size(), m.vertices.size());
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    ASSERT_LT((glb.vertices[v] * 1000 - m.vertices[v]).norm(), 1e-3);  // metres in glTF
    ASSERT_LT((glb.uvs[v] - m.uvs[v]).norm(), 1e-6);
  }
  for (auto& v : glb.vertices) v *= 1000;
  EXPECT_GT(psnr(want.image, r.render(glb, cam).image, want.mask), 40.0);

  const mesh::TriMesh ply = mesh::read_mesh((dir / "head.ply").string());
  ASSERT_EQ(ply.colors.size(), p.bare.vertices.size());
  int checked = 0;
  for (size_t v = 0; v < ply.vertices.size(); ++v) {
    const Eigen::Vector3d& q = ply.vertices[v];
    if (q.z() / 85 < 0.8) continue;  // clearly facing the front camera: the front photo's colour
    const Eigen::Vector2d px = capture::project(p.rig.front, q);
    cv::Mat sample;  // bilinear; getRectSubPix puts pixel centres at integers
    cv::getRectSubPix(p.front, cv::Size(1, 1),
                      cv::Point2f(float(px.x() - 0.5), float(px.y() - 0.5)), sample);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(ply.colors[v][2 - k] * 255, sample.at<cv::Vec3b>(0, 0)[k], 1.5) << v;
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

TEST(TexturedExport, AssimpReadsTheObjAndGlb) {
  if (std::system("assimp version > /dev/null 2>&1") != 0) GTEST_SKIP() << "assimp-utils absent";
  const Photos p = photos();
  const mesh::TriMesh m = inherit_texture(p.bare, p.rig, p.front, p.side).mesh;
  const fs::path dir = testing::temp_dir("textured_export_assimp");
  mesh::write_mesh(m, (dir / "head.obj").string());
  write_glb(m, (dir / "head.glb").string());
  for (const char* f : {"head.obj", "head.glb"}) {
    const std::string cmd =
        "assimp info " + (dir / f).string() + " > " + (dir / "info.txt").string() + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << f;
    std::ifstream in(dir / "info.txt");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find(std::to_string(m.triangles.size())), std::string::npos) << f << ":\n"
                                                                                << text;
  }
  if (std::system("gltf_validator --version > /dev/null 2>&1") == 0) {
    const std::string cmd =
        "gltf_validator -o " + (dir / "head.glb").string() + " > /dev/null 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
  }
}

TEST(TexturedExport, DegenerateAndBadInputs) {
  const Photos p = photos();
  // A mesh facing away from both cameras takes only the fill colour.
  mesh::TriMesh back;
  back.vertices = {{-10, 0, -50}, {10, 0, -50}, {0, 10, -50}};
  back.triangles = {{0, 2, 1}};  // normal toward -z
  const InheritedMesh b = inherit_texture(back, p.rig, p.front, p.side);
  EXPECT_EQ(b.source[0], -1);
  EXPECT_EQ(b.mesh.uvs[0], b.mesh.uvs[1]);

  EXPECT_THROW(inherit_texture(mesh::TriMesh{}, p.rig, p.front, p.side), std::invalid_argument);
  EXPECT_THROW(inherit_texture(p.bare, p.rig, p.front, cv::Mat(10, 10, CV_8UC3)),
               std::invalid_argument);
  InheritOptions o;
  o.padding_px = -1;
  EXPECT_THROW(inherit_texture(p.bare, p.rig, p.front, p.side, o), std::invalid_argument);
  EXPECT_THROW(write_glb(p.bare, (testing::temp_dir("glb_bad") / "x.glb").string()),
               std::invalid_argument);
  const mesh::TriMesh m = inherit_texture(p.bare, p.rig, p.front, p.side).mesh;
  EXPECT_THROW(write_glb(m, "/nonexistent_dir_orthoface/x.glb"), std::runtime_error);
}

}  // namespace
}  // namespace orthoface::render
