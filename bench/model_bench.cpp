// model_bench: speed of the adaptation and reconstruction accuracy on simulated subjects.
//   model_bench [--benchmark_...]            Google Benchmark (JSON): adapt() per call (target
//                                            <= 1 ms), Procrustes, stereo matching, base mesh
//   model_bench accuracy [SUBJECTS] [OUTDIR] relative error tables, k and landmark sweeps (JSON
//                                            on stdout, Markdown on stderr); OUTDIR gets
//                                            model_accuracy.{json,md} and model_sweeps.png
// The table is made twice: from the true masks and landmarks (sim/truth_observation.h: the model
// stage alone) and from vision::observe on the rendered photos (the whole pipeline). The k and
// landmark-count sweeps use the true observations. Ideal rig, subjects = make_head seeds 0..N-1.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include "bench/bench_report.h"

#include "model/adapt.h"
#include "model/evaluate.h"
#include "render/renderer.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "sim/truth_observation.h"
#include "vision/observe.h"

namespace {

using namespace orthoface;

struct Subject {
  int seed = 0;
  sim::Head head;
  model::StereoData data;         // from the true observation
  model::StereoData vision_data;  // from vision::observe on the rendered photos
  bool vision_ok = false;
  std::string vision_error;
  model::FaceRegion region;
};

Subject make_subject(int seed, render::Renderer& renderer) {
  Subject s;
  s.seed = seed;
  s.head = sim::make_head(seed);
  const sim::RigOptions rig_options;  // ideal rig
  const sim::Capture cap = sim::simulate_capture(s.head, rig_options, renderer);
  s.data = model::stereo_match(sim::truth_observation(cap), cap.nominal_rig);
  try {
    s.vision_data = model::stereo_match(vision::observe(cap.front, cap.side), cap.nominal_rig);
    s.vision_ok = true;
  } catch (const std::exception& e) {
    s.vision_error = e.what();
  }
  s.region = model::face_region(s.head.landmarks);
  return s;
}

double rel(const mesh::TriMesh& m, const Subject& s) {
  return model::reconstruction_error(m, s.head.mesh, s.region).relative;
}

// Order in which features are dropped for the landmark-count sweep (least important first).
const std::vector<std::string> kDropOrder = {
    "brow_left_outer",  "brow_right_outer",  "brow_left_inner",
    "brow_right_inner", "eye_left_inner",    "eye_right_inner",
    "cheek_left",       "cheek_right",       "alar_left",
    "alar_right",       "lip_lower",         "lip_upper",
    "brow_left_center", "brow_right_center", "eye_left_outer",
    "eye_right_outer",  "mouth_left",        "mouth_right",
    "nose_bridge",      "subnasale",         "chin",
    "eye_left_center",  "eye_right_center",  "forehead_top",
    "chin_bottom",      "nose_tip"};

void draw_plot(cv::Mat& img, cv::Rect area, const std::vector<double>& xs,
               const std::vector<double>& ys, const std::string& title, const std::string& xlabel) {
  cv::rectangle(img, area, cv::Scalar(0, 0, 0), 1);
  double lo = *std::min_element(ys.begin(), ys.end()), hi = *std::max_element(ys.begin(), ys.end());
  if (hi - lo < 1e-9) hi = lo + 1e-3;
  const double pad = 0.1 * (hi - lo);
  lo -= pad, hi += pad;
  auto to_px = [&](double x, double y) {
    return cv::Point(
        area.x + static_cast<int>((x - xs.front()) / (xs.back() - xs.front()) * area.width),
        area.y + area.height - static_cast<int>((y - lo) / (hi - lo) * area.height));
  };
  for (size_t i = 0; i < xs.size(); ++i) {
    const cv::Point p = to_px(xs[i], ys[i]);
    cv::circle(img, p, 4, cv::Scalar(200, 60, 20), cv::FILLED, cv::LINE_AA);
    if (i) cv::line(img, to_px(xs[i - 1], ys[i - 1]), p, cv::Scalar(200, 60, 20), 2, cv::LINE_AA);
    cv::putText(img, cv::format("%g", xs[i]), {p.x - 6, area.y + area.height + 18},
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  }
  for (double f : {0.0, 0.5, 1.0}) {
    const double y = lo + f * (hi - lo);
    cv::putText(img, cv::format("%.3f%%", 100 * y), {area.x - 70, to_px(xs.front(), y).y + 4},
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  }
  cv::putText(img, title, {area.x, area.y - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.55,
              cv::Scalar(0, 0, 0));
  cv::putText(img, xlabel, {area.x + area.width / 2 - 60, area.y + area.height + 40},
              cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0));
}

// Google Benchmark: one observation (seed 3, ideal rig, true landmarks), built once.
const Subject& speed_subject() {
  static render::Renderer renderer;
  static const Subject s = make_subject(3, renderer);
  return s;
}

const model::BaseMesh& speed_base() {
  static const model::BaseMesh base = model::base_mesh();
  return base;
}

void BM_Adapt(benchmark::State& state) {
  const model::BaseMesh& base = speed_base();
  const Subject& s = speed_subject();
  model::AdaptOptions o;
  o.method = state.range(0) == 0 ? model::AdaptMethod::Nnwa : model::AdaptMethod::Interpolate;
  state.SetLabel(state.range(0) == 0 ? "nnwa" : "interpolate");
  for (auto _ : state) benchmark::DoNotOptimize(model::adapt(base, s.data, o));
  const model::AdaptResult r = model::adapt(base, s.data, o);
  state.counters["vertices"] = static_cast<double>(base.mesh.vertices.size());
  state.counters["landmarks"] = static_cast<double>(r.targets.vertices.size());
  state.counters["folds_fixed"] = r.folds_fixed;
  state.counters["target_ms"] = 1.0;
}

void BM_Procrustes(benchmark::State& state) {
  const model::BaseMesh& base = speed_base();
  const Subject& s = speed_subject();
  for (auto _ : state) benchmark::DoNotOptimize(model::procrustes_fit(base, s.data));
}

void BM_StereoMatch(benchmark::State& state) {
  static render::Renderer renderer;
  static const sim::Capture cap = sim::simulate_capture(sim::make_head(3), {}, renderer);
  static const vision::FaceObservation obs = sim::truth_observation(cap);
  for (auto _ : state) benchmark::DoNotOptimize(model::stereo_match(obs, cap.nominal_rig));
}

void BM_BaseMesh(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(model::base_mesh());
}

BENCHMARK(BM_Adapt)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Procrustes)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StereoMatch)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_BaseMesh)->Unit(benchmark::kMillisecond);

