#include "mesh/mesh_io.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "mesh/topology.h"
#include "tests/common/test_data.h"

namespace orthoface::mesh {
namespace {

namespace fs = std::filesystem;

TriMesh textured_tetrahedron() {
  TriMesh m;
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 10}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  m.uvs = {{0.1, 0.2}, {0.9, 0.2}, {0.5, 0.9}, {0.25, 0.75}};
  m.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2, 0.4, 0.6}};
  m.texture = cv::Mat(8, 16, CV_8UC3);
  cv::randu(m.texture, 0, 255);
  return m;
}

void write_text(const fs::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary) << s;
}

// One triangle's float32 positions (0,0,0) (1,0,0) (0,1,0): a glTF buffer.
void write_triangle_bin(const fs::path& p) {
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  write_text(p, std::string(reinterpret_cast<const char*>(pos), sizeof(pos)));
}

std::string error_of(const std::string& path, const MeshReadOptions& o = {}) {
  try {
    read_mesh(path, o);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

void expect_same_geometry(const TriMesh& a, const TriMesh& b, double tol) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.vertices.size(); ++i)
    EXPECT_LT((a.vertices[i] - b.vertices[i]).norm(), tol);
  for (size_t t = 0; t < a.triangles.size(); ++t) EXPECT_EQ(a.triangles[t], b.triangles[t]);
}

TEST(MeshIo, ObjRoundTripKeepsUvsColoursAndTexture) {
  const auto dir = testing::temp_dir("mesh_io_obj");
  const TriMesh m = textured_tetrahedron();
  write_mesh(m, (dir / "tet.obj").string());
  EXPECT_TRUE(fs::exists(dir / "tet.mtl"));
  EXPECT_TRUE(fs::exists(dir / "tet.png"));
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos);
  const TriMesh r = read_mesh((dir / "tet.obj").string());
  expect_same_geometry(m, r, 1e-6);
  ASSERT_EQ(r.uvs.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_LT((r.uvs[i] - m.uvs[i]).norm(), 1e-7);
  ASSERT_EQ(r.colors.size(), 4u);
  EXPECT_LT((r.colors[3] - m.colors[3]).norm(), 1e-5);
  ASSERT_FALSE(r.texture.empty());
  EXPECT_EQ(cv::norm(r.texture, m.texture, cv::NORM_INF), 0);
}

// The texture is found through a relative mesh path and through an MTL in another folder (the
// image is named relative to the MTL, the MTL relative to the OBJ).
TEST(MeshIo, ObjTextureFoundThroughRelativePaths) {
  const auto dir = testing::temp_dir("mesh_io_obj_relative");
  const TriMesh m = textured_tetrahedron();
  fs::create_directories(dir / "sub" / "mat");
  write_mesh(m, (dir / "sub" / "tet.obj").string());
  const fs::path before = fs::current_path();
  fs::current_path(dir);
  TriMesh r;
  EXPECT_NO_THROW(r = read_mesh("sub/tet.obj"));
  fs::current_path(before);
  ASSERT_FALSE(r.texture.empty());
  EXPECT_EQ(cv::norm(r.texture, m.texture, cv::NORM_INF), 0);
  fs::rename(dir / "sub" / "tet.png", dir / "sub" / "mat" / "skin.png");
  write_text(dir / "sub" / "mat" / "tet.mtl", "newmtl skin\nmap_Kd skin.png\n");
  std::ifstream in(dir / "sub" / "tet.obj");
  std::string obj((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  obj.replace(obj.find("mtllib tet.mtl"), 14, "mtllib mat/tet.mtl");
  write_text(dir / "sub" / "tet.obj", obj);
  const TriMesh q = read_mesh((dir / "sub" / "tet.obj").string());
  ASSERT_FALSE(q.texture.empty());
  EXPECT_EQ(cv::norm(q.texture, m.texture, cv::NORM_INF), 0);
}

// A texture that is not an accepted image type (here a DICOM file cut short, which OpenCV's
// DICOM decoder aborted on) is refused with the mesh's error, not decoded.
TEST(MeshIo, TextureOfAnotherTypeIsRefusedNotDecoded) {
  const auto dir = testing::temp_dir("mesh_io_dicom_texture");
  write_mesh(textured_tetrahedron(), (dir / "tet.obj").string());
  std::string dicom(128, '\0');
  dicom.replace(0, 8, "\x89PNG\x05\n\x1a\n", 8);  // one byte off a PNG signature
  dicom += std::string("DICM\0", 5);
  write_text(dir / "tet.png", dicom);
  try {
    read_mesh((dir / "tet.obj").string());
    ADD_FAILURE() << "the DICOM texture was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be decoded"), std::string::npos) << e.what();
  }
}

