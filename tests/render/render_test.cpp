// Tests of the offscreen renderer against analytic answers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include <Eigen/Geometry>

#include "capture/camera_model.h"
#include "render/renderer.h"
#include "render/shapes.h"

namespace orthoface::render {
namespace {

using capture::CameraModel;
using mesh::TriMesh;

CameraModel perspective_camera(double yaw_deg, double distance_mm) {
  CameraModel k;
  k.projection = capture::Projection::Perspective;
  k.width = 640;
  k.height = 480;
  k.fx = k.fy = 900;
  k.cx = 321.3;
  k.cy = 238.7;
  return capture::camera_at(k, yaw_deg * M_PI / 180, 0.1, distance_mm);
}

// Analytic z_cam where the ray through pixel centre (c, r) first meets the sphere (centre,
// radius), or NaN when it misses.
double sphere_depth(const CameraModel& cam, const Eigen::Vector3d& centre_head, double radius,
                    int c, int r) {
  const Eigen::Vector3d s = cam.cam_from_head * centre_head;
  const double x = (c + 0.5 - cam.cx) / cam.fx, y = (r + 0.5 - cam.cy) / cam.fy;
  if (cam.projection == capture::Projection::Orthographic) {
    const double d2 = radius * radius - (x - s.x()) * (x - s.x()) - (y - s.y()) * (y - s.y());
    return d2 < 0 ? NAN : s.z() - std::sqrt(d2);
  }
  const Eigen::Vector3d d(x, y, 1);  // point = t d, z_cam = t
  const double a = d.squaredNorm(), b = -2 * d.dot(s), cc = s.squaredNorm() - radius * radius;
  const double disc = b * b - 4 * a * cc;
  return disc < 0 ? NAN : (-b - std::sqrt(disc)) / (2 * a);
}

void expect_sphere_depth(const CameraModel& cam) {
  const Eigen::Vector3d centre(5, -3, 2);
  const double radius = 80;
  const TriMesh sphere = uv_ellipsoid(centre, Eigen::Vector3d::Constant(radius), 96, 192);
  const RenderResult r = render_once(sphere, cam);
  int checked = 0, mask_mismatch = 0;
  double worst = 0;
  for (int row = 0; row < cam.height; ++row)
    for (int col = 0; col < cam.width; ++col) {
      const double z = sphere_depth(cam, centre, radius, col, row);
      const double z_inner = sphere_depth(cam, centre, radius * 0.95, col, row);
      const bool covered = r.mask.at<uchar>(row, col) == 255;
      if (std::isnan(z) == covered) ++mask_mismatch;  // allowed only along the silhouette
      if (!covered) {
        EXPECT_TRUE(std::isinf(r.depth_mm.at<float>(row, col)));
        continue;
      }
      if (std::isnan(z_inner)) continue;  // steep rim: facet error grows there
      worst = std::max(worst, std::abs(r.depth_mm.at<float>(row, col) - z));
      ++checked;
    }
  std::printf("sphere depth: %d px checked, worst %.4f mm, %d rim mask mismatches\n", checked,
              worst, mask_mismatch);
  EXPECT_GT(checked, 10000);
  EXPECT_LT(worst, 0.1) << "max |depth - analytic| in mm";
  EXPECT_LT(mask_mismatch, 60) << "mask differs from the analytic disc beyond the rim";
}

TEST(Renderer, SphereDepthMatchesAnalyticOrthographic) {
  expect_sphere_depth(capture::ideal_rig(640, 480, 2.0).front);
  expect_sphere_depth(capture::ideal_rig(640, 480, 2.0).side);
}

TEST(Renderer, SphereDepthMatchesAnalyticPerspective) {
  expect_sphere_depth(perspective_camera(0, 600));
  expect_sphere_depth(perspective_camera(37, 450));
}

// A triangle facing the ideal front camera whose image corners are `px` (pixels).
TriMesh image_triangle(const CameraModel& cam, const std::array<Eigen::Vector2d, 3>& px) {
  TriMesh m;
  for (const auto& p : px)  // ideal front camera: x_head = (u - cx) / fx, y_head = (cy - v) / fy
    m.vertices.emplace_back((p.x() - cam.cx) / cam.fx, (cam.cy - p.y()) / cam.fy, 10.0);
  m.triangles = {{0, 1, 2}};
  return m;
}

double edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

TEST(Renderer, FlatTriangleCoversExactlyThePixelCentresInside) {
  const CameraModel cam = capture::ideal_rig(200, 150, 1.7).front;
  const std::array<Eigen::Vector2d, 3> px = {Eigen::Vector2d(20.23, 30.61),
                                             Eigen::Vector2d(51.37, 131.12),
                                             Eigen::Vector2d(183.71, 12.89)};
  TriMesh m = image_triangle(cam, px);
  if (edge(px[0], px[1], px[2]) > 0) std::swap(m.triangles[0][1], m.triangles[0][2]);
  m.colors.assign(3, Eigen::Vector3d(0.2, 0.6, 1.0));
  RenderOptions o;
  o.background = cv::Scalar(7, 8, 9);
  const RenderResult r = render_once(m, cam, o);
  int inside_count = 0;
  for (int row = 0; row < cam.height; ++row)
    for (int col = 0; col < cam.width; ++col) {
      const Eigen::Vector2d c(col + 0.5, row + 0.5);
      const double e0 = edge(px[0], px[1], c), e1 = edge(px[1], px[2], c),
                   e2 = edge(px[2], px[0], c);
      const bool inside = (e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0);
      inside_count += inside;
      ASSERT_EQ(r.mask.at<uchar>(row, col), inside ? 255 : 0) << "pixel " << col << "," << row;
      const cv::Vec3b want = inside ? cv::Vec3b(255, 153, 51) : cv::Vec3b(7, 8, 9);
      ASSERT_EQ(r.image.at<cv::Vec3b>(row, col), want) << "pixel " << col << "," << row;
    }
  EXPECT_GT(inside_count, 5000);
}

// A square of side 1 px facing `cam`, centred on head point p.
TriMesh pixel_marker(const CameraModel& cam, const Eigen::Vector3d& p) {
  const Eigen::Vector3d pc = cam.cam_from_head * p;
  const double scale = cam.projection == capture::Projection::Orthographic ? 1.0 : pc.z();
  const double hx = 0.5 * scale / cam.fx, hy = 0.5 * scale / cam.fy;
  TriMesh m;
  for (const auto& d : {Eigen::Vector2d(-hx, -hy), Eigen::Vector2d(hx, -hy),
                        Eigen::Vector2d(hx, hy), Eigen::Vector2d(-hx, hy)})
    m.vertices.push_back(cam.cam_from_head.inverse() * (pc + Eigen::Vector3d(d.x(), d.y(), 0)));
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TEST(Renderer, ProjectedPointFallsOnTheDrawnPixel) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-70, 70);
  const auto rig = capture::ideal_rig(640, 480, 2.3);
  const std::vector<CameraModel> cams = {rig.front, rig.side, perspective_camera(25, 500)};
  Renderer renderer;
  RenderOptions o;
  o.cull_back_faces = false;
  for (const CameraModel& cam : cams)
    for (int k = 0; k < 15; ++k) {
      const Eigen::Vector3d p(u(rng), u(rng), u(rng));
      const Eigen::Vector2d uv = capture::project(cam, p);
      const RenderResult r = renderer.render(pixel_marker(cam, p), cam, o);
      cv::Mat pts;
      cv::findNonZero(r.mask, pts);
      ASSERT_GE(pts.total(), 1u);
      ASSERT_LE(pts.total(), 2u);
      const cv::Point q = pts.at<cv::Point>(0);
      EXPECT_LE(std::abs(q.x + 0.5 - uv.x()), 0.5 + 1e-3);
      EXPECT_LE(std::abs(q.y + 0.5 - uv.y()), 0.5 + 1e-3);
      EXPECT_NEAR(r.depth_mm.at<float>(q.y, q.x), capture::depth(cam, p), 1e-2);
    }
}

TEST(Renderer, TextureRowZeroIsTheTopAndVZeroTheBottom) {
  const CameraModel cam = capture::ideal_rig(100, 100, 1.0).front;
  TriMesh m;
  m.vertices = {{-40, -40, 0}, {40, -40, 0}, {40, 40, 0}, {-40, 40, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.texture = cv::Mat(64, 64, CV_8UC3, cv::Scalar(255, 0, 0));      // blue
  m.texture(cv::Rect(0, 0, 64, 32)).setTo(cv::Scalar(0, 0, 255));   // top half red
  m.texture(cv::Rect(0, 32, 32, 32)).setTo(cv::Scalar(0, 255, 0));  // bottom-left green
  const RenderResult r = render_once(m, cam);
  EXPECT_EQ(r.image.at<cv::Vec3b>(20, 70), cv::Vec3b(0, 0, 255));  // top right: red
  EXPECT_EQ(r.image.at<cv::Vec3b>(80, 70), cv::Vec3b(255, 0, 0));  // bottom right: blue
  EXPECT_EQ(r.image.at<cv::Vec3b>(80, 20), cv::Vec3b(0, 255, 0));  // bottom left: green
}

TEST(Renderer, PerVertexColoursInterpolate) {
  const CameraModel cam = capture::ideal_rig(120, 120, 1.0).front;
  TriMesh m = image_triangle(
      cam, {Eigen::Vector2d(10, 110), Eigen::Vector2d(110, 110), Eigen::Vector2d(60, 10)});
  m.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  RenderOptions o;
  o.cull_back_faces = false;
  const RenderResult r = render_once(m, cam, o);
  const cv::Vec3b centroid = r.image.at<cv::Vec3b>(76, 60);  // (60, 76.7)
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(centroid[ch], 85, 4);
  EXPECT_GT(r.image.at<cv::Vec3b>(108, 13)[2], 230);  // near the red corner (BGR)
  EXPECT_GT(r.image.at<cv::Vec3b>(108, 107)[1], 230);
  EXPECT_GT(r.image.at<cv::Vec3b>(13, 60)[0], 230);
}

TEST(Renderer, BackFacesAreCulledUnlessAsked) {
  const CameraModel cam = capture::ideal_rig(100, 100, 1.0).front;
  TriMesh front = image_triangle(
      cam, {Eigen::Vector2d(10, 90), Eigen::Vector2d(90, 90), Eigen::Vector2d(50, 10)});
  // Image-clockwise (y down) = counter-clockwise seen from the camera: faces the camera.
  TriMesh back = front;
  std::swap(back.triangles[0][1], back.triangles[0][2]);
  const RenderResult rf = render_once(front, cam), rb = render_once(back, cam);
  EXPECT_GT(cv::countNonZero(rf.mask), 2000);
  EXPECT_EQ(cv::countNonZero(rb.mask), 0);
  RenderOptions o;
  o.cull_back_faces = false;
  EXPECT_EQ(cv::countNonZero(render_once(back, cam, o).mask), cv::countNonZero(rf.mask));
  // A closed sphere: culling or not, the visible surface is the same.
  const TriMesh s = uv_ellipsoid({0, 0, 0}, {30, 30, 30}, 16, 32);
  const RenderResult a = render_once(s, cam), b = render_once(s, cam, o);
  EXPECT_EQ(cv::norm(a.depth_mm, b.depth_mm, cv::NORM_INF), 0.0);
}

TEST(Renderer, BadInputsThrow) {
  Renderer r;
  const CameraModel cam = capture::ideal_rig(64, 64, 1.0).front;
  EXPECT_THROW(r.render(TriMesh{}, cam), std::invalid_argument);
  TriMesh bad = uv_ellipsoid({0, 0, 0}, {10, 10, 10}, 4, 6);
  bad.triangles[3][1] = int(bad.vertices.size());
  EXPECT_THROW(r.render(bad, cam), std::invalid_argument);
  const TriMesh ok = uv_ellipsoid({0, 0, 0}, {10, 10, 10}, 4, 6);
  for (auto [w, h] : {std::pair{0, 64}, {64, 0}, {100000, 64}, {64, 100000}, {-3, 5}}) {
    CameraModel c = cam;
    c.width = w;
    c.height = h;
    EXPECT_THROW(r.render(ok, c), std::invalid_argument) << w << "x" << h;
  }
  CameraModel nan_cam = cam;
  nan_cam.fx = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(r.render(ok, nan_cam), std::invalid_argument);
  EXPECT_THROW(uv_ellipsoid({0, 0, 0}, {10, 0, 10}, 4, 6), std::invalid_argument);
  EXPECT_THROW(uv_ellipsoid({0, 0, 0}, {10, 10, 10}, 1, 6), std::invalid_argument);
  EXPECT_NO_THROW(r.render(ok, cam));  // still usable after the errors
}

TEST(Shapes, IcosphereCountsAndRadiusAndBadInput) {
  for (int levels : {0, 2, 4}) {
    const TriMesh m = icosphere(levels, 50.0);
    const size_t faces = 20 * (size_t(1) << (2 * levels));
    EXPECT_EQ(m.triangles.size(), faces);
    EXPECT_EQ(m.vertices.size(), faces / 2 + 2);  // a closed genus-0 triangle mesh
    for (const auto& v : m.vertices) EXPECT_NEAR(v.norm(), 50.0, 1e-9);
    for (const auto& t : m.triangles) {  // counter-clockwise from outside
      const Eigen::Vector3d n =
          (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
      EXPECT_GT(n.dot(m.vertices[t[0]]), 0);
    }
  }
  EXPECT_THROW(icosphere(-1, 1.0), std::invalid_argument);
  EXPECT_THROW(icosphere(9, 1.0), std::invalid_argument);
  EXPECT_THROW(icosphere(1, 0.0), std::invalid_argument);
  EXPECT_THROW(icosphere(1, std::nan("")), std::invalid_argument);
}

TEST(Renderer, MeshBehindThePerspectiveCameraGivesAnEmptyImage) {
  CameraModel cam = perspective_camera(0, 500);
  const TriMesh s = uv_ellipsoid({0, 0, 900}, {30, 30, 30}, 8, 16);  // behind the camera
  RenderOptions o;
  o.background = cv::Scalar(10, 20, 30);
  const RenderResult r = render_once(s, cam, o);
  EXPECT_EQ(cv::countNonZero(r.mask), 0);
  EXPECT_EQ(r.image.at<cv::Vec3b>(5, 5), cv::Vec3b(10, 20, 30));
  EXPECT_TRUE(std::isinf(r.depth_mm.at<float>(240, 320)));
}

TEST(Renderer, RenderTwiceGivesIdenticalImagesAndReusesTheUpload) {
  Renderer r;
  const CameraModel cam = perspective_camera(30, 500);
  TriMesh s = uv_ellipsoid({0, 0, 0}, {70, 90, 80}, 24, 48, 256);
  const RenderResult a = r.render(s, cam), b = r.render(s, cam);
  EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth_mm, b.depth_mm, cv::NORM_INF), 0.0);
  EXPECT_EQ(r.cached_meshes(), 1);
  for (auto& v : s.vertices) v *= 0.5;  // same buffers, new geometry: must be re-uploaded
  const RenderResult c = r.render(s, cam);
  EXPECT_EQ(r.cached_meshes(), 2);
  EXPECT_LT(cv::countNonZero(c.mask), cv::countNonZero(a.mask) / 2);
  EXPECT_EQ(cv::norm(render_once(s, cam).image, c.image, cv::NORM_INF), 0.0);
  r.clear_cache();
  EXPECT_EQ(r.cached_meshes(), 0);
}

TEST(Renderer, WithoutDepthTheImageAndMaskAreTheSame) {
  Renderer r;
  const CameraModel cam = perspective_camera(30, 500);
  const TriMesh s = uv_ellipsoid({0, 0, 0}, {70, 90, 80}, 24, 48, 256);
  RenderOptions fast;
  fast.read_depth = false;
  fast.background = cv::Scalar(10, 200, 30);
  RenderOptions full = fast;
  full.read_depth = true;
  const RenderResult a = r.render(s, cam, full), b = r.render(s, cam, fast);
  EXPECT_TRUE(b.depth_mm.empty());
  EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0.0);
  ASSERT_EQ(b.mask.type(), CV_8U);
  EXPECT_EQ(cv::norm(a.mask, b.mask, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::countNonZero(b.mask), 10000);
  EXPECT_LT(cv::countNonZero(b.mask), int(b.mask.total()));
}

TEST(Renderer, DirectionalLightShadesTheRim) {
  const CameraModel cam = capture::ideal_rig(200, 200, 1.0).front;
  TriMesh s = uv_ellipsoid({0, 0, 0}, {80, 80, 80}, 48, 96);
  s.colors.assign(s.vertices.size(), Eigen::Vector3d(1, 1, 1));
  RenderOptions o;
  o.light.ambient = 0.2;
  o.light.diffuse = 0.8;
  const RenderResult r = render_once(s, cam, o);
  EXPECT_NEAR(r.image.at<cv::Vec3b>(100, 100)[1], 255, 3);  // facing the light: 0.2 + 0.8
  // at 60 degrees from the axis: 0.2 + 0.8 * cos(60) = 0.6
  const int col = int(100 + 80 * std::sin(M_PI / 3));
  EXPECT_NEAR(r.image.at<cv::Vec3b>(100, col)[1], 0.6 * 255, 8);
}

TEST(Renderer, WireframeDrawsEdgesWithoutChangingDepth) {
  const CameraModel cam = capture::ideal_rig(200, 200, 1.0).front;
  const TriMesh s = uv_ellipsoid({0, 0, 0}, {80, 80, 80}, 12, 24);
  RenderOptions o;
  o.wireframe = true;
  o.wireframe_color = cv::Scalar(0, 0, 255);
  const RenderResult plain = render_once(s, cam), wire = render_once(s, cam, o);
  cv::Mat red;
  cv::inRange(wire.image, cv::Scalar(0, 0, 250), cv::Scalar(5, 5, 255), red);
  EXPECT_GT(cv::countNonZero(red), 1000);
  EXPECT_LT(cv::countNonZero(red), cv::countNonZero(wire.mask) / 2);
  EXPECT_EQ(cv::norm(plain.depth_mm, wire.depth_mm, cv::NORM_INF), 0.0);
}

TEST(Shapes, EllipsoidHasTheExpectedSizeAndIsClosed) {
  const TriMesh m = uv_ellipsoid({1, 2, 3}, {10, 20, 30}, 32, 64, 128);
  EXPECT_EQ(m.triangles.size(), 2u * 64 * 31);
  EXPECT_EQ(m.uvs.size(), m.vertices.size());
  EXPECT_EQ(m.texture.rows, 128);
  mesh::check_mesh(m, "ellipsoid");
  // Signed volume of a closed outward mesh = 4/3 pi abc (within the faceting error).
  double vol = 0;
  for (const auto& t : m.triangles)
    vol += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6;
  EXPECT_NEAR(vol, 4.0 / 3 * M_PI * 10 * 20 * 30, 0.01 * 4.0 / 3 * M_PI * 6000);
}

}  // namespace
}  // namespace orthoface::render
