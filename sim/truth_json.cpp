#include "sim/truth_json.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "io/json_text.h"

namespace orthoface::sim {
namespace {

using nlohmann::json;

// Field access that names the field (and the file) when it is missing or has the wrong type.
struct Reader {
  std::string path;
  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw std::runtime_error("truth file " + path + ": " + field + ": " + what);
  }
  const json& at(const json& j, const std::string& key, const std::string& field) const {
    if (!j.is_object() || !j.contains(key)) fail(field, "missing");
    return j.at(key);
  }
  // io::json_number with the file named.
  double number(const json& v, const std::string& field) const {
    try {
      return io::json_number(v, field);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error("truth file " + path + ": " + e.what());
    }
  }
  double num(const json& j, const std::string& key, const std::string& field) const {
    return number(at(j, key, field), field);
  }
  bool flag(const json& j, const std::string& key, const std::string& field) const {
    const json& v = at(j, key, field);
    if (!v.is_boolean()) fail(field, "expected true or false, got " + io::json_type_name(v));
    return v.get<bool>();
  }
  std::string text(const json& j, const std::string& key, const std::string& field) const {
    const json& v = at(j, key, field);
    if (!v.is_string()) fail(field, "expected a string, got " + io::json_type_name(v));
    return v.get<std::string>();
  }
  Eigen::VectorXd vec(const json& j, const std::string& key, const std::string& field,
                      int n) const {
    const json& v = at(j, key, field);
    if (!v.is_array() || static_cast<int>(v.size()) != n)
      fail(field,
           "expected an array of " + std::to_string(n) + " numbers, got " +
               (v.is_array() ? "an array of " + std::to_string(v.size()) : io::json_type_name(v)));
    Eigen::VectorXd out(n);
    for (int i = 0; i < n; ++i) out[i] = number(v[i], field + "[" + std::to_string(i) + "]");
    return out;
  }
  Eigen::MatrixXd mat(const json& j, const std::string& key, const std::string& field, int rows,
                      int cols) const {
    const json& v = at(j, key, field);
    if (!v.is_array() || static_cast<int>(v.size()) != rows)
      fail(field, "expected a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix");
    Eigen::MatrixXd m(rows, cols);
    for (int r = 0; r < rows; ++r) {
      json row = json::object({{"r", v[r]}});
      m.row(r) = vec(row, "r", field, cols).transpose();
    }
    return m;
  }
};

json to_json(const Eigen::VectorXd& v) {
  return json(std::vector<double>(v.data(), v.data() + v.size()));
}

json camera_json(const capture::CameraModel& c) {
  json k = {{c.fx, 0.0, c.cx}, {0.0, c.fy, c.cy}, {0.0, 0.0, 1.0}};
  json pose = json::array();
  const Eigen::Matrix4d m = c.cam_from_head.matrix();
  for (int r = 0; r < 4; ++r) pose.push_back(to_json(m.row(r).transpose()));
  std::vector<double> d = c.distortion;
  d.resize(std::max<size_t>(d.size(), 5), 0.0);
  return {{"projection",
           c.projection == capture::Projection::Orthographic ? "orthographic" : "perspective"},
          {"width", c.width},
          {"height", c.height},
          {"camera_matrix", k},
          {"distortion", d},
          {"cam_from_head", pose}};
}

capture::CameraModel read_camera(const Reader& rd, const json& j, const std::string& field) {
  capture::CameraModel c;
  const std::string proj = rd.text(j, "projection", field + ".projection");
  if (proj != "orthographic" && proj != "perspective")
    rd.fail(field + ".projection", "expected orthographic or perspective");
  c.projection =
      proj == "orthographic" ? capture::Projection::Orthographic : capture::Projection::Perspective;
  c.width = static_cast<int>(rd.num(j, "width", field + ".width"));
  c.height = static_cast<int>(rd.num(j, "height", field + ".height"));
  const Eigen::MatrixXd k = rd.mat(j, "camera_matrix", field + ".camera_matrix", 3, 3);
  c.fx = k(0, 0), c.fy = k(1, 1), c.cx = k(0, 2), c.cy = k(1, 2);
  const Eigen::VectorXd d = rd.vec(j, "distortion", field + ".distortion", 5);
  if (d.cwiseAbs().maxCoeff() > 0) c.distortion.assign(d.data(), d.data() + 5);
  c.cam_from_head.matrix() = rd.mat(j, "cam_from_head", field + ".cam_from_head", 4, 4);
  return c;
}

json rig_json(const capture::RigCalibration& rig) {
  return {
      {"front", camera_json(rig.front)}, {"side", camera_json(rig.side)}, {"source", rig.source}};
}

capture::RigCalibration read_rig_json(const Reader& rd, const json& j, const std::string& field) {
  capture::RigCalibration rig;
  rig.front = read_camera(rd, rd.at(j, "front", field + ".front"), field + ".front");
  rig.side = read_camera(rd, rd.at(j, "side", field + ".side"), field + ".side");
  rig.source =
      j.contains("source") && j["source"].is_string() ? j["source"].get<std::string>() : "";
  return rig;
}

json pose_json(const PoseError& e) {
  return {{"roll_deg", e.roll_deg},
          {"yaw_deg", e.yaw_deg},
          {"pitch_deg", e.pitch_deg},
          {"offset_mm", to_json(e.offset_mm)}};
}

PoseError read_pose(const Reader& rd, const json& j, const std::string& field) {
  PoseError e;
  e.roll_deg = rd.num(j, "roll_deg", field + ".roll_deg");
  e.yaw_deg = rd.num(j, "yaw_deg", field + ".yaw_deg");
  e.pitch_deg = rd.num(j, "pitch_deg", field + ".pitch_deg");
  e.offset_mm = rd.vec(j, "offset_mm", field + ".offset_mm", 3);
  return e;
}

const char* background_name(BackgroundKind k) {
  switch (k) {
    case BackgroundKind::Cluttered:
      return "cluttered";
    case BackgroundKind::Photo:
      return "photo";
    case BackgroundKind::Plain:
      break;
  }
  return "plain";
}

json options_json(const RigOptions& o) {
  return {{"rig", o.kind == RigKind::Ideal ? "ideal" : "perspective"},
          {"px_per_mm", o.px_per_mm},
          {"focal_px", o.focal_px},
          {"distance_mm", o.distance_mm},
          {"front_error", pose_json(o.front_error)},
          {"side_error", pose_json(o.side_error)},
          {"ambient", o.ambient},
          {"diffuse", o.diffuse},
          {"light_direction", to_json(o.light_direction)},
          {"noise_sigma", o.noise_sigma},
          {"blur_sigma", o.blur_sigma},
          {"background", background_name(o.background)},
          {"background_photo", o.background_photo},
          {"background_bgr", {o.background_bgr[0], o.background_bgr[1], o.background_bgr[2]}}};
}

RigOptions read_options(const Reader& rd, const json& j) {
  RigOptions o;
  const std::string kind = rd.text(j, "rig", "options.rig");
  if (kind != "ideal" && kind != "perspective")
    rd.fail("options.rig", "expected ideal or perspective");
  o.kind = kind == "ideal" ? RigKind::Ideal : RigKind::Perspective;
  o.px_per_mm = rd.num(j, "px_per_mm", "options.px_per_mm");
  o.focal_px = rd.num(j, "focal_px", "options.focal_px");
  o.distance_mm = rd.num(j, "distance_mm", "options.distance_mm");
  o.front_error =
      read_pose(rd, rd.at(j, "front_error", "options.front_error"), "options.front_error");
  o.side_error = read_pose(rd, rd.at(j, "side_error", "options.side_error"), "options.side_error");
  o.ambient = rd.num(j, "ambient", "options.ambient");
  o.diffuse = rd.num(j, "diffuse", "options.diffuse");
  o.light_direction = rd.vec(j, "light_direction", "options.light_direction", 3);
  o.noise_sigma = rd.num(j, "noise_sigma", "options.noise_sigma");
  o.blur_sigma = rd.num(j, "blur_sigma", "options.blur_sigma");
  const std::string bg = rd.text(j, "background", "options.background");
  if (bg != "plain" && bg != "cluttered" && bg != "photo")
    rd.fail("options.background", "expected plain, cluttered or photo");
  o.background = bg == "plain"       ? BackgroundKind::Plain
                 : bg == "cluttered" ? BackgroundKind::Cluttered
                                     : BackgroundKind::Photo;
  if (j.contains("background_photo"))
    o.background_photo = rd.text(j, "background_photo", "options.background_photo");
  const Eigen::VectorXd c = rd.vec(j, "background_bgr", "options.background_bgr", 3);
  o.background_bgr = cv::Scalar(c[0], c[1], c[2]);
  return o;
}

json landmark_json(const LandmarkTruth& t) {
  return {{"xyz_mm", to_json(t.xyz_mm)},
          {"front_px", to_json(t.front_px)},
          {"side_px", to_json(t.side_px)},
          {"visible_front", t.visible_front},
          {"visible_side", t.visible_side}};
}

// json::dump(2) with every array of plain numbers on one line, so the file reads as a table.
std::string readable_dump(const json& j) {
  const std::string in = j.dump(2);
  std::string out;
  out.reserve(in.size());
  for (size_t i = 0; i < in.size(); ++i) {
    const size_t close = in[i] == '[' ? in.find(']', i) : std::string::npos;
    if (close != std::string::npos &&
        in.find_first_of("[{\"", i + 1) > close) {  // no nested array, object or string inside
      out += '[';
      bool space = false;
      for (size_t k = i + 1; k < close; ++k) {
        const char c = in[k];
        if (c == ' ' || c == '\n') {
          space = true;
          continue;
        }
        if (space && out.back() == ',') out += ' ';
        space = false;
        out += c;
      }
      out += ']';
      i = close;
      continue;
    }
    out += in[i];
  }
  return out;
}

// A point behind a perspective camera projects to NaN, which JSON cannot hold: written as null.
json px_json(const Eigen::Vector2d& p) { return p.allFinite() ? to_json(p) : json(nullptr); }

}  // namespace

