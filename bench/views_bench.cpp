// views_bench: quality of new views by texture inheritance (seed 004 §6, issue 5).
//   views_bench sim [SUBJECTS] [OUTDIR]  simulated subjects (seeds 0..N-1, default 20, ideal rig
//                                        640x480) and the Lee Perry-Smith scan (ideal and
//                                        perspective rig) when ../shared/data has it: PSNR / SSIM
//                                        inside the face mask at yaw 15..75 against the true
//                                        view; JSON on stdout, Markdown on stderr; OUTDIR gets
//                                        views_accuracy.{json,md} and error pictures at 45 deg
//   real photos are judged by real_views_bench (an independent landmarker, dlib)
//   --no-photo-masks (last argument)     texture without the side photo's profile mask
// Every subject goes through the demo's pipeline (reconstruct::from_photos: vision -> stereo -> eq.
// 2 with the rig the station believes). The same photos texture four meshes: the TRUE head (upper
// bound: only texturing error left), the adapted mesh, the Procrustes fit of the base mesh to
// the same 3D targets and the unadapted base mesh (model/adapt.h), each with `pick` and
// `view`, `pick` and `weighted` blending (render/new_view.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include "bench/bench_report.h"

#include "model/adapt.h"
#include "model/base_mesh.h"
#include "model/stereo.h"
#include "reconstruct/reconstruction.h"
#include "render/contact_sheet.h"
#include "render/image_metrics.h"
#include "render/new_view.h"
#include "render/renderer.h"
#include "sim/face_mask.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "sim/scan.h"
#include "vision/observe.h"