TEST(MeshIo, PlyRoundTripBinaryAndAscii) {
  const auto dir = testing::temp_dir("mesh_io_ply");
  const TriMesh m = textured_tetrahedron();
  for (bool binary : {true, false}) {
    const std::string p = (dir / (binary ? "b.ply" : "a.ply")).string();
    write_mesh(m, p, {binary});
    const TriMesh r = read_mesh(p);
    expect_same_geometry(m, r, 1e-5);
    ASSERT_EQ(r.colors.size(), 4u);
    EXPECT_LT((r.colors[3] - m.colors[3]).norm(), 1.0 / 255);  // stored as uchar
    ASSERT_EQ(r.uvs.size(), 4u);
    EXPECT_LT((r.uvs[2] - m.uvs[2]).norm(), 1e-6);
    EXPECT_EQ(cv::norm(r.texture, m.texture, cv::NORM_INF), 0);
  }
}

TEST(MeshIo, OffRoundTripWithColours) {
  const auto dir = testing::temp_dir("mesh_io_off");
  TriMesh m = textured_tetrahedron();
  write_mesh(m, (dir / "t.off").string());
  const TriMesh r = read_mesh((dir / "t.off").string());
  expect_same_geometry(m, r, 1e-6);
  ASSERT_EQ(r.colors.size(), 4u);
  EXPECT_LT((r.colors[0] - m.colors[0]).norm(), 1.0 / 255);
  m.colors.clear();
  write_mesh(m, (dir / "plain.off").string());
  EXPECT_TRUE(read_mesh((dir / "plain.off").string()).colors.empty());
}

TEST(MeshIo, ObjPolygonsAreTriangulatedAndSeamsSplit) {
  const auto dir = testing::temp_dir("mesh_io_obj_poly");
  // A quad (fan-triangulated) and a triangle sharing position 2 with a different vt, negative
  // (relative) indices in the last face.
  write_text(dir / "q.obj",
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 1 0\n"
             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
             "f 1/1 2/2 3/3 4/4\nf -4/-4 -1/-1 -3/-2\n");
  const TriMesh r = read_mesh((dir / "q.obj").string());
  EXPECT_EQ(r.triangles.size(), 3u);
  EXPECT_EQ(r.vertices.size(), 6u);  // 5 positions, position 2 used with two different vt
  EXPECT_TRUE(topology_report(r).manifold());
  EXPECT_EQ(topology_report(r).vertices, 5);
}

