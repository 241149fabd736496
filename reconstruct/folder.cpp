// The reconstruction folder: written (all files first in a staging folder beside it) and read back,
// here only.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <stdexcept>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "io/atomic_file.h"
#include "io/image_file.h"
#include "io/json_text.h"
#include "mesh/mesh_io.h"
#include "mesh/topology.h"
#include "model/head_hull.h"
#include "model/symmetry.h"
#include "reconstruct/reconstruction.h"
#include "render/new_view.h"
#include "render/textured_export.h"
#include "vision/image_prep.h"
#include "vision/observation_io.h"
#include "vision/profile_mask.h"

namespace orthoface::reconstruct {
namespace {

// The JSON of the file at `path`. Throws std::runtime_error naming it when it cannot be read or
// is not valid JSON.
nlohmann::json read_json_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read " + path);
  try {
    return nlohmann::json::parse(f);
  } catch (const nlohmann::json::parse_error& e) {
    throw std::runtime_error(path + ": not valid JSON (" + io::json_error_text(e) + ")");
  }
}

// The head's measured turn from a report.json that write_reconstruction wrote (mirror_plane
// turns the face's plane by it): head_yaw_deg (a number, or null when not measured) and
// head_turn_corrected. A report without them (an older folder) leaves the turn unmeasured.
// Throws std::runtime_error naming the file when it is not valid JSON or the fields have other
// types.
void read_head_turn(const std::string& path, Reconstruction& r) {
  const nlohmann::json j = read_json_file(path);
  if (!j.is_object()) throw std::runtime_error(path + ": the top level must be an object");
  const auto yaw = j.find("head_yaw_deg");
  const auto corrected = j.find("head_turn_corrected");
  if (yaw == j.end() || corrected == j.end()) return;
  if (!(yaw->is_number() || yaw->is_null()) || !corrected->is_boolean())
    throw std::runtime_error(path +
                             ": head_yaw_deg must be a number or null and head_turn_corrected "
                             "true or false");
  if (yaw->is_number()) r.report.head_yaw_deg = yaw->get<double>();
  r.report.head_turn_corrected = corrected->get<bool>();
}

namespace fs = std::filesystem;

// Through io/atomic_file.h: a write that fails anywhere, even in the last flush, is an error
// (a plain stream's destructor and cv::imwrite both ignore that one).
void write_json(const nlohmann::json& j, const fs::path& path) {
  io::write_text_atomically(path.string(), j.dump(2) + "\n");
}

void write_png(const cv::Mat& image, const fs::path& path) {
  if (image.empty()) return;
  io::write_image_atomically(path.string(), image);
}

nlohmann::json landmarks_json(const Reconstruction& r) {
  const std::set<std::string> found(r.report.features_found.begin(), r.report.features_found.end());
  nlohmann::json l = nlohmann::json::object();
  for (const auto& [name, p] : r.landmarks) {
    const auto c = r.report.confidences.find("feature:" + name);
    l[name] = {{"xyz_mm", {p.x(), p.y(), p.z()}},
               {"observed", found.count(name) > 0},
               {"confidence", c == r.report.confidences.end() ? 0.0 : c->second}};
  }
  return {{"format", "orthoface-landmarks"},
          {"version", 1},
          {"units", "mm, head frame (DESIGN.md)"},
          {"landmarks", l}};
}

// Each check of the input check: passed, the measure and its limit (null when not measured).
nlohmann::json input_check_json(const std::vector<vision::InputCheck>& checks) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& c : checks)
    j[c.name] = {{"passed", c.passed},
                 {"value", io::number_or_null(c.value)},
                 {"limit", io::number_or_null(c.limit)}};
  return j;
}