int run_benchmarks(int argc, char** argv) {
  std::vector<char*> args(argv, argv + argc);
  std::string json = "--benchmark_format=json";  // default; a later flag overrides it
  args.insert(args.begin() + 1, json.data());
  int n = static_cast<int>(args.size());
  benchmark::Initialize(&n, args.data());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

// The four reconstructions of seed 002 §4 on one subject: relative errors, as fractions.
struct MethodErrors {
  double nnwa = 0, interpolate = 0, procrustes = 0, unadapted = 0;
};

MethodErrors method_errors(const model::BaseMesh& base, const Subject& s,
                           const model::StereoData& data) {
  model::AdaptOptions nnwa, interp;
  nnwa.method = model::AdaptMethod::Nnwa;
  interp.method = model::AdaptMethod::Interpolate;
  MethodErrors e;
  e.nnwa = rel(model::adapt(base, data, nnwa).mesh, s);
  e.interpolate = rel(model::adapt(base, data, interp).mesh, s);
  e.procrustes = rel(model::procrustes_fit(base, data), s);
  e.unadapted = rel(base.mesh, s);
  return e;
}

// Per-subject table of the four methods for one landmark source, plus means and the
// NNWA-below-Procrustes count; `md` gets the same table in Markdown (percent).
nlohmann::json method_table(const model::BaseMesh& base, const std::vector<Subject>& all,
                            bool use_vision, std::string& md) {
  nlohmann::json table = nlohmann::json::array();
  MethodErrors sum;
  int beats = 0, n = 0;
  md += std::string("\n### Landmarks from ") + (use_vision ? "vision" : "ground truth") +
        " (relative error, %)\n\n| seed | NNWA | eq. 2 | Procrustes | unadapted |\n"
        "|---|---|---|---|---|\n";
  for (const Subject& s : all) {
    if (use_vision && !s.vision_ok) {
      table.push_back({{"seed", s.seed}, {"error", s.vision_error}});
      md += cv::format("| %d | failed: %s | | | |\n", s.seed, s.vision_error.c_str());
      continue;
    }
    const MethodErrors e = method_errors(base, s, use_vision ? s.vision_data : s.data);
    sum.nnwa += e.nnwa, sum.interpolate += e.interpolate;
    sum.procrustes += e.procrustes, sum.unadapted += e.unadapted;
    beats += e.nnwa < e.procrustes;
    ++n;
    table.push_back({{"seed", s.seed},
                     {"nnwa", e.nnwa},
                     {"interpolate", e.interpolate},
                     {"procrustes", e.procrustes},
                     {"unadapted", e.unadapted}});
    md += cv::format("| %d | %.3f | %.3f | %.3f | %.3f |\n", s.seed, 100 * e.nnwa,
                     100 * e.interpolate, 100 * e.procrustes, 100 * e.unadapted);
  }
  nlohmann::json o;
  o["per_subject_relative_error"] = table;
  if (n > 0) {
    o["mean_relative_error"] = {{"nnwa", sum.nnwa / n},
                                {"interpolate", sum.interpolate / n},
                                {"procrustes", sum.procrustes / n},
                                {"unadapted", sum.unadapted / n}};
    md += cv::format("| **mean** | **%.3f** | %.3f | %.3f | %.3f |\n", 100 * sum.nnwa / n,
                     100 * sum.interpolate / n, 100 * sum.procrustes / n, 100 * sum.unadapted / n);
  }
  o["nnwa_below_procrustes"] = std::to_string(beats) + "/" + std::to_string(n);
  o["reconstructed"] = std::to_string(n) + "/" + std::to_string(all.size());
  md += "\nNNWA below Procrustes on " + o["nnwa_below_procrustes"].get<std::string>() +
        " subjects; reconstructed " + o["reconstructed"].get<std::string>() + ".\n";
  return o;
}

// Mean NNWA relative error over the subjects (true landmarks) with the given options; also
// the mean number of base vertices that got 3D data.
std::pair<double, double> mean_nnwa(const model::BaseMesh& base, const std::vector<Subject>& all,
                                    const model::AdaptOptions& o) {
  double e = 0, landmarks = 0;
  for (const Subject& s : all) {
    const model::AdaptResult r = model::adapt(base, s.data, o);
    e += rel(r.mesh, s) / static_cast<double>(all.size());
    landmarks += static_cast<double>(r.targets.vertices.size()) / static_cast<double>(all.size());
  }
  return {e, landmarks};
}

int run_accuracy(int subjects, const std::string& out_dir) {
  if (subjects < 1) throw std::invalid_argument("accuracy: SUBJECTS must be >= 1");
  render::Renderer renderer;
  const model::BaseMesh base = model::base_mesh();
  std::vector<Subject> all;
  for (int seed = 0; seed < subjects; ++seed) all.push_back(make_subject(seed, renderer));
  nlohmann::json out;
  std::string md = "## Reconstruction accuracy, ideal rig, seeds 0.." +
                   std::to_string(subjects - 1) + " (model_bench accuracy)\n";
  out["landmarks_from_truth"] = method_table(base, all, false, md);
  out["landmarks_from_vision"] = method_table(base, all, true, md);
  std::vector<double> ks, k_err, counts, count_err;
  md += "\n### NNWA vs k (true landmarks, mean relative error %)\n\n| k | NNWA |\n|---|---|\n";
  for (int k = 1; k <= 10; ++k) {
    model::AdaptOptions o;
    o.method = model::AdaptMethod::Nnwa;
    o.k = k;
    const double e = mean_nnwa(base, all, o).first;
    ks.push_back(k), k_err.push_back(e);
    out["k_sweep"].push_back({{"k", k}, {"nnwa", e}});
    md += cv::format("| %d | %.4f |\n", k, 100 * e);
  }
  md +=
      "\n### NNWA vs named features used (true landmarks; silhouette and profile points "
      "always used)\n\n| features | 3D points | NNWA % |\n|---|---|---|\n";
  for (size_t drop = 0; drop <= kDropOrder.size(); drop += 2) {
    model::AdaptOptions o;
    o.method = model::AdaptMethod::Nnwa;
    o.ignored_features.assign(kDropOrder.begin(), kDropOrder.begin() + drop);
    const auto [e, landmarks] = mean_nnwa(base, all, o);
    const int features = static_cast<int>(kDropOrder.size() - drop);
    counts.insert(counts.begin(), features), count_err.insert(count_err.begin(), e);
    out["landmark_sweep"].push_back(
        {{"features", features}, {"landmarks_with_boundary", landmarks}, {"nnwa", e}});
    md += cv::format("| %d | %.1f | %.4f |\n", features, landmarks, 100 * e);
  }
  if (!out_dir.empty()) {
    std::filesystem::create_directories(out_dir);
    cv::Mat img(420, 1000, CV_8UC3, cv::Scalar(255, 255, 255));
    draw_plot(img, {90, 40, 360, 300}, ks, k_err, "NNWA relative error vs k (true landmarks)",
              "k neighbours");
    draw_plot(img, {590, 40, 360, 300}, counts, count_err,
              "NNWA relative error vs features (true landmarks)", "named features used");
    const std::string png = out_dir + "/model_sweeps.png";
    if (!cv::imwrite(png, img)) throw std::runtime_error("cannot write " + png);
    out["plot"] = png;
  }
  bench::write_report(out_dir, "model_accuracy", out, md);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "accuracy")
      return run_accuracy(argc > 2 ? std::stoi(argv[2]) : 20, argc > 3 ? argv[3] : "");
    if (mode.empty() || mode.rfind("--", 0) == 0) return run_benchmarks(argc, argv);
    std::cerr << "usage: model_bench [--benchmark_...] | accuracy [SUBJECTS] [OUTDIR]\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