// Minimal GLB: one triangle, with the given index component type (5121/5123/5125), an embedded
// 2x2 PNG and a node translation.
std::string make_glb(int index_type) {
  std::string bin;
  auto put = [&](const void* p, size_t n) { bin.append(static_cast<const char*>(p), n); };
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const float uv[6] = {0, 0, 1, 0, 0, 1};
  put(pos, sizeof(pos));
  put(uv, sizeof(uv));
  const size_t idx_off = bin.size();
  const int isz = index_type == 5121 ? 1 : index_type == 5123 ? 2 : 4;
  for (std::uint32_t i : {0u, 1u, 2u}) put(&i, isz);  // little endian: low bytes first
  while (bin.size() % 4) bin.push_back('\0');
  std::vector<uchar> png;
  cv::imencode(".png", cv::Mat(2, 2, CV_8UC3, cv::Scalar(10, 20, 30)), png);
  const size_t img_off = bin.size();
  put(png.data(), png.size());
  while (bin.size() % 4) bin.push_back('\0');
  const std::string json =
      R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)"
      R"("nodes":[{"mesh":0,"translation":[5,0,0]}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2,"material":0}]}],)"
      R"("materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],)"
      R"("textures":[{"source":0}],"images":[{"bufferView":3,"mimeType":"image/png"}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
      R"({"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"},)"
      R"({"bufferView":2,"componentType":)" +
      std::to_string(index_type) +
      R"(,"count":3,"type":"SCALAR"}],)"
      R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":24},)"
      R"({"buffer":0,"byteOffset":)" +
      std::to_string(idx_off) + R"(,"byteLength":)" + std::to_string(3 * isz) +
      "},"
      R"({"buffer":0,"byteOffset":)" +
      std::to_string(img_off) + R"(,"byteLength":)" + std::to_string(png.size()) +
      "}],"
      R"("buffers":[{"byteLength":)" +
      std::to_string(bin.size()) + "}]}";
  std::string js = json;
  while (js.size() % 4) js.push_back(' ');
  std::string out = "glTF";
  auto u32 = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  u32(2);
  u32(static_cast<std::uint32_t>(12 + 8 + js.size() + 8 + bin.size()));
  u32(static_cast<std::uint32_t>(js.size()));
  u32(0x4E4F534Au);
  out += js;
  u32(static_cast<std::uint32_t>(bin.size()));
  u32(0x004E4942u);
  out += bin;
  return out;
}

TEST(MeshIo, GlbWithEveryIndexWidthAndEmbeddedImage) {
  const auto dir = testing::temp_dir("mesh_io_glb");
  for (int type : {5121, 5123, 5125}) {
    const fs::path p = dir / ("t" + std::to_string(type) + ".glb");
    write_text(p, make_glb(type));
    const TriMesh r = read_mesh(p.string());
    ASSERT_EQ(r.triangles.size(), 1u);
    EXPECT_EQ(r.triangles[0], (std::array<int, 3>{0, 1, 2}));
    EXPECT_NEAR(r.vertices[1].x(), 6.0, 1e-9);  // node translation applied
    EXPECT_NEAR(r.uvs[2].y(), 0.0, 1e-9);       // glTF v = 1 (bottom) becomes TriMesh v = 0
    ASSERT_EQ(r.texture.rows, 2);
    EXPECT_EQ(r.texture.at<cv::Vec3b>(0, 0), cv::Vec3b(10, 20, 30));
    MeshReadOptions keep;
    keep.gltf_uv_bottom_origin = true;
    EXPECT_NEAR(read_mesh(p.string(), keep).uvs[2].y(), 1.0, 1e-9);
  }
  // Truncated GLB and a .gltf whose external buffer is missing.
  const std::string full = make_glb(5123);
  write_text(dir / "cut.glb", full.substr(0, full.size() - 40));
  EXPECT_NE(error_of((dir / "cut.glb").string()).find("cut.glb"), std::string::npos);
  write_text(dir / "ext.gltf",
             R"({"asset":{"version":"2.0"},"buffers":[{"uri":"missing.bin","byteLength":4}]})");
  EXPECT_NE(error_of((dir / "ext.gltf").string()).find("missing.bin"), std::string::npos);
  write_text(dir / "bad.gltf", "{ not json");
  EXPECT_NE(error_of((dir / "bad.gltf").string()).find("invalid glTF"), std::string::npos);
}