nlohmann::json report_object(const Reconstruction& r) {
  const ReconstructionReport& rep = r.report;
  nlohmann::json stages = nlohmann::json::object();
  double total = 0;
  for (const auto& [stage, ms] : rep.stage_ms) stages[stage] = ms, total += ms;
  return {{"format", "orthoface-report"},
          {"version", 1},
          {"scale", rep.scale_note},
          {"front_landmarker", rep.front_landmarker},
          {"rig_source", r.rig.source},
          // `orthoface render --yaw`: > 0 views the head from the subject's left (head frame +x)
          {"photographed_side_yaw_sign", capture::photographed_side_sign(r.photo_rig)},
          // the head's turn in the front photo (> 0 toward the subject's left; null: unknown)
          {"head_yaw_deg", std::isfinite(rep.head_yaw_deg) ? nlohmann::json(rep.head_yaw_deg)
                                                           : nlohmann::json(nullptr)},
          {"head_turn_corrected", rep.head_turn_corrected},
          // the side photo rescaled to the front photo's height by this (1: same height)
          {"side_photo_scale", rep.side_photo_scale},
          // the face's flanks set back this far (mm) where the two photos agree best (their
          // correlation there before and after; reconstruct/flank_depth.h)
          {"flank_depth",
           {{"offset_mm", rep.flanks.offset_mm},
            {"offset_below_mm", rep.flanks.offset_below_mm},
            {"agreement_before", io::number_or_null(rep.flanks.agreement_before)},
            {"agreement_after", io::number_or_null(rep.flanks.agreement_after)},
            {"points", rep.flanks.points}}},
          {"stage_ms", stages},
          {"total_ms", total},
          {"warnings", rep.warnings},
          {"input_check", input_check_json(rep.input_checks)},
          {"confidences", rep.confidences},
          {"features_found", rep.features_found},
          {"landmarks_used", rep.landmarks_used},
          {"folds_fixed", rep.folds_fixed},
          {"folds_remaining", rep.folds_remaining},
          {"fins_opened", rep.fins_opened},
          {"clamped_to_silhouette", rep.clamped_to_silhouette},
          {"surface",
           {{"roughness_mm", rep.surface_roughness_mm},
            {"smoothed_share", rep.surface_smoothed_share}}},
          {"mesh",
           {{"file", "head.obj"},
            {"texture",
             "head.png: both photos, each triangle from the one that sees it and "
             "that it faces more (as render --export)"},
            {"vertices", r.mesh.vertices.size()},
            {"triangles", r.mesh.triangles.size()}}}};
}

}  // namespace

std::string report_json(const Reconstruction& r) { return report_object(r).dump(2) + "\n"; }

void write_reconstruction(const Reconstruction& r, const std::string& dir) {
  const fs::path out(dir);
  if (fs::exists(out) && !fs::is_directory(out))
    throw std::runtime_error("output " + dir + " exists and is not a folder");
  const fs::path tmp = io::temp_path_for(out.string());
  std::error_code ec;
  try {
    fs::create_directories(tmp);
    // The textured model: each triangle from the photo that sees it and that it faces more (the
    // same texture as `render --export`), in an atlas of both photos.
    mesh::write_mesh(render::inherit_texture(r.mesh, r.photo_rig, r.front, r.side).mesh,
                     (tmp / "head.obj").string());
    write_png(r.front, tmp / "front.png");
    write_png(r.side, tmp / "side.png");
    if (!r.front_silhouette.empty() && !r.side_silhouette.empty()) {
      write_png(r.front_silhouette, tmp / "silhouette_front.png");
      write_png(r.side_silhouette, tmp / "silhouette_side.png");
    }
    if (!r.front_plate.empty()) write_png(r.front_plate, tmp / "background_front.png");
    capture::write_rig(r.rig, (tmp / "rig.yaml").string());
    vision::write_observation(r.observation, (tmp / "observation.json").string());
    write_json(landmarks_json(r), tmp / "landmarks.json");
    write_json(report_object(r), tmp / "report.json");
    // A new folder is the staging folder renamed; into an existing one the files move one by
    // one (a rename within a folder needs no space).
    fs::rename(tmp, out, ec);
    if (ec) {
      fs::create_directories(out);
      for (const auto& e : fs::directory_iterator(tmp))
        fs::rename(e.path(), out / e.path().filename());
      fs::remove_all(tmp);
    }
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    // The message names the files where they were to go, not the staging folder.
    std::string why = e.what();
    for (size_t i = why.find(tmp.string()); i != std::string::npos;
         i = why.find(tmp.string(), i + out.string().size()))
      why.replace(i, tmp.string().size(), out.string());
    throw std::runtime_error("cannot write reconstruction " + dir + ": " + why);
  }
}

