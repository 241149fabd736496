#include "sim/rig.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/image_file.h"
#include "sim/face_mask.h"

namespace orthoface::sim {
namespace {

constexpr int kMaxImageSide = 8192;  // render::Renderer's limit
// A camera's pose error, or the turn of a moving head played as the cameras turning about it
// (sim/sim_camera.h): up to 30 deg of yaw and 20 of pitch, with room for a rig error on top.
constexpr double kMaxPoseErrorDeg = 45;
constexpr double kSelfHitMm = 1.0;  // hits this close to a landmark are its own surface

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("RigOptions: " + what);
}

double rad(double deg) { return deg * M_PI / 180.0; }

void check_pose_error(const PoseError& e, const std::string& which) {
  for (double a : {e.roll_deg, e.yaw_deg, e.pitch_deg})
    require(std::isfinite(a) && std::abs(a) <= kMaxPoseErrorDeg,
            which + " pose error angles must be finite and within +-45 degrees");
  require(e.offset_mm.allFinite() && e.offset_mm.cwiseAbs().maxCoeff() <= 100.0,
          which + " pose offset must be finite and within +-100 mm");
}

// seed 004 §4: the TRUE camera differs from the nominal one by a small rotation about the
// head origin (around the camera's own axes) and an offset; see PoseError.
capture::CameraModel with_error(const capture::CameraModel& nominal, const PoseError& e) {
  const Eigen::Isometry3d head_from_cam = nominal.cam_from_head.inverse();
  const Eigen::Matrix3d r_cam = (Eigen::AngleAxisd(rad(e.yaw_deg), Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(rad(e.pitch_deg), Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(rad(e.roll_deg), Eigen::Vector3d::UnitZ()))
                                    .toRotationMatrix();
  const Eigen::Matrix3d rn = head_from_cam.linear();
  const Eigen::Matrix3d r_head = rn * r_cam * rn.transpose();  // same turn, head frame
  Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
  moved.linear() = r_head * rn;
  moved.translation() = r_head * head_from_cam.translation() + e.offset_mm;
  capture::CameraModel c = nominal;
  c.cam_from_head = moved.inverse();
  return c;
}

// The head's pixels over the background, by the render mask.
cv::Mat composite(const render::RenderResult& r, const cv::Mat& background) {
  cv::Mat out = background.clone();
  r.image.copyTo(out, r.mask);
  return out;
}

render::RenderOptions render_options(const RigOptions& o, const cv::Scalar& background) {
  render::RenderOptions ro;
  ro.background = background;
  ro.light.ambient = o.ambient;
  ro.light.diffuse = o.diffuse;
  ro.light.direction_head = o.light_direction.normalized();
  return ro;
}

// True when the segment from p toward the camera (length t_max) crosses a triangle farther than
// kSelfHitMm from p (Moller-Trumbore). An exact ray cast rather than the rendered depth map:
// at silhouette points (nose tip in the side view, cheeks in the front view) the pixel's ray
// grazes the surface, so the depth map reads a nearer surface than the landmark.
bool occluded(const mesh::TriMesh& mesh, const Eigen::Vector3d& p, const Eigen::Vector3d& dir,
              double t_max) {
  for (const auto& tri : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[tri[0]];
    const Eigen::Vector3d e1 = mesh.vertices[tri[1]] - a, e2 = mesh.vertices[tri[2]] - a;
    const Eigen::Vector3d h = dir.cross(e2);
    const double det = e1.dot(h);
    if (std::abs(det) < 1e-12) continue;
    const Eigen::Vector3d s = p - a;
    const double u = s.dot(h) / det;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = dir.dot(q) / det;
    if (v < 0 || u + v > 1) continue;
    const double t = e2.dot(q) / det;
    if (t > kSelfHitMm && t < t_max) return true;
  }
  return false;
}

// Visible when the landmark projects inside the image and nothing lies between it and the camera.
bool visible(const mesh::TriMesh& mesh, const capture::CameraModel& cam, const Eigen::Vector3d& p,
             const Eigen::Vector2d& px) {
  if (!px.allFinite() || px.x() < 0 || px.y() < 0 || px.x() >= cam.width || px.y() >= cam.height)
    return false;
  if (cam.projection == capture::Projection::Orthographic)
    return !occluded(mesh, p, -capture::view_direction(cam),
                     std::numeric_limits<double>::infinity());
  const Eigen::Vector3d centre = cam.cam_from_head.inverse().translation();
  return !occluded(mesh, p, (centre - p).normalized(), (centre - p).norm());
}

void add_clutter(cv::Mat& img, cv::RNG& rng) {
  const int w = img.cols, h = img.rows, big = std::max(w, h);
  auto colour = [&] {
    return cv::Scalar(rng.uniform(20, 235), rng.uniform(20, 235), rng.uniform(20, 235));
  };
  auto point = [&] {
    return cv::Point(rng.uniform(-w / 8, w + w / 8), rng.uniform(-h / 8, h + h / 8));
  };
  for (int i = 0; i < 14; ++i) {  // shelves, posters, doors
    const cv::Point a = point();
    const cv::Point b =
        a + cv::Point(rng.uniform(big / 20, big / 3 + 2), rng.uniform(big / 20, big / 3 + 2));
    cv::rectangle(img, a, b, colour(), cv::FILLED);
  }
  for (int i = 0; i < 10; ++i)  // lamps, plates, plants
    cv::circle(img, point(), rng.uniform(big / 60 + 1, big / 10 + 2), colour(), cv::FILLED,
               cv::LINE_AA);
  for (int i = 0; i < 16; ++i)  // cables, frames, edges that disturb an edge detector
    cv::line(img, point(), point(), colour(), rng.uniform(1, std::max(2, big / 160)), cv::LINE_AA);
  for (int i = 0; i < 6; ++i)
    cv::putText(img, "ORTHO" + std::to_string(rng.uniform(0, 1000)), point(),
                cv::FONT_HERSHEY_SIMPLEX, big / 800.0 + 0.3, colour(), 1 + big / 500, cv::LINE_AA);
}

// One camera's part of the background photo: the photo scaled to cover 1.3 times the frame, a
// seeded frame-sized window of it (the front camera's in the left half of the spare room, the
// side camera's in the right half), mirrored for the side camera.
cv::Mat photo_part(const RigOptions& o, int camera_index) {
  const cv::Mat photo = io::imread_accepted(o.background_photo, cv::IMREAD_COLOR);
  if (photo.empty())
    throw std::invalid_argument("background photo '" + o.background_photo +
                                "' cannot be read as an image (" + io::kAcceptedImageTypes + ")");
  const double s = 1.3 * std::max(double(o.width) / photo.cols, double(o.height) / photo.rows);
  cv::Mat big;
  cv::resize(photo, big,
             cv::Size(std::max(o.width, int(std::ceil(photo.cols * s))),
                      std::max(o.height, int(std::ceil(photo.rows * s)))),
             0, 0, s > 1 ? cv::INTER_CUBIC : cv::INTER_AREA);
  cv::RNG rng(o.seed * 104729u + 11u);
  const int spare_x = big.cols - o.width, spare_y = big.rows - o.height;
  const double fx = rng.uniform(0.0, 0.5) + 0.5 * camera_index, fy = rng.uniform(0.0, 1.0);
  cv::Mat out = big(cv::Rect(int(fx * spare_x), int(fy * spare_y), o.width, o.height)).clone();
  if (camera_index == 1) cv::flip(out, out, 1);
  return out;
}

}  // namespace

void RigOptions::check() const {
  require(width >= 1 && width <= kMaxImageSide && height >= 1 && height <= kMaxImageSide,
          "image size " + std::to_string(width) + "x" + std::to_string(height) +
              " must be within 1..8192 per side");
  require(std::isfinite(px_per_mm) && px_per_mm > 0 && px_per_mm <= 1000,
          "px_per_mm must be in (0, 1000]");
  require(std::isfinite(focal_px) && focal_px > 0 && focal_px <= 1e6,
          "focal_px must be in (0, 1e6]");
  require(std::isfinite(distance_mm) && distance_mm >= 200 && distance_mm <= 1e5,
          "distance_mm must be in [200, 100000] (the camera must stand outside the head)");
  check_pose_error(front_error, "front");
  check_pose_error(side_error, "side");
  require(std::isfinite(ambient) && ambient >= 0 && ambient <= 4, "ambient must be in [0, 4]");
  require(std::isfinite(diffuse) && diffuse >= 0 && diffuse <= 4, "diffuse must be in [0, 4]");
  require(light_direction.allFinite() && light_direction.norm() > 1e-9,
          "light_direction must be a finite non-zero vector");
  require(std::isfinite(noise_sigma) && noise_sigma >= 0 && noise_sigma <= 100,
          "noise_sigma must be in [0, 100] grey levels");
  require(std::isfinite(blur_sigma) && blur_sigma >= 0 && blur_sigma <= 50,
          "blur_sigma must be in [0, 50] pixels");
  for (int i = 0; i < 3; ++i)
    require(background_bgr[i] >= 0 && background_bgr[i] <= 255, "background_bgr must be in 0..255");
  require((background == BackgroundKind::Photo) == !background_photo.empty(),
          "background_photo is needed with, and only with, a photo background");
}

capture::RigCalibration nominal_rig(const RigOptions& options) {
  options.check();
  capture::RigCalibration rig;
  if (options.kind == RigKind::Ideal) {
    rig = capture::ideal_rig(options.width, options.height, options.px_per_mm);
  } else {
    capture::CameraModel base;
    base.projection = capture::Projection::Perspective;
    base.width = options.width;
    base.height = options.height;
    base.fx = base.fy = options.focal_px;
    base.cx = options.width / 2.0;
    base.cy = options.height / 2.0;
    rig.front = capture::camera_at(base, 0.0, 0.0, options.distance_mm);
    rig.side = capture::camera_at(base, M_PI / 2, 0.0, options.distance_mm);
  }
  rig.source = "sim";
  return rig;
}

capture::RigCalibration true_rig(const RigOptions& options) {
  capture::RigCalibration rig = nominal_rig(options);
  rig.front = with_error(rig.front, options.front_error);
  rig.side = with_error(rig.side, options.side_error);
  rig.source = "sim (true cameras)";
  return rig;
}

cv::Mat background_image(const RigOptions& options, int camera_index) {
  options.check();
  if (camera_index != 0 && camera_index != 1)
    throw std::invalid_argument("background_image: camera_index must be 0 (front) or 1 (side)");
  if (options.background == BackgroundKind::Photo) return photo_part(options, camera_index);
  cv::Mat img(options.height, options.width, CV_8UC3, options.background_bgr);
  if (options.background == BackgroundKind::Plain) return img;
  // Cluttered: a lit wall (vertical gradient), objects, and fine texture; cv::RNG is the same
  // on every platform, so a seed always gives the same room.
  cv::RNG rng(options.seed * 7919u + 17u + static_cast<std::uint64_t>(camera_index));
  const cv::Vec3b top(rng.uniform(60, 220), rng.uniform(60, 220), rng.uniform(60, 220));
  const cv::Vec3b bottom(rng.uniform(30, 200), rng.uniform(30, 200), rng.uniform(30, 200));
  for (int r = 0; r < img.rows; ++r) {
    const double t = img.rows > 1 ? r / double(img.rows - 1) : 0.0;
    img.row(r).setTo(cv::Scalar(top[0] * (1 - t) + bottom[0] * t, top[1] * (1 - t) + bottom[1] * t,
                                top[2] * (1 - t) + bottom[2] * t));
  }
  add_clutter(img, rng);
  cv::Mat grain(img.size(), CV_16SC3);
  rng.fill(grain, cv::RNG::NORMAL, 0, 12);
  cv::GaussianBlur(grain, grain, cv::Size(0, 0), 1.5);
  cv::Mat out;
  cv::add(img, grain, out, cv::noArray(), CV_8UC3);
  return out;
}

cv::Mat degrade(const cv::Mat& image, const RigOptions& options, int stream) {
  options.check();
  if (image.empty() || image.type() != CV_8UC3)
    throw std::invalid_argument("degrade: expected a non-empty 8-bit BGR image");
  cv::Mat out = image.clone();
  if (options.blur_sigma > 0) cv::GaussianBlur(out, out, cv::Size(0, 0), options.blur_sigma);
  if (options.noise_sigma > 0) {
    cv::RNG rng(options.seed * 1000003u + 101u + static_cast<std::uint64_t>(stream));
    cv::Mat noise(out.size(), CV_32FC3), f;
    rng.fill(noise, cv::RNG::NORMAL, 0, options.noise_sigma);
    out.convertTo(f, CV_32FC3);
    f += noise;
    f.convertTo(out, CV_8UC3);  // rounds and saturates to 0..255
  }
  return out;
}

Capture simulate_capture(const Head& head, const RigOptions& options, render::Renderer& renderer) {
  options.check();
  mesh::check_mesh(head.mesh, "simulate_capture: head '" + head.name + "'");
  Capture cap;
  cap.nominal_rig = nominal_rig(options);
  cap.true_rig = true_rig(options);
  const render::RenderOptions ro = render_options(options, cv::Scalar(0, 0, 0));
  const capture::CameraModel* cams[2] = {&cap.true_rig.front, &cap.true_rig.side};
  render::RenderResult views[2];
  for (int i = 0; i < 2; ++i) {
    views[i] = renderer.render(head.mesh, *cams[i], ro);
    const cv::Mat bg = background_image(options, i);
    (i == 0 ? cap.front : cap.side) = degrade(composite(views[i], bg), options, i);
    (i == 0 ? cap.background_front : cap.background_side) = degrade(bg, options, 2 + i);
  }
  cap.front_mask = views[0].mask;
  cap.side_mask = views[1].mask;
  cap.front_depth_mm = views[0].depth_mm;
  cap.side_depth_mm = views[1].depth_mm;
  if (has_face_landmarks(head)) {
    cap.front_face_mask = face_mask(head, cap.true_rig.front, renderer);
    cap.side_face_mask = face_mask(head, cap.true_rig.side, renderer);
  }
  for (const auto& [name, p] : head.landmarks) {
    LandmarkTruth t;
    t.xyz_mm = p;
    t.front_px = capture::project(cap.true_rig.front, p);
    t.side_px = capture::project(cap.true_rig.side, p);
    t.visible_front = visible(head.mesh, cap.true_rig.front, p, t.front_px);
    t.visible_side = visible(head.mesh, cap.true_rig.side, p, t.side_px);
    cap.landmarks[name] = t;
  }
  return cap;
}

Capture simulate_capture(const Head& head, const RigOptions& options) {
  options.check();
  render::Renderer renderer;
  return simulate_capture(head, options, renderer);
}

render::RenderResult true_view(const Head& head, const RigOptions& options, double yaw_rad,
                               double pitch_rad, render::Renderer& renderer) {
  return render_head(head, options, true_view_camera(options, yaw_rad, pitch_rad), renderer);
}

render::RenderResult render_head(const Head& head, const RigOptions& options,
                                 const capture::CameraModel& camera, render::Renderer& renderer) {
  options.check();
  return renderer.render(head.mesh, camera, render_options(options, options.background_bgr));
}

}  // namespace orthoface::sim
