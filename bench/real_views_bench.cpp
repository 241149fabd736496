// real_views_bench: the real-photo judge (issue 14). Every FRMDB person in DIR (DIR/<id>/Img_33
// front, Img_53 side from the subject's right, Img_43 / Img_23 the real +-45 degree photos) is
// reconstructed from Img_33 + Img_53 through the product's pipeline (reconstruct::from_photos) and
// rendered at yaw +-15, +-30, +-45 the way `orthoface render` does. An independent landmarker,
// dlib's HOG face detector (one upsampling, the largest face) and its 68-point predictor
// (judge/face_judge.h), then says:
//   - whether a face is found in each view;
//   - the shape error (NME) at +-45 degrees: the view's eye points aligned by a similarity onto
//     the real photo's, the mean distance over jaw, nose and mouth points / the real outer-eye
//     distance; the photographed side against Img_43, the other side against Img_23; a view
//     without a face counts 1.0;
//   - identity at +-45 degrees: the face descriptor distance (vision::FaceDescriber, face-api.js's
//     recognition network) from the view to the real photo, where dlib finds both faces;
//   - the baseline: the front photo Img_33 itself scored the same way;
//   - the view from each source camera against its photo (PSNR where that photo sees the head);
//   - vision's front landmarks against the judge's on the front photo (eye and mouth corners,
//     brows: median and worst point / outer-eye distance, points not found).
// usage: real_views_bench DIR OUTDIR [--people 031,032] [--blend view|pick|weighted] [--view-gain
// G] [--camera-gain G] [--camera-power P] [--landmarker filters|network|consensus] [--no-float]
// [--unseen view|texture|front]
// [--no-equalize] [--head-turn MIN_DEG] [--turn-toward-side] [--no-flanks] [--flanks-max MM]
// [--flanks-below-max MM] [--flanks-blend MM] [--no-flank-bands] [--head face|whole
// (default)] [--background photo (default: the views composited into the front photo's scene, the
// head removed) | black] [--scene PHOTO: each person put in front of a scene photograph first
// (into_scene)]. JSON on stdout, Markdown on stderr, both in OUTDIR with one contact sheet per
// person (front | +-15 | +-45 | real
// +-45, dlib's points drawn). The pictures show real people: keep OUTDIR outside the repository.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/bench_report.h"
#include "io/json_text.h"
#include "judge/face_judge.h"
#include "judge/head_region.h"
#include "model/symmetry.h"
#include "reconstruct/reconstruction.h"
#include "render/contact_sheet.h"
#include "render/image_metrics.h"
#include "render/new_view.h"
#include "vision/face_descriptor.h"
#include "vision/foreground.h"