Truth make_truth(const Capture& capture, const RigOptions& options, const std::string& subject,
                 const std::string& mesh_file) {
  Truth t;
  t.subject = subject;
  t.mesh_file = mesh_file;
  t.options = options;
  t.true_rig = capture.true_rig;
  t.nominal_rig = capture.nominal_rig;
  t.landmarks = capture.landmarks;
  return t;
}

void write_truth_json(const Truth& truth, const std::string& path) {
  json lm = json::object();
  for (const auto& [name, t] : truth.landmarks) {
    lm[name] = landmark_json(t);
    lm[name]["front_px"] = px_json(t.front_px);
    lm[name]["side_px"] = px_json(t.side_px);
  }
  const json j = {
      {"format", "orthoface-truth"},
      {"version", 1},
      {"subject", truth.subject},
      {"seed", truth.options.seed},
      {"mesh", truth.mesh_file},
      {"image_size", {truth.options.width, truth.options.height}},
      {"units", "mm (head frame, DESIGN.md); px (origin top-left, pixel centre = index + 0.5)"},
      {"options", options_json(truth.options)},
      {"cameras", {{"true", rig_json(truth.true_rig)}, {"nominal", rig_json(truth.nominal_rig)}}},
      {"landmarks", lm}};
  io::write_text_atomically(path, readable_dump(j) + "\n");
}