Reconstruction read_reconstruction(const std::string& dir, const ReadOptions& options) {
  const fs::path in(dir);
  const std::string what = "reconstruction folder " + dir;
  if (!fs::is_directory(in)) throw std::runtime_error(what + " does not exist");
  for (const char* name : {"head.obj", "front.png", "side.png"})
    if (!fs::is_regular_file(in / name)) throw std::runtime_error(what + ": no " + name);
  Reconstruction r;
  for (auto [name, image] : {std::pair{"front.png", &r.front}, {"side.png", &r.side}}) {
    try {  // read_image: a truncated or undecodable file is refused without decoder chatter
      *image = vision::read_image((in / name).string());
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(what + ": " + e.what());
    }
  }
  mesh::MeshReadOptions ro;
  ro.load_texture = false;  // views and exports texture the mesh from the photos themselves
  // The atlas splits vertices where triangles of the two photos meet: welded back into the mesh
  // that was modelled.
  r.mesh = mesh::weld(mesh::read_mesh((in / "head.obj").string(), ro));
  r.mesh.uvs.clear();
  r.rig = fs::exists(in / "rig.yaml") ? capture::read_rig((in / "rig.yaml").string())
                                      : capture::ideal_rig(r.front.cols, r.front.rows, 1.6);
  r.photo_rig = r.rig;
  if (fs::exists(in / "observation.json")) {
    r.observation = vision::read_observation((in / "observation.json").string());
    r.photo_rig = capture::photo_rig(r.rig, r.observation.side_faces_left);
    r.side_mask = vision::side_photo_mask(r.observation, r.side.size());
  }
  if (fs::is_regular_file(in / "silhouette_front.png") &&
      fs::is_regular_file(in / "silhouette_side.png")) {
    r.front_silhouette =
        io::imread_accepted((in / "silhouette_front.png").string(), cv::IMREAD_GRAYSCALE);
    r.side_silhouette =
        io::imread_accepted((in / "silhouette_side.png").string(), cv::IMREAD_GRAYSCALE);
    if (r.front_silhouette.size() != r.front.size() || r.side_silhouette.size() != r.side.size())
      throw std::runtime_error(what +
                               ": silhouette_front.png / silhouette_side.png are unreadable "
                               "or not the photos' size");
  }
  if (fs::is_regular_file(in / "background_front.png")) {
    r.front_plate = io::imread_accepted((in / "background_front.png").string(), cv::IMREAD_COLOR);
    if (r.front_plate.size() != r.front.size())
      throw std::runtime_error(what +
                               ": background_front.png is unreadable or not the front "
                               "photo's size");
  }
  if (options.landmarks && fs::exists(in / "landmarks.json"))
    r.landmarks = read_landmarks((in / "landmarks.json").string());
  if (fs::is_regular_file(in / "report.json")) read_head_turn((in / "report.json").string(), r);
  return r;
}

capture::CameraModel ViewModel::camera(const capture::CameraModel& base, double yaw_deg,
                                       double pitch_deg) const {
  return capture::turned_camera(base, yaw_deg, pitch_deg, pivot);
}

ViewModel view_model(const Reconstruction& r, HeadExtent extent,
                     const model::HullOptions& hull_options) {
  ViewModel v;
  v.mesh = r.mesh;
  v.face_vertices = int(r.mesh.vertices.size());
  if (extent == HeadExtent::Face || r.front_silhouette.empty() || r.side_silhouette.empty())
    return v;
  const model::HeadHull hull =
      model::head_hull(r.front_silhouette, r.side_silhouette, r.photo_rig, r.mesh, hull_options);
  if (hull.mesh.triangles.empty()) return v;
  v.mesh = model::combined(r.mesh, hull.mesh);
  if (hull.pivot.allFinite()) v.pivot = hull.pivot;
  // The neck twists over its lower half, between the hull's lowest point (no turn) and halfway up
  // to the chin (the face mesh's lowest point; the head's full turn from there up) in a smooth
  // step. Twisting the whole neck up to the chin cost the real-photo judge two faces at 30 and
  // 45 degrees and the other side's shape (docs/views_accuracy.md).
  double chin = std::numeric_limits<double>::infinity(), bottom = chin;
  for (const Eigen::Vector3d& p : r.mesh.vertices) chin = std::min(chin, p.y());
  for (const Eigen::Vector3d& p : v.mesh.vertices) bottom = std::min(bottom, p.y());
  v.turn_weights.assign(v.mesh.vertices.size(), 1.0f);
  if (chin - bottom > 1)
    for (size_t i = size_t(v.face_vertices); i < v.mesh.vertices.size(); ++i) {
      const double u =
          std::clamp((v.mesh.vertices[i].y() - bottom) / (chin - bottom) / 0.5, 0.0, 1.0);
      v.turn_weights[i] = float(u * u * (3 - 2 * u));
    }
  return v;
}