// Crafted glTF files: each is refused with an error naming the file, none crashes, hangs or
// reads a device. One triangle's positions in tri.bin; the JSON around it varies.
TEST(MeshIo, HostileGltfIsRefused) {
  const auto dir = testing::temp_dir("mesh_io_gltf_hostile");
  write_triangle_bin(dir / "tri.bin");
  auto gltf = [&](const std::string& nodes, const std::string& accessor,
                  const std::string& view = R"({"buffer":0,"byteLength":36})",
                  const std::string& uri = "tri.bin") {
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":)" + nodes +
           R"(,"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"accessors":[)" +
           accessor + R"(],"bufferViews":[)" + view + R"(],"buffers":[{"uri":")" + uri +
           R"(","byteLength":36}]})";
  };
  const std::string ok_accessor =
      R"({"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"})";
  write_text(dir / "ok.gltf", gltf(R"([{"mesh":0}])", ok_accessor));
  EXPECT_EQ(read_mesh((dir / "ok.gltf").string()).triangles.size(), 1u);
  std::string chain = "[";
  for (int i = 0; i < 5000; ++i)
    chain += (i ? "," : "") + std::string(R"({"children":[)") + std::to_string(i + 1) + "]}";
  chain += R"(,{"mesh":0}])";
  const std::pair<std::string, std::string> cases[] = {
      {gltf(R"([{"mesh":0,"children":[0]}])", ok_accessor), "its own ancestor"},
      {gltf(R"([{"children":[1]},{"mesh":0,"children":[0]}])", ok_accessor), "its own ancestor"},
      {gltf(chain, ok_accessor), "deeper than"},
      {gltf(R"([{"mesh":0}])",
            R"({"bufferView":0,"componentType":5126,"count":1000000000000,"type":"VEC3"})"),
       "past the end"},
      {gltf(R"([{"mesh":0}])",
            R"({"bufferView":0,"componentType":5126,"count":-3.4e38,"type":"VEC3"})"),
       "invalid glTF"},
      {gltf(R"([{"mesh":0}])",
            R"({"bufferView":0,"byteOffset":18446744073709551600,"componentType":5126,)"
            R"("count":3,"type":"VEC3"})"),
       "past the end"},
      {gltf(R"([{"mesh":0}])", ok_accessor,
            R"({"buffer":0,"byteOffset":18446744073709551600,"byteLength":36})"),
       "past the end"},
      {gltf(R"([{"mesh":0}])", ok_accessor, R"({"buffer":0,"byteLength":36})", "/dev/zero"),
       "/dev/zero"},
      {gltf(R"([{"mesh":7}])", ok_accessor), "does not exist"},
  };
  int i = 0;
  for (const auto& [text, needle] : cases) {
    const fs::path p = dir / ("h" + std::to_string(i++) + ".gltf");
    write_text(p, text);
    const std::string e = error_of(p.string());
    EXPECT_NE(e.find(p.string()), std::string::npos) << i << ": " << e;
    EXPECT_NE(e.find(needle), std::string::npos) << i << ": " << e;
  }
}

TEST(MeshIo, GltfWithExternalBinFile) {
  const auto dir = testing::temp_dir("mesh_io_gltf");
  write_triangle_bin(dir / "tri.bin");
  write_text(
      dir / "tri.gltf",
      R"({"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"uri":"tri.bin","byteLength":36}]})");
  const TriMesh r = read_mesh((dir / "tri.gltf").string());
  EXPECT_EQ(r.triangles.size(), 1u);
  EXPECT_TRUE(r.uvs.empty());
}

TEST(MeshIo, BadInputFilesGiveErrorsNamingTheFile) {
  const fs::path bad = fs::path(ORTHOFACE_SOURCE_DIR) / "tests/data/bad_inputs";
  const std::pair<const char*, const char*> cases[] = {
      {"mesh_empty.obj", "empty"},
      {"mesh_points_only.obj", "no faces"},
      {"mesh_nan_vertex.obj", "non-finite"},
      {"mesh_face_index_out_of_range.obj", "out of range"},
      {"mesh_negative_index_too_far.obj", "out of range"},
      {"mesh_degenerate_only.obj", "zero area"},
      {"mesh_garbage.ply", "claims"},
      {"mesh_truncated.ply", "truncated"}};
  for (const auto& [file, what] : cases) {
    const std::string msg = error_of((bad / file).string());
    EXPECT_NE(msg.find(file), std::string::npos) << file << ": " << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << file << ": " << msg;
  }
  // A non-manifold mesh is a valid file: it reads, and topology reports the problem.
  const TriMesh nm = read_mesh((bad / "mesh_non_manifold_edge.obj").string());
  EXPECT_EQ(topology_report(nm).non_manifold_edges, 1);
}