Truth read_truth_json(const std::string& path) {
  const Reader rd{path};
  std::ifstream f(path);
  if (!f || !std::filesystem::is_regular_file(path))
    throw std::runtime_error("truth file " + path + ": cannot be opened");
  const json j = json::parse(f, nullptr, false);
  if (j.is_discarded()) throw std::runtime_error("truth file " + path + ": not valid JSON");
  if (rd.text(j, "format", "format") != "orthoface-truth")
    rd.fail("format", "expected orthoface-truth");
  if (rd.num(j, "version", "version") != 1) rd.fail("version", "only version 1 is known");
  Truth t;
  t.subject = rd.text(j, "subject", "subject");
  t.mesh_file = rd.text(j, "mesh", "mesh");
  t.options = read_options(rd, rd.at(j, "options", "options"));
  const double seed = rd.num(j, "seed", "seed");
  if (seed < 0 || seed != std::floor(seed)) rd.fail("seed", "expected a non-negative integer");
  t.options.seed = static_cast<std::uint64_t>(seed);
  const Eigen::VectorXd size = rd.vec(j, "image_size", "image_size", 2);
  t.options.width = static_cast<int>(size[0]);
  t.options.height = static_cast<int>(size[1]);
  try {
    t.options.check();
  } catch (const std::invalid_argument& e) {
    rd.fail("options", e.what());
  }
  const json& cams = rd.at(j, "cameras", "cameras");
  t.true_rig = read_rig_json(rd, rd.at(cams, "true", "cameras.true"), "cameras.true");
  t.nominal_rig = read_rig_json(rd, rd.at(cams, "nominal", "cameras.nominal"), "cameras.nominal");
  const json& lms = rd.at(j, "landmarks", "landmarks");
  if (!lms.is_object()) rd.fail("landmarks", "expected an object");
  for (const auto& [name, v] : lms.items()) {
    const std::string field = "landmarks." + name;
    LandmarkTruth lt;
    lt.xyz_mm = rd.vec(v, "xyz_mm", field + ".xyz_mm", 3);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    lt.front_px = v.contains("front_px") && v["front_px"].is_null()
                      ? Eigen::Vector2d(nan, nan)
                      : Eigen::Vector2d(rd.vec(v, "front_px", field + ".front_px", 2));
    lt.side_px = v.contains("side_px") && v["side_px"].is_null()
                     ? Eigen::Vector2d(nan, nan)
                     : Eigen::Vector2d(rd.vec(v, "side_px", field + ".side_px", 2));
    lt.visible_front = rd.flag(v, "visible_front", field + ".visible_front");
    lt.visible_side = rd.flag(v, "visible_side", field + ".visible_side");
    t.landmarks[name] = lt;
  }
  return t;
}

}  // namespace orthoface::sim