namespace {

using namespace orthoface;
using json = nlohmann::json;
namespace fs = std::filesystem;

// The side photo's subject mask from vision's profile (ViewSynthesizer::set_photo_masks); off
// with --no-photo-masks to measure what it changes.
bool g_photo_masks = true;
// The front landmarker of the pipeline (--landmarker filters|network|consensus).
vision::FrontLandmarker g_landmarker = vision::ObserveOptions{}.landmarker;

constexpr double kYawsDeg[] = {15, 30, 45, 60, 75};
constexpr int kNumYaws = 5;
constexpr int kHeadlineYaw = 2;  // index of 45 deg
const char* const kMeshNames[] = {"true mesh", "adapted", "Procrustes", "unadapted"};
constexpr int kNumMeshes = 4;
const char* const kBlendNames[] = {"view", "pick", "weighted"};
constexpr int kNumBlends = 3;
// Where an uncovered face-mask pixel lies on the true head: height bands between landmarks, on
// the side turned away from the camera (far) or toward it (near).
const char* const kRegionNames[] = {"far forehead",    "far brow..nose tip", "far nose tip..mouth",
                                    "far mouth..chin", "under the chin",     "near side"};
constexpr int kNumRegions = 6;

mesh::TriMesh bare(const mesh::TriMesh& m) {
  mesh::TriMesh b;
  b.vertices = m.vertices;
  b.triangles = m.triangles;
  return b;
}

// The four meshes of one reconstruction (index as kMeshNames).
std::array<mesh::TriMesh, kNumMeshes> meshes(const mesh::TriMesh& truth,
                                             const reconstruct::Reconstruction& r) {
  static const model::BaseMesh base = model::base_mesh();
  const model::StereoData data = model::stereo_match(r.observation, r.rig);  // as the pipeline
  return {bare(truth), bare(r.mesh), bare(model::procrustes_fit(base, data)), bare(base.mesh)};
}

// score[mesh][blend][yaw]
struct Scores {
  double psnr[kNumMeshes][kNumBlends][kNumYaws] = {};
  double ssim[kNumMeshes][kNumBlends][kNumYaws] = {};
  double uncovered[kNumMeshes][kNumBlends][kNumYaws] = {};  // share of the face mask
  double psnr_covered[kNumMeshes][kNumBlends][kNumYaws] =
      {};  // PSNR where the mesh covers the mask
  // 45 deg, pick: uncovered face-mask pixels by where they lie on the true head (kRegionNames),
  // as shares of the face mask; has_regions false when the head lacks the landmarks.
  double uncovered_region[kNumMeshes][kNumRegions] = {};
  bool has_regions = false;
  // The whole head as `render` draws it (reconstruct::view_model, view blend) against the true
  // head down to 30 mm below the chin: silhouette IoU, PSNR and SSIM over the true head; NaN
  // without a chin landmark.
  double head_iou[kNumYaws] = {}, head_psnr[kNumYaws] = {}, head_ssim[kNumYaws] = {};
};

struct SubjectResult {
  std::string label;
  bool ok = false;
  std::string error;
  Scores s;
};

cv::Mat abs_error_image(const cv::Mat& truth, const cv::Mat& view, const cv::Mat& mask) {
  cv::Mat d;
  cv::absdiff(truth, view, d);
  d.convertTo(d, CV_8U, 4.0);  // x4 so that 10 grey levels show
  cv::Mat out(d.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  d.copyTo(out, mask);
  return out;
}

// The true head drawn with its head-frame position as colour (2 mm per grey level, +-255 mm),
// so each pixel of a view tells which surface point it shows. Unlit (render/renderer.h).
render::RenderResult position_view(const sim::Head& head, const capture::CameraModel& camera,
                                   render::Renderer& renderer) {
  mesh::TriMesh m;
  m.vertices = head.mesh.vertices;
  m.triangles = head.mesh.triangles;
  for (const auto& v : m.vertices)
    m.colors.push_back(((v + Eigen::Vector3d::Constant(255)) / 510).cwiseMax(0).cwiseMin(1));
  return renderer.render(m, camera);
}

bool has_region_landmarks(const sim::Head& head) {
  for (const char* n : {"brow_left_center", "nose_tip", "mouth_left", "chin_bottom"})
    if (!head.landmarks.count(n)) return false;
  return true;
}

// Shares of the face mask that `uncovered` holds in each of kRegionNames; `positions` from
// position_view, yaw > 0 turns the camera toward +x (so -x is the far side).
std::array<double, kNumRegions> uncovered_by_region(const sim::Head& head, const cv::Mat& positions,
                                                    const cv::Mat& uncovered, const cv::Mat& mask,
                                                    double yaw_rad) {
  const double bands[] = {head.landmarks.at("brow_left_center").y(),
                          head.landmarks.at("nose_tip").y(), head.landmarks.at("mouth_left").y(),
                          head.landmarks.at("chin_bottom").y()};
  std::array<double, kNumRegions> share{};
  const double n = std::max(1, cv::countNonZero(mask));
  for (int r = 0; r < uncovered.rows; ++r)
    for (int c = 0; c < uncovered.cols; ++c) {
      if (!uncovered.at<uchar>(r, c)) continue;
      const cv::Vec3b bgr = positions.at<cv::Vec3b>(r, c);
      const double x = 2.0 * bgr[2] - 255, y = 2.0 * bgr[1] - 255;
      int region = 0;
      while (region < 4 && y <= bands[region]) ++region;
      if (region < 4 && x * yaw_rad > 0) region = 5;
      share[region] += 1 / n;
    }
  return share;
}

// Scores::head_* for reconstruction `r` of `head`; `truths` are its true views at kYawsDeg.
// With `picture`: truth, view and error at 45 deg written there.
void whole_head_scores(const sim::Head& head, const sim::RigOptions& options,
                       const reconstruct::Reconstruction& r,
                       const std::vector<render::RenderResult>& truths, Scores& s,
                       const std::string& picture) {
  const auto chin = head.landmarks.find("chin_bottom");
  const reconstruct::ViewModel whole = reconstruct::view_model(r, reconstruct::HeadExtent::Whole);
  const auto synth = reconstruct::view_synthesizer(r, whole);
  for (int y = 0; y < kNumYaws; ++y) {
    if (chin == head.landmarks.end()) {
      s.head_iou[y] = s.head_psnr[y] = s.head_ssim[y] = NAN;
      continue;
    }
    const double yaw = kYawsDeg[y] * M_PI / 180;
    const render::RenderResult& truth = truths[size_t(y)];
    const capture::CameraModel camera = sim::true_view_camera(options, yaw, 0);
    render::SynthesisOptions so;
    so.background = options.background_bgr;
    so.depth = false;
    const render::RenderResult view = synth->render(camera, so).view;
    const double bottom = capture::project(camera, chin->second - Eigen::Vector3d(0, 30, 0)).y();
    cv::Mat head_rows = cv::Mat::zeros(truth.mask.size(), CV_8U);
    head_rows.rowRange(0, std::clamp(int(bottom), 0, head_rows.rows)).setTo(255);
    const cv::Mat t = truth.mask & head_rows, v = view.mask & head_rows;
    s.head_iou[y] = double(cv::countNonZero(t & v)) / std::max(1, cv::countNonZero(t | v));
    s.head_psnr[y] = render::psnr(truth.image, view.image, t);
    s.head_ssim[y] = render::ssim(truth.image, view.image, t);
    if (y == kHeadlineYaw && !picture.empty()) {
      const cv::Rect box = cv::boundingRect(t | v);
      render::ContactSheetOptions o;
      o.columns = 3;
      render::write_png(
          render::contact_sheet(
              {{truth.image(box), "truth yaw 45"},
               {view.image(box),
                cv::format("whole head: IoU %.3f, %.1f dB", s.head_iou[y], s.head_psnr[y])},
               {abs_error_image(truth.image, view.image, t)(box), "|error| x4 over the true head"}},
              o),
          picture);
    }
  }
}

// One simulated or scanned subject through the rig, the pipeline and the four meshes.
SubjectResult run_subject(const sim::Head& head, const std::string& label,
                          const sim::RigOptions& options, render::Renderer& renderer,
                          const std::string& picture) {
  SubjectResult out;
  out.label = label;
  const sim::Capture cap = sim::simulate_capture(head, options, renderer);
  reconstruct::ReconstructOptions ro;
  ro.rig = cap.nominal_rig;
  ro.observe.landmarker = g_landmarker;
  reconstruct::Reconstruction r;
  try {
    r = reconstruct::from_photos(cap.front, cap.side, ro);
  } catch (const std::exception& e) {
    out.error = e.what();
    return out;
  }
  const auto m = meshes(head.mesh, r);
  render::ViewSynthesizer synth(m[0], r.photo_rig, r.front, r.side);
  if (g_photo_masks) synth.set_photo_masks({}, r.side_mask);
  std::vector<render::Tile> tiles;
  std::vector<render::RenderResult> truths;
  for (int y = 0; y < kNumYaws; ++y) {
    const double yaw = kYawsDeg[y] * M_PI / 180;
    truths.push_back(sim::true_view(head, options, yaw, 0, renderer));
    const render::RenderResult& truth = truths.back();
    const capture::CameraModel camera = sim::true_view_camera(options, yaw, 0);
    const cv::Mat mask =
        sim::has_face_landmarks(head) ? sim::face_mask(head, camera, renderer) : truth.mask;
    const bool regions = y == kHeadlineYaw && has_region_landmarks(head);
    const cv::Mat positions = regions ? position_view(head, camera, renderer).image : cv::Mat();
    out.s.has_regions = out.s.has_regions || regions;
    for (int k = 0; k < kNumMeshes; ++k) {
      synth.set_mesh(m[k]);
      for (int b = 0; b < kNumBlends; ++b) {
        render::SynthesisOptions so;
        so.blend = render::parse_blend(kBlendNames[b]);
        so.background = options.background_bgr;
        so.depth = false;
        const render::RenderResult rendered = synth.render(camera, so).view;
        const cv::Mat& view = rendered.image;
        out.s.psnr[k][b][y] = render::psnr(truth.image, view, mask);
        // Diagnostic only (the score above is the metric): face-mask pixels the mesh does not
        // cover (geometry: silhouette / extent), and PSNR over the covered ones.
        const cv::Mat covered = mask & rendered.mask;
        out.s.uncovered[k][b][y] = 1.0 - double(cv::countNonZero(covered)) / cv::countNonZero(mask);
        out.s.psnr_covered[k][b][y] =
            cv::countNonZero(covered) ? render::psnr(truth.image, view, covered) : 0.0;
        out.s.ssim[k][b][y] = render::ssim(truth.image, view, mask);
        if (regions && b == 0) {
          const auto share = uncovered_by_region(head, positions, mask & ~rendered.mask, mask, yaw);
          std::copy(share.begin(), share.end(), out.s.uncovered_region[k]);
        }
        if (y == kHeadlineYaw && b == 0 && !picture.empty()) {
          char text[96];
          std::snprintf(text, sizeof text, "%s pick: %.1f dB %.3f", kMeshNames[k],
                        out.s.psnr[k][b][y], out.s.ssim[k][b][y]);
          tiles.push_back({truth.image, label + ": truth yaw 45"});
          tiles.push_back({view, text});
          tiles.push_back({abs_error_image(truth.image, view, mask), "|error| x4 in face mask"});
        }
      }
    }
    synth.set_mesh(m[0]);
  }
  whole_head_scores(head, options, r, truths, out.s,
                    picture.empty() ? "" : picture.substr(0, picture.size() - 4) + "_whole.png");
  if (!picture.empty()) {
    render::ContactSheetOptions o;
    o.columns = 3;  // per mesh: truth, synthesized view, error
    o.tile_width = 300;
    o.tile_height = 300;
    o.font_scale = 0.38;
    cv::Rect box = cv::boundingRect(cap.front_mask);
    for (auto& t : tiles) {
      const int pad = 20;
      const cv::Rect crop = cv::Rect(0, 0, t.image.cols, t.image.rows) &
                            cv::Rect(t.image.cols / 2 - box.width * 3 / 4 - pad, box.y - pad,
                                     box.width * 3 / 2 + 2 * pad, box.height + 2 * pad);
      t.image = t.image(crop).clone();
    }
    render::write_png(render::contact_sheet(tiles, o), picture);
  }
  out.ok = true;
  return out;
}

json scores_json(const Scores& s) {
  json j;
  for (int k = 0; k < kNumMeshes; ++k)
    for (int b = 0; b < kNumBlends; ++b)
      for (int y = 0; y < kNumYaws; ++y)
        j[kMeshNames[k]][kBlendNames[b]].push_back({{"yaw_deg", kYawsDeg[y]},
                                                    {"psnr_db", s.psnr[k][b][y]},
                                                    {"ssim", s.ssim[k][b][y]},
                                                    {"uncovered_share", s.uncovered[k][b][y]},
                                                    {"psnr_covered_db", s.psnr_covered[k][b][y]}});
  for (int y = 0; y < kNumYaws; ++y)
    j["whole_head"].push_back({{"yaw_deg", kYawsDeg[y]},
                               {"iou", s.head_iou[y]},
                               {"psnr_db", s.head_psnr[y]},
                               {"ssim", s.head_ssim[y]}});
  if (s.has_regions)
    for (int k = 0; k < kNumMeshes; ++k)
      for (int g = 0; g < kNumRegions; ++g)
        j["uncovered_by_region_45_pick"][kMeshNames[k]][kRegionNames[g]] = s.uncovered_region[k][g];
  return j;
}

// "| mesh | blend | 15 | 30 | ... |" with "mean (min)" cells for PSNR and SSIM.
std::string summary_table(const std::vector<SubjectResult>& all, json& summary) {
  std::string md =
      "| mesh | blend | metric | 15° | 30° | 45° | 60° | 75° "
      "|\n|---|---|---|---|---|---|---|---|\n";
  int n = 0;
  for (const auto& r : all) n += r.ok;
  if (n == 0) return md;
  for (int k = 0; k < kNumMeshes; ++k)
    for (int b = 0; b < kNumBlends; ++b)
      for (int metric = 0; metric < 2; ++metric) {
        md += std::string("| ") + kMeshNames[k] + " | " + kBlendNames[b] + " | " +
              (metric == 0 ? "PSNR dB" : "SSIM") + " |";
        for (int y = 0; y < kNumYaws; ++y) {
          double sum = 0, lo = 1e300;
          for (const auto& r : all) {
            if (!r.ok) continue;
            const double v = metric == 0 ? r.s.psnr[k][b][y] : r.s.ssim[k][b][y];
            sum += v, lo = std::min(lo, v);
          }
          const bool bold = k == 1 && y == kHeadlineYaw;
          md += cv::format(metric == 0 ? " %s%.1f (%.1f)%s |" : " %s%.3f (%.3f)%s |",
                           bold ? "**" : "", sum / n, lo, bold ? "**" : "");
          summary[kMeshNames[k]][kBlendNames[b]][metric == 0 ? "psnr_db" : "ssim"].push_back(
              {{"yaw_deg", kYawsDeg[y]}, {"mean", sum / n}, {"min", lo}});
        }
        md += "\n";
      }
  return md;
}

// The whole head, mean (min) over subjects per yaw: silhouette IoU, PSNR, SSIM.
std::string whole_head_table(const std::vector<SubjectResult>& all, json& summary) {
  std::string md = "| metric | 15° | 30° | 45° | 60° | 75° |\n|---|---|---|---|---|---|\n";
  const char* names[] = {"head-silhouette IoU", "PSNR dB (whole head)", "SSIM (whole head)"};
  for (int metric = 0; metric < 3; ++metric) {
    md += std::string("| ") + names[metric] + " |";
    for (int y = 0; y < kNumYaws; ++y) {
      double sum = 0, lo = 1e300;
      int n = 0;
      for (const auto& r : all) {
        const double v = metric == 0   ? r.s.head_iou[y]
                         : metric == 1 ? r.s.head_psnr[y]
                                       : r.s.head_ssim[y];
        if (!r.ok || !std::isfinite(v)) continue;
        sum += v, lo = std::min(lo, v), ++n;
      }
      if (n == 0) {
        md += " - |";
        continue;
      }
      md += cv::format(metric == 1 ? " %.1f (%.1f) |" : " %.3f (%.3f) |", sum / n, lo);
      summary["whole_head"][names[metric]].push_back(
          {{"yaw_deg", kYawsDeg[y]}, {"mean", sum / n}, {"min", lo}});
    }
    md += "\n";
  }
  return md;
}

// Mean over subjects at 45 deg, pick: share of the face mask the mesh leaves uncovered and
// PSNR over the covered part (where the error comes from: extent vs texture registration).
std::string coverage_table(const std::vector<SubjectResult>& all) {
  std::string md =
      "| mesh | uncovered face mask | PSNR where covered | PSNR (metric) |\n|---|---|---|---|\n";
  for (int k = 0; k < kNumMeshes; ++k) {
    double u = 0, pc = 0, p = 0;
    int n = 0;
    for (const auto& r : all)
      if (r.ok)
        u += r.s.uncovered[k][0][kHeadlineYaw], pc += r.s.psnr_covered[k][0][kHeadlineYaw],
            p += r.s.psnr[k][0][kHeadlineYaw], ++n;
    if (n)
      md += cv::format("| %s | %.1f %% | %.1f dB | %.1f dB |\n", kMeshNames[k], 100 * u / n, pc / n,
                       p / n);
  }
  return md;
}

// Mean over subjects at 45 deg, pick: where on the true head the uncovered face-mask pixels lie
// (share of the face mask per region of kRegionNames).
std::string region_table(const std::vector<SubjectResult>& all) {
  std::string md = "| mesh |";
  for (const char* r : kRegionNames) md += std::string(" ") + r + " |";
  md += "\n|---|";
  for (int g = 0; g < kNumRegions; ++g) md += "---|";
  md += "\n";
  for (int k = 0; k < kNumMeshes; ++k) {
    double sum[kNumRegions] = {};
    int n = 0;
    for (const auto& r : all) {
      if (!r.ok || !r.s.has_regions) continue;
      for (int g = 0; g < kNumRegions; ++g) sum[g] += r.s.uncovered_region[k][g];
      ++n;
    }
    if (n == 0) return "";
    md += std::string("| ") + kMeshNames[k] + " |";
    for (int g = 0; g < kNumRegions; ++g) md += cv::format(" %.2f %% |", 100 * sum[g] / n);
    md += "\n";
  }
  return md;
}

// Per subject at 45 deg, pick: PSNR / SSIM of each mesh.
std::string headline_table(const std::vector<SubjectResult>& all) {
  std::string md = "| subject |";
  for (const char* m : kMeshNames) md += std::string(" ") + m + " |";
  md += "\n|---|---|---|---|---|\n";
  for (const auto& r : all) {
    if (!r.ok) {
      md += "| " + r.label + " | failed: " + r.error + " | | | |\n";
      continue;
    }
    md += "| " + r.label + " |";
    for (int k = 0; k < kNumMeshes; ++k)
      md +=
          cv::format(" %.1f / %.3f |", r.s.psnr[k][0][kHeadlineYaw], r.s.ssim[k][0][kHeadlineYaw]);
    md += "\n";
  }
  return md;
}

int run_sim(int subjects, const std::string& out_dir) {
  if (subjects < 1) throw std::invalid_argument("sim: SUBJECTS must be >= 1");
  if (!out_dir.empty()) fs::create_directories(out_dir);
  render::Renderer renderer;
  const sim::RigOptions ideal;  // seed 004 rig, 640x480, 1.6 px/mm
  std::vector<SubjectResult> all;
  json out;
  for (int seed = 0; seed < subjects; ++seed) {
    const std::string picture = out_dir.empty() || seed > 2
                                    ? ""
                                    : out_dir + "/views_error_seed" + std::to_string(seed) + ".png";
    all.push_back(run_subject(sim::make_head(seed), "seed " + std::to_string(seed), ideal, renderer,
                              picture));
    std::cerr << all.back().label << (all.back().ok ? "" : ": failed " + all.back().error) << "\n";
    out["sim"]["per_subject"].push_back(
        {{"seed", seed},
         {"ok", all.back().ok},
         {"error", all.back().error},
         {"scores", all.back().ok ? scores_json(all.back().s) : json()}});
  }
  std::string md = "### Simulated subjects, seeds 0.." + std::to_string(subjects - 1) +
                   ", ideal rig 640x480 (mean (min) over subjects)\n\n";
  md += summary_table(all, out["sim"]["summary"]);
  md +=
      "\n### The whole head (head, hair, ears, neck to 30 mm below the chin; adapted mesh and "
      "head hull, view blend; mean (min) over subjects)\n\n" +
      whole_head_table(all, out["sim"]["summary"]);
  md += "\n### Where the error is, 45°, pick (mean over subjects)\n\n" + coverage_table(all);
  md +=
      "\nUncovered face mask by where it lies on the true head (far = the side turned away "
      "from the camera; bands between brow, nose tip, mouth corners and chin bottom):\n\n" +
      region_table(all);
  md += "\n### Per subject at 45°, pick (PSNR dB / SSIM)\n\n" + headline_table(all);
  int n_ok = 0;
  for (const auto& r : all) n_ok += r.ok;
  md += "\nReconstructed " + std::to_string(n_ok) + "/" + std::to_string(subjects) + ".\n";

  const fs::path scan_dir = fs::path(ORTHOFACE_DATA_DIR) / "lee_perry_smith_head";
  if (fs::is_directory(scan_dir)) {
    const sim::Head lps = sim::lee_perry_smith_head(scan_dir.string());
    std::vector<SubjectResult> scans;
    sim::RigOptions persp;
    persp.kind = sim::RigKind::Perspective;
    for (const auto& [name, rig] :
         {std::pair{"perspective rig", persp}, std::pair{"ideal rig", ideal}}) {
      const std::string picture =
          out_dir.empty() ? ""
                          : out_dir + "/views_error_lps_" + std::string(name).substr(0, 5) + ".png";
      scans.push_back(
          run_subject(lps, std::string("Lee Perry-Smith, ") + name, rig, renderer, picture));
      out["lee_perry_smith"][name] = {
          {"ok", scans.back().ok},
          {"error", scans.back().error},
          {"scores", scans.back().ok ? scores_json(scans.back().s) : json()}};
    }
    for (const auto& s : scans) {
      md += "\n### " + s.label + " (PSNR dB / SSIM)\n\n";
      if (!s.ok) {
        md += "failed: " + s.error + "\n";
        continue;
      }
      json unused;
      md += summary_table({s}, unused) + "\n" + coverage_table({s}) + "\n" +
            whole_head_table({s}, unused);
    }
  } else {
    md += "\n(Lee Perry-Smith scan not found in " + scan_dir.string() + ": skipped)\n";
  }
  bench::write_report(out_dir, "views_accuracy", out, md);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc > 1 && std::string(argv[argc - 1]) == "--no-photo-masks")
      g_photo_masks = false, --argc;
    if (argc > 2 && std::string(argv[argc - 2]) == "--landmarker")
      g_landmarker = vision::parse_front_landmarker(argv[argc - 1]), argc -= 2;
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "sim") return run_sim(argc > 2 ? std::stoi(argv[2]) : 20, argc > 3 ? argv[3] : "");
    std::cerr << "usage: views_bench sim [SUBJECTS] [OUTDIR] [--landmarker L] [--no-photo-masks]\n"
                 "(real photos: real_views_bench)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
