// scene_bench: sim heads in front of real scenes (issue 17). Each subject is reconstructed five
// ways, as `reconstruct --rig` would from `orthoface simulate` folders: over the plain background,
// over each scene photograph with both cameras' clean plates, with the front camera's plate only,
// with the side camera's only, and without plates (the subject cut out of the scene around the
// face, vision/scene_cut.h). Relative error as `eval` gives it (seed 002 §4.1), or the input
// check / vision failure that refused the pair.
//   scene_bench [SUBJECTS] [OUT_DIR] [SCENE...]
// SUBJECTS: make_head seeds 0..N-1 (default 5); SCENE: photographs (default: five of the OpenCV
// sample photos Debian's opencv-doc installs: a street, a cluttered table, a plant against
// patterned cloth, a building, objects on a desk). JSON on stdout, Markdown on stderr, both in
// OUT_DIR/scene_bench.{json,md}.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/bench_report.h"
#include "model/evaluate.h"
#include "reconstruct/reconstruction.h"
#include "render/renderer.h"
#include "sim/head.h"
#include "sim/rig.h"

namespace {

using namespace orthoface;
namespace fs = std::filesystem;

const char* const kSampleDir = "/usr/share/doc/opencv-doc/examples/data";
const char* const kSampleScenes[] = {"leuvenA.jpg", "rubberwhale1.png", "aloeL.jpg", "building.jpg",
                                     "stuff.jpg"};

// One reconstruction's outcome: the relative error (fraction), or why there is none.
struct Outcome {
  double error = -1;
  std::string refused;  // the input check that refused the pair, or "vision: ..." for a failure
  nlohmann::json json() const {
    return refused.empty() ? nlohmann::json(error) : nlohmann::json({{"refused", refused}});
  }
  std::string md() const {
    if (!refused.empty()) return "refused (" + refused + ")";
    char b[32];
    std::snprintf(b, sizeof b, "%.2f %%", 100 * error);
    return b;
  }
};

// Which cameras' clean plates a run is given.
enum class Plates { None, Front, Side, Both };

Outcome reconstruct_and_score(const sim::Head& head, const sim::Capture& cap, Plates plates) {
  reconstruct::ReconstructOptions o;
  o.rig = cap.nominal_rig;
  if (plates == Plates::Front || plates == Plates::Both)
    o.observe.background_front = cap.background_front;
  if (plates == Plates::Side || plates == Plates::Both)
    o.observe.background_side = cap.background_side;
  Outcome out;
  try {
    const reconstruct::Reconstruction r = reconstruct::from_photos(cap.front, cap.side, o);
    out.error = model::reconstruction_error(r.mesh, head.mesh, model::face_region(head.landmarks),
                                            r.landmarks, head.landmarks)
                    .relative;
  } catch (const reconstruct::InputRefused& e) {
    out.refused = e.check();
  } catch (const std::exception& e) {
    out.refused = std::string("vision: ") + e.what();
    if (out.refused.size() > 60) out.refused = out.refused.substr(0, 57) + "...";
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    int subjects = 5;
    if (argc > 1) {
      std::size_t used = 0;
      try {
        subjects = std::stoi(argv[1], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || argv[1][used] != '\0' || subjects < 1 || subjects > 1000)
        throw std::invalid_argument("SUBJECTS must be a whole number in 1..1000, got '" +
                                    std::string(argv[1]) + "'");
    }
    const std::string out_dir = argc > 2 ? argv[2] : "";
    std::vector<std::string> scenes;
    for (int i = 3; i < argc; ++i) scenes.push_back(argv[i]);
    if (scenes.empty())
      for (const char* s : kSampleScenes)
        if (fs::exists(fs::path(kSampleDir) / s))
          scenes.push_back((fs::path(kSampleDir) / s).string());
    if (scenes.empty()) {
      std::cerr << "scene_bench: no scene photos (install opencv-doc or name them); skipped\n";
      return 0;
    }
    if (!out_dir.empty()) fs::create_directories(out_dir);
    render::Renderer renderer;
    // The ways each pair is run over a scene; the plain background is the reference.
    struct Way {
      const char* key;
      const char* title;
      Plates plates;
      std::vector<double> errors;  // over the pairs it and the plain background modelled
      int refused = 0;
    };
    std::vector<Way> ways = {{"plates", "scene + plates", Plates::Both, {}, 0},
                             {"front_plate", "front plate only", Plates::Front, {}, 0},
                             {"side_plate", "side plate only", Plates::Side, {}, 0},
                             {"no_plates", "scene, no plates", Plates::None, {}, 0}};
    nlohmann::json rows = nlohmann::json::array();
    std::string md = "| subject | scene | plain |", rule = "|---|---|---|";
    for (const Way& w : ways) md += std::string(" ") + w.title + " |", rule += "---|";
    md += "\n" + rule + "\n";
    std::vector<double> plain_all;
    int pairs = 0;
    for (int seed = 0; seed < subjects; ++seed) {
      const sim::Head head = sim::make_head(seed);
      sim::RigOptions ro;
      ro.seed = seed;
      const Outcome plain =
          reconstruct_and_score(head, sim::simulate_capture(head, ro, renderer), Plates::None);
      for (const std::string& scene : scenes) {
        ro.background = sim::BackgroundKind::Photo;
        ro.background_photo = scene;
        const sim::Capture cap = sim::simulate_capture(head, ro, renderer);
        const std::string name = fs::path(scene).stem().string();
        nlohmann::json row = {{"subject", seed}, {"scene", name}, {"plain", plain.json()}};
        md += "| " + std::to_string(seed) + " | " + name + " | " + plain.md() + " |";
        std::cerr << "subject " << seed << " " << name << ": " << plain.md();
        for (Way& w : ways) {
          const Outcome out = reconstruct_and_score(head, cap, w.plates);
          row[w.key] = out.json();
          md += " " + out.md() + " |";
          std::cerr << " / " << out.md();
          w.refused += !out.refused.empty();
          if (out.refused.empty() && plain.refused.empty()) w.errors.push_back(out.error);
        }
        rows.push_back(row);
        md += "\n";
        std::cerr << "\n";
        ++pairs;
        if (plain.refused.empty()) plain_all.push_back(plain.error);
      }
    }
    using bench::mean, bench::median;
    nlohmann::json means = {{"plain", mean(plain_all)}}, medians = {{"plain", median(plain_all)}},
                   refused = nlohmann::json::object();
    char line[160];
    std::snprintf(line, sizeof line,
                  "\n%d pairs. Mean (median) relative error over the pairs modelled: plain %.2f %% "
                  "(%.2f)",
                  pairs, 100 * mean(plain_all), 100 * median(plain_all));
    std::string summary = line;
    for (const Way& w : ways) {
      means[w.key] = mean(w.errors), medians[w.key] = median(w.errors), refused[w.key] = w.refused;
      std::snprintf(line, sizeof line, "; %s %.2f %% (%.2f), refused %d", w.title,
                    100 * mean(w.errors), 100 * median(w.errors), w.refused);
      summary += line;
    }
    summary += "\n";
    const nlohmann::json j = {{"pairs", pairs},
                              {"refused", refused},
                              {"mean_relative_error", means},
                              {"median_relative_error", medians},
                              {"rows", rows}};
    bench::write_report(out_dir, "scene_bench", j, md + summary);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: scene_bench: " << e.what() << "\n";
    return 1;
  }
}
