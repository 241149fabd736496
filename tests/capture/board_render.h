#pragma once
// Renders a checkerboard (a textured plane, render::Renderer) through the simulated perspective
// rig, for calibration tests with known poses.
#include <cmath>

#include <Eigen/Geometry>

#include "capture/calibration.h"
#include "render/renderer.h"
#include "sim/rig.h"

namespace orthoface::testing {

// Board plane with a one-square white margin; board frame as in capture::Checkerboard.
inline mesh::TriMesh board_mesh(const capture::Checkerboard& b,
                                const Eigen::Isometry3d& head_from_board) {
  const int sq_px = 32, nx = b.cols + 3, ny = b.rows + 3;  // squares incl. margin
  cv::Mat tex(ny * sq_px, nx * sq_px, CV_8UC3, cv::Scalar::all(255));
  for (int j = 1; j < ny - 1; ++j)
    for (int i = 1; i < nx - 1; ++i)
      if ((i + j) % 2 == 0)
        tex(cv::Rect(i * sq_px, j * sq_px, sq_px, sq_px)).setTo(cv::Scalar::all(0));
  const double s = b.square_mm, x0 = -2 * s, y0 = -2 * s, w = nx * s, h = ny * s;
  mesh::TriMesh m;
  for (auto [u, v] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
    m.vertices.push_back(head_from_board * Eigen::Vector3d(x0 + u * w, y0 + v * h, 0));
    m.uvs.emplace_back(u, 1.0 - v);  // v = 0 at the texture's bottom row
  }
  m.triangles = {{0, 2, 1}, {0, 3, 2}};  // outward normal = -z (toward the viewer)
  m.texture = tex;
  return m;
}

// Board pose: facing yaw `base_deg` (0 = the front camera, 90 = the side camera, 45 = both)
// plus tilts, centre at `centre_mm` (head frame).
inline Eigen::Isometry3d board_pose(const capture::Checkerboard& b, double base_deg,
                                    double tilt_y_deg, double tilt_x_deg,
                                    const Eigen::Vector3d& centre_mm) {
  const double d = M_PI / 180;
  Eigen::Matrix3d r0;
  r0.col(0) = Eigen::Vector3d::UnitX();
  r0.col(1) = -Eigen::Vector3d::UnitY();
  r0.col(2) = -Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd((base_deg + tilt_y_deg) * d, Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(tilt_x_deg * d, Eigen::Vector3d::UnitX()) * r0;
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = r;
  const Eigen::Vector3d c((b.cols - 1) * b.square_mm / 2, (b.rows - 1) * b.square_mm / 2, 0);
  p.translation() = centre_mm - r * c;
  return p;
}

struct BoardViews {
  std::vector<cv::Mat> front, side;
};

// One image pair per pose, rendered through `rig` (its cameras' intrinsics and poses).
inline BoardViews render_board_views(const capture::Checkerboard& b,
                                     const capture::RigCalibration& rig,
                                     const std::vector<Eigen::Isometry3d>& poses) {
  render::Renderer renderer;
  render::RenderOptions ro;
  ro.cull_back_faces = true;  // a printed board is not seen from behind
  ro.background = cv::Scalar(90, 90, 90);
  BoardViews v;
  for (const auto& p : poses) {
    const mesh::TriMesh m = board_mesh(b, p);
    v.front.push_back(renderer.render(m, rig.front, ro).image);
    v.side.push_back(renderer.render(m, rig.side, ro).image);
  }
  return v;
}

// A typical session: boards facing each camera (intrinsics) and `shared` held at ~45 deg.
inline std::vector<Eigen::Isometry3d> session_poses(const capture::Checkerboard& b, int shared) {
  std::vector<Eigen::Isometry3d> poses;
  const double tilts[8][2] = {{-35, 0},  {35, 0},   {0, -35},   {0, 35},
                              {-25, 25}, {25, -25}, {-20, -20}, {20, 20}};
  const double shift[8][2] = {{-50, -30}, {50, 30},  {50, -30}, {-50, 30},
                              {0, 0},     {-30, 20}, {30, -20}, {0, 35}};
  for (double base : {0.0, 90.0})
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d across =
          base == 0 ? Eigen::Vector3d(1, 0, 0) : Eigen::Vector3d(0, 0, -1);
      poses.push_back(board_pose(b, base, tilts[i][0], tilts[i][1],
                                 shift[i][0] * across + Eigen::Vector3d(0, shift[i][1], 0)));
    }
  for (int i = 0; i < shared; ++i)
    poses.push_back(
        board_pose(b, 45, tilts[i % 8][0] * 0.4, tilts[i % 8][1] * 0.6,
                   Eigen::Vector3d(15.0 * (i % 3) - 15, 10.0 * (i % 2) - 5, 20.0 * (i % 2))));
  return poses;
}

// The first 8 poses of session_poses face the front camera, the next 8 the side camera: hide
// each from the other camera (a blank frame), so only the 45 deg poses are shared.
inline void hide_cross_views(BoardViews& v) {
  for (size_t i = 0; i < 16 && i < v.front.size(); ++i) {
    cv::Mat& other = i < 8 ? v.side[i] : v.front[i];
    other.setTo(cv::Scalar(90, 90, 90));
  }
}

}  // namespace orthoface::testing