// Inputs the fuzz targets found (fuzz/corpus/*/regress_*): refused with an error, not undefined
// behaviour (a face size beyond size_t cast from double; a NaN index printed through a cast; the
// message of a truncated vertex list read from the emptied token list).
TEST(MeshIo, FuzzFindingsAreRefused) {
  const fs::path corpus = fs::path(ORTHOFACE_SOURCE_DIR) / "fuzz/corpus";
  const std::pair<const char*, const char*> cases[] = {
      {"off/regress_face_count_beyond_size_t.off", "bad face"},
      {"glb/regress_nan_index.glb", "index -nan out of range"},
      {"off/regress_truncated_vertices_message.off", "truncated"}};
  for (const auto& [file, what] : cases) {
    const std::string msg = error_of((corpus / file).string());
    EXPECT_NE(msg.find(fs::path(file).filename().string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << file << ": " << msg;
  }
}

TEST(MeshIo, MissingFilesAndUnknownFormats) {
  const auto dir = testing::temp_dir("mesh_io_missing");
  EXPECT_NE(error_of((dir / "none.obj").string()).find("does not exist"), std::string::npos);
  write_text(dir / "x.stl", "solid x\n");
  EXPECT_NE(error_of((dir / "x.stl").string()).find("unknown mesh format"), std::string::npos);
  write_text(dir / "t.obj",
             "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n");
  EXPECT_NE(error_of((dir / "t.obj").string()).find("nowhere.mtl"), std::string::npos);
  MeshReadOptions no_tex;
  no_tex.load_texture = false;
  EXPECT_EQ(read_mesh((dir / "t.obj").string(), no_tex).triangles.size(), 1u);
  write_text(dir / "bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  EXPECT_NE(error_of((dir / "bad.off").string()).find("out of range"), std::string::npos);
}

TEST(MeshIo, WriteFailuresLeaveNothingBehind) {
  const auto dir = testing::temp_dir("mesh_io_write_fail");
  const TriMesh m = textured_tetrahedron();
  EXPECT_THROW(write_mesh(m, (dir / "no_such_dir" / "t.ply").string()), std::runtime_error);
  EXPECT_THROW(write_mesh(m, (dir / "t.stl").string()), std::runtime_error);
  EXPECT_THROW(write_mesh(TriMesh{}, (dir / "t.obj").string()), std::invalid_argument);
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(MeshIo, LeePerrySmithGlbAndObjAgree) {
  const std::string glb = testing::shared_data("lee_perry_smith_head/LeePerrySmith.glb");
  const std::string obj = testing::shared_data("lee_perry_smith_head/LeePerrySmith.obj");
  if (glb.empty() || obj.empty()) GTEST_SKIP() << "no ../shared/data/lee_perry_smith_head";
  MeshReadOptions o;
  o.gltf_uv_bottom_origin = true;  // SOURCE.md: this file's UVs are OBJ-style
  const TriMesh a = read_mesh(glb, o);
  const TriMesh b = read_mesh(obj);
  EXPECT_EQ(a.vertices.size(), 9279u);
  EXPECT_EQ(a.triangles.size(), 17684u);
  expect_same_geometry(a, b, 1e-5);
  ASSERT_EQ(a.uvs.size(), b.uvs.size());
  double max_uv = 0;
  for (size_t i = 0; i < a.uvs.size(); ++i) max_uv = std::max(max_uv, (a.uvs[i] - b.uvs[i]).norm());
  EXPECT_LT(max_uv, 1e-6);
  EXPECT_EQ(b.texture.rows, 1024);  // map_Kd Map-COL.jpg
  EXPECT_TRUE(a.texture.empty());   // the glb has no image
  const TopologyReport r = topology_report(a);
  EXPECT_TRUE(r.watertight());
  EXPECT_EQ(r.euler_characteristic, 2);
}

}  // namespace
}  // namespace orthoface::mesh