namespace {

using namespace orthoface;
using json = nlohmann::json;
namespace fs = std::filesystem;

constexpr int kYawsDeg[] = {15, 30, 45};
constexpr double kIdentical = 99;  // PSNR (dB) reported for identical pixels

// A square around the face (3 face boxes wide), or around the image centre without one.
cv::Rect head_crop(const cv::Mat& image, const std::optional<judge::FaceFound>& face) {
  const cv::Point c =
      face ? (face->box.tl() + face->box.br()) / 2 : cv::Point(image.cols / 2, image.rows / 2);
  const int half = face ? int(1.1 * face->box.width) : image.rows / 3;
  return cv::Rect(c.x - half, c.y - half, 2 * half, 2 * half) &
         cv::Rect(0, 0, image.cols, image.rows);
}

// Vision's front features against the judge's points where the definitions agree: eye corners,
// mouth corners, brows (dlib's on the brow's upper edge, ours on its middle).
struct LandmarkGroup {
  const char* name;
  std::vector<std::pair<const char*, int>> points;  // our feature, iBUG index
};
const LandmarkGroup kGroups[] = {{"eye_corners",
                                  {{"eye_right_outer", 36},
                                   {"eye_right_inner", 39},
                                   {"eye_left_inner", 42},
                                   {"eye_left_outer", 45}}},
                                 {"mouth_corners", {{"mouth_right", 48}, {"mouth_left", 54}}},
                                 {"brows",
                                  {{"brow_right_outer", 17},
                                   {"brow_right_center", 19},
                                   {"brow_right_inner", 21},
                                   {"brow_left_inner", 22},
                                   {"brow_left_center", 24},
                                   {"brow_left_outer", 26}}}};

using bench::median;

void draw_points(cv::Mat& image, const std::optional<judge::FaceFound>& face) {
  if (!face) {
    cv::putText(image, "no face", {10, 40}, cv::FONT_HERSHEY_SIMPLEX, 1.2, {0, 0, 255}, 2);
    return;
  }
  cv::rectangle(image, face->box, {0, 255, 255}, 1);
  for (const cv::Point2d& p : face->points) cv::circle(image, p, 2, {0, 255, 0}, cv::FILLED);
}

// Named points: a landmark of the model (vision/landmarks.h) and the iBUG points whose mean is
// the judge's on a real photo.
using NamedPoints = std::vector<std::pair<const char*, std::vector<int>>>;

// The view's eye corners and centres (the model's landmarks through the view's camera) and the
// judge's on a real photo: iBUG 36, 39, 42, 45 and the means of 36-41 / 42-47.
const NamedPoints kEyePoints = {{"eye_right_outer", {36}},
                                {"eye_right_inner", {39}},
                                {"eye_left_inner", {42}},
                                {"eye_left_outer", {45}},
                                {"eye_right_center", {36, 37, 38, 39, 40, 41}},
                                {"eye_left_center", {42, 43, 44, 45, 46, 47}}};

// Beside the eyes, points that fix the face's height too (the eyes lie nearly on one line, so an
// alignment by them alone scales by their spread, which is the sitter's turn as much as the
// head's size): the mouth corners (iBUG 48, 54) and the chin's lowest point (8).
const NamedPoints kShapePoints = [] {
  NamedPoints p = kEyePoints;
  p.insert(p.end(), {{"mouth_right", {48}}, {"mouth_left", {54}}, {"chin_bottom", {8}}});
  return p;
}();

// The judge's points of `list`, in its order.
std::vector<cv::Point2f> judge_points(const NamedPoints& list, const judge::Landmarks68& points) {
  std::vector<cv::Point2f> out;
  for (const auto& entry : list) {
    cv::Point2d mean(0, 0);
    for (int i : entry.second) mean += points[size_t(i)];
    out.push_back(mean / double(entry.second.size()));
  }
  return out;
}

std::vector<cv::Point2f> eye_points(const judge::Landmarks68& points) {
  return judge_points(kEyePoints, points);
}

// The similarity taking the view's pixels onto the real photo's by the points of `list` (the
// model's landmarks through the view's camera against the judge's); empty when the model lacks
// three of them.
cv::Mat view_to_real(const reconstruct::Reconstruction& rec, const capture::CameraModel& camera,
                     const judge::Landmarks68& real, const NamedPoints& list) {
  const std::vector<cv::Point2f> real_points = judge_points(list, real);
  std::vector<cv::Point2f> from, to;
  for (size_t k = 0; k < list.size(); ++k) {
    const auto it = rec.landmarks.find(list[k].first);
    if (it == rec.landmarks.end()) continue;
    const Eigen::Vector2d px = capture::project(camera, it->second);
    from.emplace_back(float(px.x()), float(px.y()));
    to.push_back(real_points[k]);
  }
  if (from.size() < 3) return {};
  return cv::estimateAffinePartial2D(from, to, cv::noArray(), cv::LMEDS);
}

struct Options {
  std::vector<std::string> people;  // empty: all
  render::Blend blend = render::SynthesisOptions{}.blend;
  double view_gain = render::SynthesisOptions{}.view_gain;
  double camera_gain = render::SynthesisOptions{}.camera_gain;
  double camera_power = render::SynthesisOptions{}.camera_power;
  vision::FrontLandmarker landmarker = vision::ObserveOptions{}.landmarker;
  bool float_textures = render::SynthesisOptions{}.float_textures;
  bool equalize = render::SynthesisOptions{}.equalize;
  render::UnseenSide unseen = render::SynthesisOptions{}.unseen;
  double min_head_turn_deg = reconstruct::ReconstructOptions{}.min_head_turn_deg;
  bool turn_toward_side = reconstruct::ReconstructOptions{}.turn_toward_side;
  bool fit_flanks = reconstruct::ReconstructOptions{}.fit_flanks;
  reconstruct::FlankDepthOptions flanks;
  reconstruct::HeadExtent head = reconstruct::HeadExtent::Whole;
  bool composite = true;  // views over the front photo's scene (else on black)
  std::string scene;      // a scene photograph the people are put in front of (empty: none)
};

// The person of a studio photo in front of `scene`: vision's own border-colour blob of the photo
// (head and body before FRMDB's plain curtain; dark hair on the dark curtain is lost with it),
// feathered by a pixel, over the scene scaled to cover the photo (mirrored for the side photo, so
// the two cameras see different parts of it).
cv::Mat into_scene(const cv::Mat& photo, const cv::Mat& scene, bool mirror) {
  const cv::Mat blob = vision::head_mask(vision::foreground_probability(photo, {}));
  if (blob.empty()) throw std::runtime_error("no person found to put in front of the scene");
  const double s = std::max(double(photo.cols) / scene.cols, double(photo.rows) / scene.rows);
  cv::Mat big, alpha, out;
  cv::resize(scene, big, cv::Size(), s * 1.05, s * 1.05, cv::INTER_AREA);
  if (mirror) cv::flip(big, big, 1);
  big = big(
      cv::Rect((big.cols - photo.cols) / 2, (big.rows - photo.rows) / 2, photo.cols, photo.rows));
  blob.convertTo(alpha, CV_32F, 1.0 / 255);
  cv::GaussianBlur(alpha, alpha, cv::Size(0, 0), 1.0);
  cv::Mat a3, p, b;
  cv::merge(std::vector<cv::Mat>{alpha, alpha, alpha}, a3);
  photo.convertTo(p, CV_32FC3);
  big.convertTo(b, CV_32FC3);
  cv::Mat mixed = p.mul(a3) + b.mul(cv::Scalar::all(1.0) - a3);
  mixed.convertTo(out, CV_8UC3);
  return out;
}

int run(const std::string& dir, const std::string& out_dir, const Options& opt) {
  if (!fs::is_directory(dir)) {
    std::cout << json{{"skipped", "no FRMDB folder at " + dir}}.dump() << "\n";
    return 0;
  }
  if (!judge::predictor_available()) {
    std::cout
        << json{{"skipped", std::string("no dlib predictor at ") + judge::kDefaultPredictor}}.dump()
        << "\n";
    return 0;
  }
  cv::Mat scene;
  if (!opt.scene.empty()) {
    scene = cv::imread(opt.scene);
    if (scene.empty()) throw std::invalid_argument("--scene: cannot read '" + opt.scene + "'");
  }
  fs::create_directories(out_dir);
  std::vector<std::string> people;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string id = e.path().filename();
    if (!e.is_directory() || !fs::exists(e.path() / "Img_33.JPG")) continue;
    if (opt.people.empty() || std::count(opt.people.begin(), opt.people.end(), id))
      people.push_back(id);
  }
  std::sort(people.begin(), people.end());
  const judge::FaceJudge judge;
  json res = json::array();
  int found[3] = {0, 0, 0}, views[3] = {0, 0, 0};  // per |yaw|
  double score_sum[3] = {0, 0, 0};       // the judge's detection confidence (FaceSearch::score)
  std::vector<double> landmark_err[3];   // per group, all points of all people
  double landmark_worst[3] = {0, 0, 0};  // per group, the worst point of any person
  int landmark_missing[3] = {0, 0, 0};   // points vision did not find (or only mirrored)
  double nme_sum[2] = {0, 0}, base_sum[2] = {0, 0}, psnr_front_min = INFINITY,
         psnr_side_min = INFINITY;
  int nme_n[2] = {0, 0}, better[2] = {0, 0}, compared[2] = {0, 0}, reconstructed = 0;
  int cut_out = 0;                    // pairs vision cut out of a busy background
  double iou_sum = 0, black_max = 0;  // whole-head silhouette IoU at +-45; pure-black share
  int iou_n = 0, wrong_size = 0;
  double iou_shape_sum = 0;  // the same IoU aligned by kShapePoints
  int iou_shape_n = 0;
  // Identity at +-45: face descriptor distance (vision::FaceDescriber) from the view to the real
  // photo, and from the front photo unrotated to it (the baseline), where dlib finds all three.
  double id_sum[2] = {0, 0}, id_base_sum[2] = {0, 0};
  int id_n[2] = {0, 0}, id_better[2] = {0, 0};
  const vision::FaceDescriber* describer = vision::shared_describer();
  if (!describer)
    std::cerr << "identity at 45 left out: no face-recognition weights in "
              << vision::default_model_dir() << " (scripts/fetch-face-model.sh)\n";
  double iou_base_sum = 0;  // the front photo's head, unrotated, against the same real heads
  int iou_base_n = 0;
  std::string md =
      "| person | faces found (+-15, +-30, +-45) | NME photographed side (baseline) | NME other "
      "side "
      "(baseline) | yaw 0 vs front PSNR | side yaw vs side PSNR |\n|---|---|---|---|---|---|\n";
  for (const std::string& p : people) {
    const fs::path d = fs::path(dir) / p;
    json r = {{"person", p}};
    try {
      cv::Mat front = cv::imread((d / "Img_33.JPG").string());
      cv::Mat side = cv::imread((d / "Img_53.JPG").string());
      const cv::Mat real_near = cv::imread((d / "Img_43.JPG").string());
      const cv::Mat real_far = cv::imread((d / "Img_23.JPG").string());
      if (front.empty() || side.empty() || real_near.empty() || real_far.empty())
        throw std::runtime_error("unreadable photo");
      if (!scene.empty())
        front = into_scene(front, scene, false), side = into_scene(side, scene, true);
      reconstruct::ReconstructOptions ro;
      ro.observe.side_camera = vision::SideCamera::Right;  // FRMDB's Img_53 (SOURCE.md)
      ro.observe.landmarker = opt.landmarker;
      ro.min_head_turn_deg = opt.min_head_turn_deg;
      ro.turn_toward_side = opt.turn_toward_side;
      ro.fit_flanks = opt.fit_flanks;
      ro.flanks = opt.flanks;
      const reconstruct::Reconstruction rec = reconstruct::from_photos(front, side, ro);
      ++reconstructed;
      for (const std::string& w : rec.report.warnings)
        if (w.find("busy background") != std::string::npos) {
          ++cut_out;
          break;
        }
      const capture::RigCalibration& rig = rec.photo_rig;
      const reconstruct::ViewModel model = reconstruct::view_model(rec, opt.head);
      const auto synth = reconstruct::view_synthesizer(rec, model);
      render::SynthesisOptions so;
      so.float_textures = opt.float_textures;
      so.equalize = opt.equalize;
      so.blend = opt.blend;
      so.view_gain = opt.view_gain;
      so.camera_gain = opt.camera_gain;
      so.camera_power = opt.camera_power;
      so.unseen = opt.unseen;
      // The photographed side: the yaw sign that turns the view toward the side camera.
      const double near_sign = capture::photographed_side_sign(rig);
      // Composited, the turned views twist the neck into the unturned body as `render` does;
      // the source cameras' own views (the reproduction below) do not.
      render::SynthesisOptions turned = so;
      if (opt.composite) turned.body_camera = rec.rig.front, turned.body_pivot = model.pivot;
      auto view = [&](double yaw_deg) {
        return synth->render(model.camera(rec.rig.front, yaw_deg, 0), turned);
      };
      r["photographed_side_yaw_sign"] = near_sign;
      r["head_yaw_deg"] = rec.report.head_yaw_deg;
      r["head_turn_corrected"] = rec.report.head_turn_corrected;
      r["flank_offset_mm"] = rec.report.flanks.offset_mm;
      r["flank_offset_below_mm"] = rec.report.flanks.offset_below_mm;
      r["flank_agreement_before"] = io::number_or_null(rec.report.flanks.agreement_before);
      r["flank_agreement_after"] = io::number_or_null(rec.report.flanks.agreement_after);

      // Reproduction at the source cameras: the view from the front camera against the front
      // photo, and from the side camera (raw colours: the side photo is otherwise mapped to the
      // front's) against the side photo, over the pixels the mesh covers.
      render::SynthesisOptions with_weights = so;
      with_weights.source_weights = true;
      const render::SynthesisResult v0 = synth->render(rig.front, with_weights);
      cv::Mat front_share;
      cv::extractChannel(v0.weights, front_share, 0);
      const cv::Mat front_sees = (front_share > 0) & v0.view.mask;  // the front photo sees it
      r["yaw0_pixels_not_from_front"] =
          1.0 - double(cv::countNonZero((front_share == 255) & v0.view.mask)) /
                    std::max(1, cv::countNonZero(v0.view.mask));
      render::SynthesisOptions raw = with_weights;
      raw.equalize = false;
      const render::SynthesisResult v90 = synth->render(rig.side, raw);
      cv::Mat side_share;
      cv::extractChannel(v90.weights, side_share, 1);
      const cv::Mat side_sees = (side_share > 0) & v90.view.mask;
      // Identical images have infinite PSNR: reported as kIdentical.
      const double psnr_front =
          std::min(render::psnr(rec.front, v0.view.image, front_sees), kIdentical);
      const double psnr_side =
          std::min(render::psnr(rec.side, v90.view.image, side_sees), kIdentical);
      cv::Mat error0;  // |yaw-0 view - front photo| x 4 where the mesh is drawn
      cv::absdiff(rec.front, v0.view.image, error0);
      error0 = error0 * 4;
      error0.setTo(cv::Scalar(60, 0, 0), v0.view.mask == 0);
      // The scene the views are composited into: the front photo, the head removed (inpainted).
      const reconstruct::ViewScene scene =
          opt.composite ? reconstruct::view_scene(rec, *synth, /*neck_twists=*/true)
                        : reconstruct::ViewScene{};
      psnr_front_min = std::min(psnr_front_min, psnr_front);
      psnr_side_min = std::min(psnr_side_min, psnr_side);
      r["psnr_yaw0_vs_front"] = psnr_front;
      r["psnr_side_yaw_vs_side"] = psnr_side;

      const auto real_near_face = judge.largest_face(real_near);
      const auto real_far_face = judge.largest_face(real_far);
      const auto front_face = judge.largest_face(front);
      // The real +-45 photos' heads (hair included), for the whole head's silhouette, and the
      // front photo's, shown unrotated (the baseline).
      cv::Mat front_head;
      if (front_face) {
        const cv::Rect box = front_face->box & cv::Rect(0, 0, front.cols, front.rows);
        if (box.width >= 4 && box.height >= 4)
          front_head = judge::head_region(front, box, &front_face->points);
      }
      cv::Mat real_head[2];
      for (int s = 0; s < 2; ++s) {
        const auto& f = s == 0 ? real_near_face : real_far_face;
        const cv::Mat& photo = s == 0 ? real_near : real_far;
        const cv::Rect box = f ? f->box & cv::Rect(0, 0, photo.cols, photo.rows) : cv::Rect();
        if (box.width >= 4 && box.height >= 4)
          real_head[s] = judge::head_region(photo, box, &f->points);
      }
      // Where the nose tip lies between the outer eye corners in each real photo (dlib's points
      // 30, 36, 45: 0 at the image-left corner, 1 at the other): the head's turn as the three
      // cameras saw it.
      nlohmann::json nose_between_eyes;
      for (const auto& [key, face] :
           {std::pair{"front", &front_face}, std::pair{"near", &real_near_face},
            std::pair{"far", &real_far_face}})
        if (*face)
          nose_between_eyes[key] = io::number_or_null(judge::nose_between_eyes((*face)->points));
      r["nose_between_eyes"] = nose_between_eyes;
      if (front_face) {  // vision's front landmarks against the judge's, / outer-eye distance
        const auto& d = front_face->points;
        const double iod = cv::norm(d[36] - d[45]);
        for (int g = 0; g < 3; ++g)
          for (const auto& [name, k] : kGroups[g].points) {
            const auto it = rec.observation.front.features.find(name);
            if (it == rec.observation.front.features.end() || it->second.mirrored) {
              ++landmark_missing[g];
              continue;
            }
            // Observation pixels have their centre at index + 0.5; dlib's points are indices.
            const double e = cv::norm(it->second.px - cv::Point2d(0.5, 0.5) - d[k]) / iod;
            landmark_err[g].push_back(e);
            landmark_worst[g] = std::max(landmark_worst[g], e);
            r["front_landmarks"][kGroups[g].name][name] = e;
          }
      }
      std::vector<render::Tile> tiles;
      cv::Mat shown = front.clone();
      draw_points(shown, front_face);
      const cv::Rect crop = head_crop(front, front_face);  // the views keep the front's framing
      tiles.push_back({shown(crop).clone(), p + " front (Img_33)"});
      std::string found_text;
      double nme[2] = {NAN, NAN}, base[2] = {NAN, NAN}, head_iou[2] = {NAN, NAN};
      const auto describe = [&](const cv::Mat& image, const auto& face) {
        return vision::FaceDescriptor(describer->describe(image, face->points));
      };
      std::optional<vision::FaceDescriptor> front_id;
      if (describer && front_face) front_id = describe(front, front_face);
      std::pair<cv::Mat, cv::Mat> real_outline[2];
      for (int k = 0; k < 3; ++k) {
        int n_found = 0;
        for (int side_k = 0; side_k < 2; ++side_k) {  // 0 photographed side, 1 other side
          const double yaw = kYawsDeg[k] * near_sign * (side_k == 0 ? 1 : -1);
          const render::SynthesisResult v = view(yaw);
          const cv::Mat image = opt.composite ? scene.composite(v.view) : v.view.image;
          if (opt.composite) {
            const double black = judge::black_fraction(image);
            black_max = std::max(black_max, black);
            r["black_fraction_max"] = std::max(r.value("black_fraction_max", 0.0), black);
            if (image.size() != front.size()) ++wrong_size;
          }
          const judge::FaceSearch looked = judge.search(image);
          const auto& face = looked.face;
          ++views[k];
          score_sum[k] += looked.score;
          if (face) ++found[k], ++n_found;
          r["found"][std::to_string(int(yaw))] = bool(face);
          r["face_score"][std::to_string(int(yaw))] = looked.score;
          if (kYawsDeg[k] == 30) continue;
          cv::Mat img = image.clone();
          draw_points(img, face);
          tiles.push_back({img(crop).clone(), cv::format("yaw %+d (%s)", int(yaw),
                                                         side_k == 0 ? "photographed" : "other")});
          if (kYawsDeg[k] != 45) continue;
          const auto& real_face = side_k == 0 ? real_near_face : real_far_face;
          if (!real_face) continue;  // dlib does not annotate this real photo: not scored
          if (!real_head[side_k].empty()) {
            const capture::CameraModel view_camera = model.camera(rec.rig.front, yaw, 0);
            const cv::Mat m = view_to_real(rec, view_camera, real_face->points, kEyePoints);
            // The same outline aligned by the face's height too (a diagnostic beside the
            // issue's eye-aligned figure).
            const cv::Mat ms = view_to_real(rec, view_camera, real_face->points, kShapePoints);
            if (!ms.empty()) {
              const double iou_shape =
                  judge::head_iou(v.view.mask, ms, real_head[side_k], real_face->points[8].y);
              iou_shape_sum += iou_shape, ++iou_shape_n;
              r["head_iou_45_shape_aligned"][side_k == 0 ? "photographed" : "other"] = iou_shape;
            }
            if (!m.empty()) {
              const double iou =
                  judge::head_iou(v.view.mask, m, real_head[side_k], real_face->points[8].y);
              iou_sum += iou, ++iou_n;
              head_iou[side_k] = iou;
              r["head_iou_45"][side_k == 0 ? "photographed" : "other"] = iou;
              if (!front_head.empty()) {
                const cv::Mat b = cv::estimateAffinePartial2D(eye_points(front_face->points),
                                                              eye_points(real_face->points),
                                                              cv::noArray(), cv::LMEDS);
                if (!b.empty()) {
                  const double base_iou =
                      judge::head_iou(front_head, b, real_head[side_k], real_face->points[8].y);
                  iou_base_sum += base_iou, ++iou_base_n;
                  r["baseline_head_iou_45"][side_k == 0 ? "photographed" : "other"] = base_iou;
                }
              }
              // The sheet's real photo shows both outlines: the real head (green), the view's
              // (red).
              cv::Mat carried;
              cv::warpAffine(v.view.mask, carried, m, real_head[side_k].size(), cv::INTER_NEAREST);
              real_outline[side_k] = {real_head[side_k].clone(), carried};
            }
          }
          if (front_id && face) {
            const vision::FaceDescriptor real_d =
                describe(side_k == 0 ? real_near : real_far, real_face);
            const double id = vision::descriptor_distance(describe(image, face), real_d);
            const double id_base = vision::descriptor_distance(*front_id, real_d);
            r["identity_45"][side_k == 0 ? "photographed" : "other"] = id;
            r["baseline_identity_45"][side_k == 0 ? "photographed" : "other"] = id_base;
            id_sum[side_k] += id, id_base_sum[side_k] += id_base, ++id_n[side_k];
            if (id < id_base) ++id_better[side_k];
          }
          nme[side_k] = judge::shape_nme_or_miss(face, real_face->points);
          base[side_k] = judge::shape_nme_or_miss(front_face, real_face->points);
        }
        found_text += (k ? ", " : "") + std::to_string(n_found) + "/2";
      }
      tiles.push_back({error0(crop).clone(), cv::format("yaw 0 error x4, %.1f dB", psnr_front)});
      for (int s = 0; s < 2; ++s) {
        const auto& real_face = s == 0 ? real_near_face : real_far_face;
        cv::Mat img = (s == 0 ? real_near : real_far).clone();
        draw_points(img, real_face);
        for (const auto& [mask, colour] :
             {std::pair{real_outline[s].first, cv::Scalar(0, 255, 0)},
              std::pair{real_outline[s].second, cv::Scalar(0, 0, 255)}}) {
          if (mask.empty()) continue;
          std::vector<std::vector<cv::Point>> contours;
          cv::findContours(mask.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
          cv::drawContours(img, contours, -1, colour, 2);
        }
        const cv::Rect real_crop = head_crop(img, real_face);
        if (!std::isnan(head_iou[s]))
          cv::putText(img, cv::format("head IoU %.2f", head_iou[s]),
                      {real_crop.x + 10, real_crop.y + real_crop.height - 20},
                      cv::FONT_HERSHEY_SIMPLEX, 1.0, {255, 255, 255}, 2);
        tiles.push_back({img(real_crop).clone(), s == 0 ? "real Img_43" : "real Img_23"});
        if (std::isnan(nme[s])) continue;
        nme_sum[s] += nme[s], base_sum[s] += base[s], ++nme_n[s], ++compared[s];
        if (nme[s] < base[s]) ++better[s];
      }
      r["nme"] = {{"photographed", nme[0]}, {"other", nme[1]}};
      r["baseline_nme"] = {{"photographed", base[0]}, {"other", base[1]}};
      // Order the sheet: front, +-15, +-45 (photographed first), the real photos last.
      render::ContactSheetOptions co;
      co.columns = 8;
      co.tile_width = 260;
      co.tile_height = 260;
      co.font_scale = 0.4;
      render::write_png(render::contact_sheet(tiles, co),
                        (fs::path(out_dir) / (p + "_judge.png")).string());
      md += cv::format("| %s | %s | %.3f (%.3f) | %.3f (%.3f) | %.1f dB | %.1f dB |\n", p.c_str(),
                       found_text.c_str(), nme[0], base[0], nme[1], base[1], psnr_front, psnr_side);
    } catch (const std::exception& e) {
      r["error"] = e.what();
      md += "| " + p + " | failed: " + std::string(e.what()) + " | | | | |\n";
    }
    std::cerr << p << "\n";
    res.push_back(r);
  }
  json out = {{"people", people.size()}, {"reconstructed", reconstructed}, {"results", res}};
  if (!opt.scene.empty()) {
    out["scene"] = {{"photo", opt.scene}, {"cut_out_of_the_scene", cut_out}};
    md += cv::format(
        "\nIn front of %s: %d of %zu pairs reconstructed, %d of them cut out of a busy "
        "background.\n",
        opt.scene.c_str(), reconstructed, people.size(), cut_out);
  }
  const auto mean_score = [&](int k) { return views[k] ? score_sum[k] / views[k] : NAN; };
  for (int k = 0; k < 3; ++k)
    out["faces_found"][std::to_string(kYawsDeg[k])] = {
        {"found", found[k]}, {"views", views[k]}, {"mean_score", mean_score(k)}};
  const char* side_name[2] = {"photographed", "other"};
  for (int s = 0; s < 2; ++s)
    if (nme_n[s] > 0)
      out["nme_45"][side_name[s]] = {{"mean", nme_sum[s] / nme_n[s]},
                                     {"baseline_mean", base_sum[s] / nme_n[s]},
                                     {"better_than_baseline", better[s]},
                                     {"scored", compared[s]}};
  for (int s = 0; s < 2; ++s)
    if (id_n[s] > 0)
      out["identity_45"][side_name[s]] = {{"mean", id_sum[s] / id_n[s]},
                                          {"baseline_mean", id_base_sum[s] / id_n[s]},
                                          {"better_than_baseline", id_better[s]},
                                          {"scored", id_n[s]}};
  out["psnr_yaw0_vs_front_min"] = psnr_front_min;
  if (iou_n > 0) out["head_iou_45"] = {{"mean", iou_sum / iou_n}, {"scored", iou_n}};
  if (iou_shape_n > 0)
    out["head_iou_45_shape_aligned"] = {{"mean", iou_shape_sum / iou_shape_n},
                                        {"scored", iou_shape_n}};
  if (iou_base_n > 0)
    out["baseline_head_iou_45"] = {{"mean", iou_base_sum / iou_base_n}, {"scored", iou_base_n}};
  if (opt.composite)
    out["composited"] = {{"black_fraction_max", black_max}, {"views_not_front_size", wrong_size}};
  out["front_landmarker"] = vision::front_landmarker_name(opt.landmarker);
  md += cv::format(
      "\nFront landmarks (%s) against the judge's, fraction of the outer-eye distance, "
      "median / worst:",
      vision::front_landmarker_name(opt.landmarker));
  for (int g = 0; g < 3; ++g) {
    out["front_landmarks"][kGroups[g].name] = {{"median", median(landmark_err[g])},
                                               {"worst", landmark_worst[g]},
                                               {"not_found", landmark_missing[g]}};
    md += cv::format(" %s %.3f / %.3f (%d not found);", kGroups[g].name, median(landmark_err[g]),
                     landmark_worst[g], landmark_missing[g]);
  }
  md += "\n";
  out["psnr_side_yaw_vs_side_min"] = psnr_side_min;
  md += cv::format("\nFaces found: +-15 %d/%d, +-30 %d/%d, +-45 %d/%d.\n", found[0], views[0],
                   found[1], views[1], found[2], views[2]);
  md += cv::format(
      "Face score (dlib's detection confidence of the best window, a face from 0, floor %.0f), "
      "mean: +-15 %.3f, +-30 %.3f, +-45 %.3f.\n",
      judge::kNoFaceScore, mean_score(0), mean_score(1), mean_score(2));
  for (int s = 0; s < 2; ++s)
    if (nme_n[s] > 0)
      md += cv::format(
          "NME at 45 (%s side): %.3f, baseline %.3f, better than the baseline on %d/%d.\n",
          side_name[s], nme_sum[s] / nme_n[s], base_sum[s] / nme_n[s], better[s], compared[s]);
  for (int s = 0; s < 2; ++s)
    if (id_n[s] > 0)
      md += cv::format(
          "Identity at 45 (%s side; face descriptor distance to the real photo, same person "
          "below about 0.55): %.3f, the front photo unrotated %.3f, closer on %d/%d.\n",
          side_name[s], id_sum[s] / id_n[s], id_base_sum[s] / id_n[s], id_better[s], id_n[s]);
  if (iou_n > 0)
    md += cv::format(
        "Head silhouette at 45 (eye-aligned, above the real chin) against GrabCut's head in the "
        "real photo: IoU %.3f mean over %d views (the front photo's head unrotated: %.3f over "
        "%d).\n",
        iou_sum / iou_n, iou_n, iou_base_n ? iou_base_sum / iou_base_n : NAN, iou_base_n);
  if (iou_shape_n > 0)
    md += cv::format(
        "The same aligned by the eyes, mouth corners and chin (the face's height fixes the "
        "scale): IoU %.3f mean over %d views.\n",
        iou_shape_sum / iou_shape_n, iou_shape_n);
  if (opt.composite)
    md += cv::format(
        "Composited views: pure black at most %.4f of a frame; %d not the front "
        "photo's size.\n",
        black_max, wrong_size);
  md += cv::format(
      "Yaw 0 vs the front photo where it sees the head: min PSNR %.1f dB (%.0f = "
      "identical); the side camera's view vs the side photo: min %.1f dB.\n",
      psnr_front_min, kIdentical, psnr_side_min);
  bench::write_report(out_dir, "real_views", out, md);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::string> pos;
    Options opt;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--people" && i + 1 < argc) {
        std::stringstream ss(argv[++i]);
        for (std::string id; std::getline(ss, id, ',');) opt.people.push_back(id);
      } else if (a == "--landmarker" && i + 1 < argc) {
        opt.landmarker = vision::parse_front_landmarker(argv[++i]);
      } else if (a == "--view-gain" && i + 1 < argc) {
        opt.view_gain = std::stod(argv[++i]);
      } else if (a == "--camera-gain" && i + 1 < argc) {
        opt.camera_gain = std::stod(argv[++i]);
      } else if (a == "--camera-power" && i + 1 < argc) {
        opt.camera_power = std::stod(argv[++i]);
      } else if (a == "--no-float") {
        opt.float_textures = false;
      } else if (a == "--no-equalize") {
        opt.equalize = false;
      } else if (a == "--unseen" && i + 1 < argc) {
        opt.unseen = render::parse_unseen_side(argv[++i]);
      } else if (a == "--no-flanks") {
        opt.fit_flanks = false;
      } else if (a == "--flanks-max" && i + 1 < argc) {
        opt.flanks.max_mm = std::stod(argv[++i]);
      } else if (a == "--flanks-below-max" && i + 1 < argc) {
        opt.flanks.below_max_mm = std::stod(argv[++i]);
      } else if (a == "--flanks-blend" && i + 1 < argc) {
        opt.flanks.blend_mm = std::stod(argv[++i]);
      } else if (a == "--no-flank-bands") {
        opt.flanks.bands = false;
      } else if (a == "--head-turn" && i + 1 < argc) {
        opt.min_head_turn_deg = std::stod(argv[++i]);
      } else if (a == "--turn-toward-side") {
        opt.turn_toward_side = true;
      } else if (a == "--head" && i + 1 < argc) {
        const std::string h = argv[++i];
        if (h != "face" && h != "whole") throw std::invalid_argument("--head: face or whole");
        opt.head = h == "face" ? reconstruct::HeadExtent::Face : reconstruct::HeadExtent::Whole;
      } else if (a == "--background" && i + 1 < argc) {
        const std::string b = argv[++i];
        if (b != "photo" && b != "black")
          throw std::invalid_argument("--background: photo or black");
        opt.composite = b == "photo";
      } else if (a == "--scene" && i + 1 < argc) {
        opt.scene = argv[++i];
      } else if (a == "--blend" && i + 1 < argc) {
        opt.blend = render::parse_blend(argv[++i]);
      } else {
        pos.push_back(a);
      }
    }
    if (pos.size() != 2) {
      std::cerr
          << "usage: real_views_bench DIR OUTDIR [--people 031,032] [--blend view|pick|weighted] "
             "[--view-gain G] [--camera-gain G] [--camera-power P] [--landmarker "
             "filters|network|consensus] [--no-float] [--unseen "
             "view|texture|front] [--no-equalize] [--head-turn MIN_DEG] [--turn-toward-side] "
             "[--no-flanks] [--flanks-max MM] [--flanks-below-max MM] [--flanks-blend MM] "
             "[--no-flank-bands] [--head face|whole] "
             "[--background photo|black] [--scene PHOTO]\n";
      return 2;
    }
    return run(pos[0], pos[1], opt);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