std::optional<Eigen::Vector4d> mirror_plane(const Reconstruction& r) {
  const auto plane = model::mid_sagittal_plane(r.landmarks);
  if (!plane || r.report.head_turn_corrected || !std::isfinite(r.report.head_yaw_deg)) return plane;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& [name, p] : r.landmarks) centre += p;
  centre /= double(r.landmarks.size());
  const Eigen::Vector3d n = plane->head<3>();
  centre -= (n.dot(centre) - plane->w()) * n;  // onto the plane
  // The face turned by head_yaw_deg about the vertical (model::estimate_head_turn): its plane's
  // normal, seen from above, points head_yaw_deg from the x axis (toward -z for a positive turn).
  const double now = std::atan2(n.z(), n.x()), wanted = -r.report.head_yaw_deg * M_PI / 180;
  const Eigen::Vector3d turned = Eigen::AngleAxisd(now - wanted, Eigen::Vector3d::UnitY()) * n;
  return Eigen::Vector4d(turned.x(), turned.y(), turned.z(), turned.dot(centre));
}

std::unique_ptr<render::ViewSynthesizer> view_synthesizer(const Reconstruction& r,
                                                          HeadExtent extent) {
  return view_synthesizer(r, view_model(r, extent));
}

std::unique_ptr<render::ViewSynthesizer> view_synthesizer(const Reconstruction& r,
                                                          const ViewModel& model) {
  if (r.front.empty() || r.side.empty())
    throw std::invalid_argument("view_synthesizer: the reconstruction has no photos");
  auto synth = std::make_unique<render::ViewSynthesizer>(model.mesh, r.photo_rig, r.front, r.side);
  if (model.face_vertices < int(model.mesh.vertices.size()))  // the head hull follows the face
    synth->set_face_vertices(model.face_vertices);
  if (!model.turn_weights.empty()) synth->set_turn_weights(model.turn_weights);
  synth->set_photo_masks({}, r.side_mask);
  synth->set_mirror_plane(mirror_plane(r));  // nullopt without pairs
  return synth;
}

std::map<std::string, Eigen::Vector3d> read_landmarks(const std::string& path) {
  const nlohmann::json j = read_json_file(path);
  auto fail = [&](const std::string& what) { throw std::runtime_error(path + ": " + what); };
  if (!j.is_object()) fail(io::json_type_error("top level", "an object", j));
  if (!j.contains("landmarks")) fail("landmarks: missing");
  const nlohmann::json& landmarks = j["landmarks"];
  if (!landmarks.is_object()) fail(io::json_type_error("landmarks", "an object", landmarks));
  std::map<std::string, Eigen::Vector3d> out;
  for (const auto& [name, v] : landmarks.items()) {
    const std::string field = "landmarks." + name;
    if (!v.is_object()) fail(io::json_type_error(field, "an object", v));
    if (!v.contains("xyz_mm")) fail(field + ".xyz_mm: missing");
    const nlohmann::json& p = v["xyz_mm"];
    if (!p.is_array() || p.size() != 3)
      fail(io::json_type_error(field + ".xyz_mm", "an array of 3 numbers", p));
    try {
      for (int k = 0; k < 3; ++k)
        out[name][k] = io::json_number(p[k], field + ".xyz_mm[" + std::to_string(k) + "]");
    } catch (const std::invalid_argument& e) {
      fail(e.what());
    }
  }
  return out;
}

}  // namespace orthoface::reconstruct
