// scene_bench: sim heads in front of real scenes (issue 17). Each subject is reconstructed three
// ways, as `reconstruct --rig` would from `orthoface simulate` folders: over the plain background,
// over each scene photograph with the cameras' clean plates, and over it without plates (the
// subject cut out of the scene around the face, vision/scene_cut.h). Relative error as `eval`
// gives it (seed 002 §4.1), or the input check / vision failure that refused the pair.
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

Outcome reconstruct_and_score(const sim::Head& head, const sim::Capture& cap, bool plates) {
  reconstruct::ReconstructOptions o;
  o.rig = cap.nominal_rig;
  if (plates) {
    o.observe.background_front = cap.background_front;
    o.observe.background_side = cap.background_side;
  }
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
    nlohmann::json rows = nlohmann::json::array();
    std::string md =
        "| subject | scene | plain | scene + plates | scene, no plates |\n|---|---|---|---|---|\n";
    std::vector<double> plain_all, plates_all, none_all;
    int pairs = 0, refused_none = 0, refused_plates = 0;
    for (int seed = 0; seed < subjects; ++seed) {
      const sim::Head head = sim::make_head(seed);
      sim::RigOptions ro;
      ro.seed = seed;
      const Outcome plain =
          reconstruct_and_score(head, sim::simulate_capture(head, ro, renderer), false);
      for (const std::string& scene : scenes) {
        ro.background = sim::BackgroundKind::Photo;
        ro.background_photo = scene;
        const sim::Capture cap = sim::simulate_capture(head, ro, renderer);
        const Outcome with = reconstruct_and_score(head, cap, true);
        const Outcome without = reconstruct_and_score(head, cap, false);
        const std::string name = fs::path(scene).stem().string();
        rows.push_back({{"subject", seed},
                        {"scene", name},
                        {"plain", plain.json()},
                        {"plates", with.json()},
                        {"no_plates", without.json()}});
        md += "| " + std::to_string(seed) + " | " + name + " | " + plain.md() + " | " + with.md() +
              " | " + without.md() + " |\n";
        ++pairs;
        refused_plates += !with.refused.empty();
        refused_none += !without.refused.empty();
        if (plain.refused.empty() && with.refused.empty() && without.refused.empty()) {
          plain_all.push_back(plain.error);
          plates_all.push_back(with.error);
          none_all.push_back(without.error);
        }
        std::cerr << "subject " << seed << " " << name << ": " << plain.md() << " / " << with.md()
                  << " / " << without.md() << "\n";
      }
    }
    using bench::mean, bench::median;
    const nlohmann::json j = {
        {"pairs", pairs},
        {"refused_with_plates", refused_plates},
        {"refused_without_plates", refused_none},
        {"scored_in_all_three", plain_all.size()},
        {"mean_relative_error",
         {{"plain", mean(plain_all)}, {"plates", mean(plates_all)}, {"no_plates", mean(none_all)}}},
        {"median_relative_error",
         {{"plain", median(plain_all)},
          {"plates", median(plates_all)},
          {"no_plates", median(none_all)}}},
        {"rows", rows}};
    char summary[256];
    std::snprintf(summary, sizeof summary,
                  "\n%d pairs; refused: %d with plates, %d without. Over the %zu scored all three "
                  "ways, mean (median) relative error: plain %.2f %% (%.2f), plates %.2f %% "
                  "(%.2f), no plates %.2f %% (%.2f)\n",
                  pairs, refused_plates, refused_none, plain_all.size(), 100 * mean(plain_all),
                  100 * median(plain_all), 100 * mean(plates_all), 100 * median(plates_all),
                  100 * mean(none_all), 100 * median(none_all));
    bench::write_report(out_dir, "scene_bench", j, md + summary);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: scene_bench: " << e.what() << "\n";
    return 1;
  }
}
