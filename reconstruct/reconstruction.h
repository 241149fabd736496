// The photo-pair pipeline: front + side photos -> observation (vision) -> stereo -> adapted mesh
// (model), and the reconstruction folder, written and read here only.
#pragma once

#include <array>

#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "model/adapt.h"
#include "model/head_hull.h"
#include "model/stereo.h"
#include "reconstruct/flank_depth.h"
#include "vision/observation.h"
#include "vision/observe.h"
#include "vision/pair_check.h"

namespace orthoface::render {
class ViewSynthesizer;
struct RenderResult;
}  // namespace orthoface::render

namespace orthoface::reconstruct {

// Without a rig file the scale comes from this: the front silhouette's width at eye height is
// taken to be the generic head's width there (model::generic_half_width, about 150 mm), and the
// side photo is matched to the front by its midline features (scale and row offset).
struct ReconstructOptions {
  std::optional<capture::RigCalibration> rig;  // calibrated / simulated rig; none = ideal rig
  vision::ObserveOptions observe;              // includes --side-camera
  model::StereoOptions stereo;
  model::AdaptOptions adapt;  // --method, --k
  // A head turned in the front photo away from the side camera by at least this much (degrees,
  // model::estimate_head_turn) is modelled facing front and turned back; smaller turns are taken
  // as frontal. Negative: never (seed 004's frontal front photo). A head turned toward the side
  // camera is taken as frontal unless `turn_toward_side`: turning it back lost on real photos
  // (docs/views_accuracy.md).
  double min_head_turn_deg = 5;
  bool turn_toward_side = false;
  // The input check (vision/pair_check.h) before modelling: a failed check refuses the pair
  // (InputRefused) unless `force`, which models it with the failures in the report's warnings.
  bool check_input = true;
  bool force = false;
  // With check_input, also the same_person_face check after modelling: the front photo's face
  // against the model's views at 45-65 degrees (reconstruct/identity.h; limit
  // input_limits.max_face_distance). About 0.9 s a pair; off by default. Needs the
  // face-recognition weights (scripts/fetch-face-model.sh): from_photos throws
  // std::runtime_error without them.
  bool check_identity = false;
  vision::PairCheckLimits input_limits;
  // The face's flanks set back to where the two photos agree (reconstruct/flank_depth.h);
  // false keeps the adapted mesh as it is.
  bool fit_flanks = true;
  FlankDepthOptions flanks;
  void check() const;  // throws std::invalid_argument
};

// A pair the input check refused: what() is "input check NAME: problem"; check names the check
// (docs/input_check.md). The command line exits with kExitInputRefused.
class InputRefused : public std::invalid_argument {
 public:
  InputRefused(const std::string& check, const std::string& problem);
  const std::string& check() const { return check_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string check_, problem_;
};
inline constexpr int kExitInputRefused = 3;

struct ReconstructionReport {
  std::vector<std::pair<std::string, double>> stage_ms;  // in pipeline order
  std::vector<std::string> warnings;
  std::map<std::string, double> confidences;  // "front_boundary", "side_profile", "centre_line",
                                              // "feature:<name>"
  std::vector<std::string> features_found;    // observed landmark names with 3D data
  std::string scale_note;                     // where the scale came from
  std::string front_landmarker;               // the front features' detector that ran
  // The head's turn in the front photo (degrees, > 0 toward the subject's left), NaN when it
  // could not be estimated; head_turn_corrected when the model was built facing front.
  double head_yaw_deg = std::numeric_limits<double>::quiet_NaN();
  bool head_turn_corrected = false;
  int landmarks_used = 0, folds_fixed = 0, folds_remaining = 0;
  // Face vertices moved out to open a fin, and moved in onto the front silhouette
  // (model::AdaptOptions::open_fins, inside_silhouette).
  int fins_opened = 0, clamped_to_silhouette = 0;
  // The adapted mesh's displacement roughness and the share of it smoothed away
  // (model::AdaptOptions::smooth_iterations).
  double surface_roughness_mm = 0, surface_smoothed_share = 0;
  std::vector<vision::InputCheck> input_checks;  // empty when the check did not run
  // The side photo's scale to the front photo's height (1 when they share it; without a rig a
  // side photo of another height is rescaled and kept so in the reconstruction).
  double side_photo_scale = 1;
  // The flanks' offset (mm, > 0 back) and the two photos' agreement there before and after it
  // (reconstruct/flank_depth.h; its weights left empty); offset 0 and NaN agreements when it
  // did not run.
  FlankDepth flanks;
};

struct Reconstruction {
  vision::FaceObservation observation;
  mesh::TriMesh mesh;  // adapted base mesh, head frame mm; uvs into `texture` = the front photo
  std::map<std::string, Eigen::Vector3d> landmarks;  // head frame, mm
  capture::RigCalibration rig;  // the rig the model was built with (written as rig.yaml)
  // Where the photos were really taken (capture::photo_rig): the side camera on the side it
  // stood, for texturing from the side photo as it is.
  capture::RigCalibration photo_rig;
  cv::Mat front, side;  // the photos used
  cv::Mat side_mask;    // the subject's side of vision's profile (vision::profile_mask); empty
                        // when the observation has no profile for the side photo
  // The subject's silhouettes (CV_8U 0 / 255, vision's head blobs of the photos used): the whole
  // head and neck around the face mesh (model::head_hull). Empty when vision found none or the
  // folder predates them.
  cv::Mat front_silhouette, side_silhouette;
  // The front camera's empty scene (a clean plate) when one was given: a composited view's
  // background where the head is removed. Empty otherwise.
  cv::Mat front_plate;
  ReconstructionReport report;
};

// Front + side photos -> observation (vision) -> input check -> stereo -> adapted mesh with the
// front photo as texture. Without a rig, a side photo of another height is first rescaled to the
// front photo's (report.side_photo_scale). Throws InputRefused when the input check fails (without
// `force`), std::invalid_argument naming the input when the photos are unusable or the observation
// cannot be reconstructed (no silhouette / profile, inconsistent heights).
Reconstruction from_photos(const cv::Mat& front, const cv::Mat& side,
                           const ReconstructOptions& options = {});

// The same from an observation already made (e.g. sim::truth_observation); photos may be empty
// (then there is no texture).
Reconstruction from_observation(const vision::FaceObservation& observation, const cv::Mat& front,
                                const cv::Mat& side, const ReconstructOptions& options = {});

// Writes the reconstruction folder (DESIGN.md): head.obj head.mtl head.png (the textured model:
// render::inherit_texture, the same texture as `render --export`), front.png,
// side.png, rig.yaml, landmarks.json, observation.json, report.json, and when there are any
// silhouette_front.png / silhouette_side.png and background_front.png (the clean plate). Files are
// written into a hidden staging folder beside DIR (io::temp_path_for) and moved into DIR only when
// all succeeded. Throws std::runtime_error naming the file that failed (DIR is then untouched).
void write_reconstruction(const Reconstruction& reconstruction, const std::string& dir);

// Every file name write_reconstruction may write into the folder: what commands reading a folder
// must not overwrite with their own output.
inline constexpr std::array<const char*, 12> kFolderFiles = {"head.obj",
                                                             "head.mtl",
                                                             "head.png",
                                                             "front.png",
                                                             "side.png",
                                                             "rig.yaml",
                                                             "landmarks.json",
                                                             "observation.json",
                                                             "report.json",
                                                             "silhouette_front.png",
                                                             "silhouette_side.png",
                                                             "background_front.png"};

// The text of the report.json that write_reconstruction writes (JSON: scale, what was found with
// confidences, warnings, input check, stage timings, the mesh's size).
std::string report_json(const Reconstruction& reconstruction);

// A reconstruction folder read back: mesh (welded where the atlas split it; no uvs, no texture:
// views texture it from the photos), photos, rig,
// observation, the rig as the photos were taken and the side mask, landmarks when landmarks.json is
// there. The report is not read (report.json is for people). A folder without rig.yaml gets the
// ideal rig at 1.6 px/mm; without observation.json the side mask is empty and the side camera is
// taken to stand where the rig says. Throws std::runtime_error naming the folder and the file that
// is missing or unreadable.
struct ReadOptions {
  bool landmarks = true;  // read landmarks.json when it is there (false: leave it unread)
};
Reconstruction read_reconstruction(const std::string& dir, const ReadOptions& options = {});

// What a view shows of the subject: the face mesh alone (a mask), or the whole head and neck
// (model::head_hull from the silhouettes around the face mesh; the face alone when the
// reconstruction has no silhouettes or they hold no head).
enum class HeadExtent { Face, Whole };

// What a view draws (head frame, mm) for an extent, and where the head turns.
struct ViewModel {
  mesh::TriMesh mesh;     // the face mesh, then the head hull when there is one
  int face_vertices = 0;  // the face mesh's vertices come first
  // Views turn the head about this point (capture::turned_camera): the neck (model::HeadHull::
  // pivot), so the turned head stays over the body; the head frame's origin without a hull.
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  // How much each vertex turns with the head (render::ViewSynthesizer::set_turn_weights): 1 from
  // halfway between the hull's lowest point and the face's lowest point up, easing to 0 at the
  // hull's lowest point, so that with the body's camera (render::SynthesisOptions::body_camera)
  // the neck twists and meets the unturned body. Empty without a hull.
  std::vector<float> turn_weights;
  // The camera of a new view at yaw / pitch (degrees, capture::camera_at's convention): `base`
  // (e.g. the front camera, rescaled to the output) turned about the pivot.
  capture::CameraModel camera(const capture::CameraModel& base, double yaw_deg,
                              double pitch_deg) const;
};
// `hull` sets how finely the head hull is sliced (the live view takes a coarser one: every
// triangle is drawn three times a frame there).
ViewModel view_model(const Reconstruction& reconstruction, HeadExtent extent,
                     const model::HullOptions& hull = {});

// The face's mid-sagittal plane for the side never photographed (model::mid_sagittal_plane of
// the landmarks; nullopt without left / right pairs). A head modelled facing the front camera
// though it was turned (report.head_yaw_deg measured, head_turn_corrected false: a turn toward
// the side camera) has landmarks that hold little of the turn, so their plane is turned about
// the vertical through the landmarks' centre until, seen from above, it lies at the measured
// turn (the landmarks' own small angle replaced, not added to): mirrored through their plane, a
// view toward the unseen side showed the face nearly frontal where the real head is seen at the
// view's angle plus its turn.
std::optional<Eigen::Vector4d> mirror_plane(const Reconstruction& reconstruction);

// A view synthesizer loaded with the reconstruction: the model's mesh (its face vertices marked),
// both photos where they were taken, the side mask, and mirror_plane for the side never
// photographed. Throws std::invalid_argument when the photos are missing.
std::unique_ptr<render::ViewSynthesizer> view_synthesizer(const Reconstruction& reconstruction,
                                                          const ViewModel& model);
// The same for view_model(reconstruction, extent).
std::unique_ptr<render::ViewSynthesizer> view_synthesizer(const Reconstruction& reconstruction,
                                                          HeadExtent extent = HeadExtent::Whole);

// The scene a composited view is drawn into (`render --background photo`): the front photo with
// the head and neck removed (render::head_removed: the reconstruction's clean plate, else
// inpainted) above where the neck meets the body, and the rows over which the view's neck fades
// into the photo's own (the body does not turn with the head).
struct ViewScene {
  cv::Mat background;  // 8-bit BGR
  cv::Mat removed;     // CV_8U: where the head was removed and `background` filled in
  double fade_from_row = std::numeric_limits<double>::infinity();
  double fade_to_row = std::numeric_limits<double>::infinity();
  // `view` (of the scene's size and framing) drawn into the scene.
  cv::Mat composite(const render::RenderResult& view) const;
  // The same over `frame` (a later photo from the same camera, e.g. a live frame) with the
  // removed region taken from the scene: the body moves, the head's place stays filled. Within
  // `keep_px` pixels outside the view's head the frame's own pixels stay instead: the real
  // head's edge where the model's hull falls short of it, and the real scene rather than a fill.
  // Throws std::invalid_argument for a frame of another size or type, or a negative keep_px.
  cv::Mat composite(const render::RenderResult& view, const cv::Mat& frame, int keep_px = 0) const;
  // The scene scaled into a width x height frame as render::fitted does.
  ViewScene fitted(int width, int height) const;
};
// The scene of the front photo's own camera for `synth` (loaded with this reconstruction);
// `neck_twists`: the views drawn into it turn the neck back into the body
// (render::SynthesisOptions::body_camera), so they fade into the photo lower down. Throws
// std::invalid_argument when the reconstruction has no front photo.
ViewScene view_scene(const Reconstruction& reconstruction, render::ViewSynthesizer& synth,
                     bool neck_twists = false);

// The named landmarks of a landmarks.json that write_reconstruction wrote (head frame, mm).
// Throws std::runtime_error naming the file when it cannot be read or is malformed.
std::map<std::string, Eigen::Vector3d> read_landmarks(const std::string& path);

}  // namespace orthoface::reconstruct
