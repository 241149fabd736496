// `orthoface features | segment | similarity` (and orthoface-batch when built), run as processes.
#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "mesh/mesh_io.h"
#include "sim/head.h"
#include "tests/analysis/analysis_test_meshes.h"
#include "tests/common/run_command.h"
#include "tests/common/test_data.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;

using Result = testing::CommandResult;
using testing::slurp;

Result run(const std::string& binary, const std::string& args, const fs::path& work) {
  return testing::run_in(work, binary + " " + args);
}

Result orthoface(const std::string& args, const fs::path& work) {
  return testing::run_orthoface(args, work);
}

// One "error:" line naming the input, non-zero exit.
void expect_clean_error(const Result& r, const std::string& names) {
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(names), std::string::npos) << r.err;
}

TEST(AnalysisCli, HelpPrintsUsage) {
  const fs::path w = testing::temp_dir("analysis_cli_help");
  for (const char* c : {"features", "segment", "similarity"}) {
    const Result r = orthoface(std::string(c) + " --help", w);
    EXPECT_EQ(r.code, 0) << c;
    EXPECT_NE(r.out.find(c), std::string::npos) << c;
  }
}

TEST(AnalysisCli, BadMeshesGiveOneErrorLine) {
  const fs::path w = testing::temp_dir("analysis_cli_bad");
  expect_clean_error(orthoface("features missing.obj -o out", w), "missing.obj");
  for (const char* bad : {"mesh_empty.obj", "mesh_nan_vertex.obj", "mesh_points_only.obj",
                          "mesh_degenerate_only.obj"}) {
    const std::string path = testing::shared_data(std::string("bad_inputs/") + bad);
    if (path.empty()) GTEST_SKIP() << "no shared bad_inputs";
    expect_clean_error(orthoface("features '" + path + "' -o out", w), bad);
    EXPECT_FALSE(fs::exists(w / "out" / "features.json")) << bad;
  }
}

TEST(AnalysisCli, SegmentRejectsUnknownPointNames) {
  const fs::path w = testing::temp_dir("analysis_cli_segment");
  sim::HeadOptions o;
  o.target_triangles = 2000;
  mesh::write_mesh(sim::make_head(sim::head_params(0), o).mesh, (w / "head.ply").string());
  std::ofstream(w / "fp.json") << R"({"9.3": [0, -20, 110], "nose_tipp": [0, 0, 90]})";
  expect_clean_error(orthoface("segment head.ply --points fp.json -o seg", w), "nose_tipp");
  std::ofstream(w / "good.json")
      << R"({"9.3": [0, -20, 110], "10.1": [80, 0, 0], "10.2": [-80, 0, 0]})";
  const Result ok = orthoface("segment head.ply --points good.json -o seg", w);
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_TRUE(fs::exists(w / "seg" / "membership.csv"));
  EXPECT_TRUE(fs::exists(w / "seg" / "areas.ply"));
  EXPECT_TRUE(fs::exists(w / "seg" / "segment.png"));
}

// The commands chained as a user would: a textured OBJ that `simulate` wrote, named by a path
// relative to the working folder (its texture once went missing under "sim/sim/truth.png"), then
// `segment` on the points `features` wrote (once refused: "unknown ... nasion").
TEST(AnalysisCli, FeaturesOfARelativeTexturedObjFeedSegment) {
  const fs::path w = testing::temp_dir("analysis_cli_chain");
  const Result sim = orthoface("simulate --subject 3 --out sim", w);
  ASSERT_EQ(sim.code, 0) << sim.err;
  const Result f = orthoface("features sim/truth.obj -o feat", w);
  ASSERT_EQ(f.code, 0) << f.err;
  const std::string written = slurp(w / "feat" / "features.json");
  EXPECT_NE(written.find("\"nasion\""), std::string::npos);
  const Result seg = orthoface("segment sim/truth.obj --points feat/features.json -o seg", w);
  ASSERT_EQ(seg.code, 0) << seg.err;
  EXPECT_TRUE(fs::exists(w / "seg" / "membership.csv"));
}

// A non-manifold edge (a fin of a third triangle) is analysed, and the run says so (it was
// accepted in silence).
TEST(AnalysisCli, FeaturesSayWhenTheMeshIsNotAManifold) {
  const fs::path w = testing::temp_dir("analysis_cli_nonmanifold");
  sim::HeadOptions o;
  o.target_triangles = 2000;
  mesh::TriMesh m = sim::make_head(sim::head_params(0), o).mesh;
  const auto t = m.triangles[0];
  m.vertices.push_back((m.vertices[t[0]] + m.vertices[t[1]]) / 2 + Eigen::Vector3d(0, 0, 8));
  m.triangles.push_back({t[0], t[1], int(m.vertices.size()) - 1});
  if (!m.uvs.empty()) m.uvs.push_back(m.uvs[t[0]]);
  if (!m.colors.empty()) m.colors.push_back(m.colors[t[0]]);
  mesh::write_mesh(m, (w / "fin.ply").string());
  const Result r = orthoface("features fin.ply -o feat", w);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("not a manifold: 1 edge(s)"), std::string::npos) << r.out;
  EXPECT_NE(slurp(w / "feat" / "features.json").find("not a manifold"), std::string::npos);
}

TEST(AnalysisCli, SimilarityNeedsTwoMeshesAndScoresAPair) {
  const fs::path w = testing::temp_dir("analysis_cli_similarity");
  expect_clean_error(orthoface("similarity only.obj", w), "two meshes");
  sim::HeadOptions o;
  o.target_triangles = 2000;
  mesh::write_mesh(sim::make_head(sim::head_params(1), o).mesh, (w / "a.ply").string());
  mesh::write_mesh(sim::make_head(sim::head_params(2), o).mesh, (w / "b.ply").string());
  const Result r = orthoface("similarity a.ply b.ply", w);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("shape_index"), std::string::npos);
  expect_clean_error(orthoface("similarity a.ply b.ply a.ply", w), "-o DIR");
  const Result m = orthoface("similarity a.ply b.ply a.ply -o mat", w);
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_TRUE(fs::exists(w / "mat" / "similarity_shape_index.png"));
}

// `count` sim heads (seeds 0..count-1, about `triangles` triangles) as work/meshes/h<seed>.ply.
void write_sim_meshes(const fs::path& work, int count, int triangles) {
  fs::create_directories(work / "meshes");
  sim::HeadOptions o;
  o.target_triangles = triangles;
  for (int s = 0; s < count; ++s)
    mesh::write_mesh(sim::make_head(sim::head_params(s), o).mesh,
                     (work / "meshes" / ("h" + std::to_string(s) + ".ply")).string());
}

TEST(AnalysisCli, BatchUnderMpirunMatchesSingleProcess) {
  const fs::path batch = fs::path(ORTHOFACE_BINARY).parent_path() / "orthoface-batch";
  if (!fs::exists(batch)) GTEST_SKIP() << "orthoface-batch not built (no MPI)";
  const fs::path w = testing::temp_dir("analysis_cli_batch");
  write_sim_meshes(w, 4, 2000);
  const Result one = run("'" + batch.string() + "'", "similarity meshes -o one", w);
  ASSERT_EQ(one.code, 0) << one.err;
  if (std::system("command -v mpirun >/dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
  const Result two =
      run("mpirun -np 2 --allow-run-as-root --oversubscribe '" + batch.string() + "'",
          "similarity meshes -o two", w);
  ASSERT_EQ(two.code, 0) << two.err;
  EXPECT_NE(two.err.find("4/4"), std::string::npos) << two.err;  // progress bar reached the end
  EXPECT_EQ(slurp(w / "one" / "similarity_shape_index.csv"),
            slurp(w / "two" / "similarity_shape_index.csv"));
  expect_clean_error(run("'" + batch.string() + "'", "similarity nowhere -o x", w), "nowhere");
}

// Started without mpirun, orthoface-batch keeps Open MPI's session files in a folder of its own
// and removes it: side-by-side runs (a test suite, a shell loop) no longer race on one shared
// session folder, and nothing is left in the temporary directory (Open MPI's singleton left a
// pid.N folder behind after every run).
TEST(AnalysisCli, BatchRunsSideBySideAndLeavesNoSessionFiles) {
  const fs::path batch = fs::path(ORTHOFACE_BINARY).parent_path() / "orthoface-batch";
  if (!fs::exists(batch)) GTEST_SKIP() << "orthoface-batch not built (no MPI)";
  const fs::path w = testing::temp_dir("analysis_cli_batch_session");
  write_sim_meshes(w, 2, 1000);
  fs::create_directories(w / "tmp");
  const std::string env = "env -u OMPI_MCA_orte_tmpdir_base TMPDIR='" + (w / "tmp").string() + "' ";
  // Six at once, each writing its exit code; a lost race is a non-zero code.
  std::string loop;
  for (int k = 0; k < 6; ++k)
    loop += "(" + env + "'" + batch.string() + "' similarity meshes -o out" + std::to_string(k) +
            " >/dev/null 2>&1; echo $? > rc" + std::to_string(k) + ") & ";
  ASSERT_EQ(testing::run_in(w, "{ " + loop + "wait; }").code, 0);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(slurp(w / ("rc" + std::to_string(k))), "0\n") << "run " << k;
    EXPECT_TRUE(fs::exists(w / ("out" + std::to_string(k)) / "similarity_shape_index.csv"));
  }
  const Result bad = run(env + "'" + batch.string() + "'", "similarity nowhere -o x", w);
  expect_clean_error(bad, "nowhere");
  EXPECT_TRUE(fs::is_empty(w / "tmp")) << (*fs::directory_iterator(w / "tmp")).path();
}

// orthoface-batch similarity never writes NaN (it once wrote a NaN row and column for every mesh
// without a signature, and a NaN cell for a metric constant on a face): a flat grid (no
// curvature anywhere) and a degenerate mesh are each one error line naming the file and a failed
// item in batch_report.json, and the matrices hold the other meshes; two identical meshes score
// 1. `orthoface similarity` refuses the flat grid the same way.
TEST(AnalysisCli, BatchSimilarityNeverWritesNaN) {
  const fs::path batch = fs::path(ORTHOFACE_BINARY).parent_path() / "orthoface-batch";
  if (!fs::exists(batch)) GTEST_SKIP() << "orthoface-batch not built (no MPI)";
  const fs::path w = testing::temp_dir("analysis_cli_batch_nan");
  fs::create_directories(w / "meshes");
  sim::HeadOptions o;
  o.target_triangles = 2000;
  for (int s = 0; s < 2; ++s)
    mesh::write_mesh(sim::make_head(sim::head_params(s), o).mesh,
                     (w / "meshes" / ("h" + std::to_string(s) + ".ply")).string());
  fs::copy_file(w / "meshes" / "h0.ply", w / "meshes" / "h0_copy.ply");
  mesh::write_mesh(testing::plane_grid(40, 2.0), (w / "meshes" / "flat.ply").string());
  std::ofstream(w / "meshes" / "degenerate.obj") << "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n";
  const Result r = run("'" + batch.string() + "'", "similarity meshes -o out", w);
  EXPECT_EQ(r.code, 1) << r.err;
  std::vector<std::string> errors;
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("error: ", 0) == 0) errors.push_back(line);
  ASSERT_EQ(errors.size(), 2u) << r.err;
  EXPECT_NE(errors[0].find("degenerate.obj"), std::string::npos) << errors[0];
  EXPECT_NE(errors[1].find("flat.ply: its "), std::string::npos) << errors[1];
  for (const char* metric : {"mean", "gaussian", "shape_index", "curvedness"}) {
    const std::string csv = slurp(w / "out" / (std::string("similarity_") + metric + ".csv"));
    SCOPED_TRACE(csv);
    std::string lower = csv;
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    EXPECT_EQ(lower.find("nan"), std::string::npos);
    EXPECT_EQ(lower.find("inf"), std::string::npos);
    EXPECT_EQ(csv.find("flat"), std::string::npos);
    std::istringstream rows(csv);
    std::string header;
    std::getline(rows, header);
    EXPECT_EQ(header, "mesh,h0.ply,h0_copy.ply,h1.ply");
    std::map<std::string, std::vector<double>> cells;
    for (std::string row; std::getline(rows, row);) {
      std::istringstream cols(row);
      std::string name, v;
      std::getline(cols, name, ',');
      while (std::getline(cols, v, ',')) cells[name].push_back(std::stod(v));
    }
    ASSERT_EQ(cells.size(), 3u);
    EXPECT_DOUBLE_EQ(cells["h0.ply"][1], 1.0);  // identical meshes
    for (const auto& [name, row] : cells)
      for (double v : row) EXPECT_TRUE(v >= 0 && v <= 1) << name << " " << v;
  }
  const auto report = nlohmann::json::parse(slurp(w / "out" / "batch_report.json"));
  EXPECT_EQ(report["ok"], 3);
  EXPECT_EQ(report["failed"], 2);
  for (const auto& item : report["items"])
    EXPECT_EQ(item["ok"].get<bool>(), !item.contains("error")) << item.dump();

  // Fewer than two usable meshes: no matrix at all, the report says why.
  fs::create_directories(w / "few");
  fs::copy_file(w / "meshes" / "h1.ply", w / "few" / "h1.ply");
  fs::copy_file(w / "meshes" / "flat.ply", w / "few" / "flat.ply");
  const Result few = run("'" + batch.string() + "'", "similarity few -o few_out", w);
  EXPECT_EQ(few.code, 1) << few.err;
  EXPECT_NE(few.err.find("error: " + (fs::path("few") / "flat.ply").string()), std::string::npos)
      << few.err;
  EXPECT_FALSE(fs::exists(w / "few_out" / "similarity_mean.csv"));
  EXPECT_TRUE(fs::exists(w / "few_out" / "batch_report.json"));

  const Result one = orthoface("similarity meshes/h1.ply meshes/flat.ply -o single", w);
  expect_clean_error(one, "flat.ply");
  EXPECT_EQ(std::count(one.err.begin(), one.err.end(), '\n'), 1) << one.err;
  EXPECT_FALSE(fs::exists(w / "single"));
}

// orthoface-batch pairs takes the photo types `reconstruct` takes, tries every item, says why
// each failed one failed, and exits 1 only after the others are done (once: PNG only, failures
// without a reason, a folder missing a photo skipped in silence).
TEST(AnalysisCli, BatchPairsTakesJpegAndRecordsEachFailure) {
  const fs::path batch = fs::path(ORTHOFACE_BINARY).parent_path() / "orthoface-batch";
  if (!fs::exists(batch)) GTEST_SKIP() << "orthoface-batch not built (no MPI)";
  const fs::path w = testing::temp_dir("analysis_cli_batch_pairs");
  ASSERT_EQ(orthoface("simulate --subject 3 --out sim", w).code, 0);
  const cv::Mat front = cv::imread((w / "sim" / "front.png").string());
  const cv::Mat side = cv::imread((w / "sim" / "side.png").string());
  for (const char* d : {"pairs/a_jpeg", "pairs/b_png", "pairs/c_no_side", "pairs/d_broken"})
    fs::create_directories(w / d);
  cv::imwrite((w / "pairs/a_jpeg/Front.JPG").string(), front);
  cv::imwrite((w / "pairs/a_jpeg/side.jpeg").string(), side);
  cv::imwrite((w / "pairs/b_png/front.png").string(), front);
  cv::imwrite((w / "pairs/b_png/side.png").string(), side);
  cv::imwrite((w / "pairs/c_no_side/front.png").string(), front);
  std::ofstream(w / "pairs/d_broken/front.png") << "not a png";
  cv::imwrite((w / "pairs/d_broken/side.png").string(), side);
  for (const std::string& launcher : {std::string(), std::string("mpirun -np 2 --allow-run-as-root "
                                                                 "--oversubscribe ")}) {
    const std::string out = launcher.empty() ? "one" : "two";
    const Result r = run(launcher + "'" + batch.string() + "'", "pairs pairs -o " + out, w);
    if (launcher.empty())
      EXPECT_EQ(r.code, 1) << r.err;
    else
      EXPECT_NE(r.code, 0) << r.err;  // mpirun reports rank 0's failure in its own way
    const auto j = nlohmann::json::parse(slurp(w / out / "batch_report.json"));
    EXPECT_EQ(j["pairs"], 4);
    EXPECT_EQ(j["ok"], 2);
    EXPECT_EQ(j["failed"], 2);
    std::map<std::string, nlohmann::json> items;
    for (const auto& it : j["items"]) items[it["name"].get<std::string>()] = it;
    EXPECT_TRUE(items["a_jpeg"]["ok"].get<bool>()) << launcher;
    EXPECT_TRUE(items["b_png"]["ok"].get<bool>()) << launcher;
    EXPECT_TRUE(fs::exists(w / out / "a_jpeg" / "head.obj"));
    EXPECT_NE(items["c_no_side"]["error"].get<std::string>().find("no side image"),
              std::string::npos)
        << launcher;
    EXPECT_NE(items["d_broken"]["error"].get<std::string>().find("front.png"), std::string::npos)
        << launcher;
  }
  EXPECT_EQ(run("'" + batch.string() + "'", "pairs", w).code, 2);
  EXPECT_EQ(run("'" + batch.string() + "'", "pairs pairs -o x --fast", w).code, 2);
}

// --check-identity runs reconstruct's identity check on every pair: its verdict is in the item's
// report.json (or, without the face-recognition weights, the item fails saying so).
TEST(AnalysisCli, BatchPairsChecksIdentityWhenAsked) {
  const fs::path batch = fs::path(ORTHOFACE_BINARY).parent_path() / "orthoface-batch";
  if (!fs::exists(batch)) GTEST_SKIP() << "orthoface-batch not built (no MPI)";
  const fs::path w = testing::temp_dir("analysis_cli_batch_identity");
  ASSERT_EQ(orthoface("simulate --subject 3 --out sim", w).code, 0);
  fs::create_directories(w / "pairs/right");
  fs::copy_file(w / "sim/front.png", w / "pairs/right/front.png");
  fs::copy_file(w / "sim/side.png", w / "pairs/right/side.png");
  const Result r =
      run("'" + batch.string() + "'", "pairs pairs -o out --check-identity --force", w);
  const auto j = nlohmann::json::parse(slurp(w / "out" / "batch_report.json"));
  const auto& item = j["items"][0];
  if (!item["ok"].get<bool>() &&
      item["error"].get<std::string>().find("face-recognition weights") != std::string::npos)
    GTEST_SKIP() << "no face-recognition weights (scripts/fetch-face-model.sh)";
  EXPECT_EQ(r.code, 0) << r.err;
  const auto report = nlohmann::json::parse(slurp(w / "out" / "right" / "report.json"));
  ASSERT_TRUE(report["input_check"].contains("same_person_face")) << report["input_check"];
  EXPECT_TRUE(report["input_check"]["same_person_face"]["passed"].get<bool>());
  // Without the flag the check does not run.
  ASSERT_EQ(run("'" + batch.string() + "'", "pairs pairs -o plain", w).code, 0);
  const auto plain = nlohmann::json::parse(slurp(w / "plain" / "right" / "report.json"));
  EXPECT_FALSE(plain["input_check"].contains("same_person_face"));
  EXPECT_EQ(run("'" + batch.string() + "'", "similarity pairs -o x --check-identity", w).code, 2);
}

// A pair the input check refuses (photos swapped) is a failed item naming the check; with
// --force it is modelled. An item's clean plates are used.
TEST(AnalysisCli, BatchPairsRecordsTheInputCheckThatRefusedAPair) {
  const fs::path batch = fs::path(ORTHOFACE_BINARY).parent_path() / "orthoface-batch";
  if (!fs::exists(batch)) GTEST_SKIP() << "orthoface-batch not built (no MPI)";
  const fs::path w = testing::temp_dir("analysis_cli_batch_refused");
  ASSERT_EQ(orthoface("simulate --subject 3 --out sim", w).code, 0);
  ASSERT_EQ(orthoface("simulate --subject 6 --background cluttered --out clutter", w).code, 0);
  for (const char* d : {"pairs/right", "pairs/swapped", "pairs/plates"})
    fs::create_directories(w / d);
  // A pair in front of clutter with its clean plates (front_background.*, side_background.*).
  fs::copy_file(w / "clutter/front.png", w / "pairs/plates/front.png");
  fs::copy_file(w / "clutter/side.png", w / "pairs/plates/side.png");
  fs::copy_file(w / "clutter/background.png", w / "pairs/plates/front_background.png");
  fs::copy_file(w / "clutter/background_side.png", w / "pairs/plates/side_background.png");
  fs::copy_file(w / "sim/front.png", w / "pairs/right/front.png");
  fs::copy_file(w / "sim/side.png", w / "pairs/right/side.png");
  fs::copy_file(w / "sim/side.png", w / "pairs/swapped/front.png");
  fs::copy_file(w / "sim/front.png", w / "pairs/swapped/side.png");
  const Result r = run("'" + batch.string() + "'", "pairs pairs -o out", w);
  EXPECT_EQ(r.code, 1) << r.err;
  const auto j = nlohmann::json::parse(slurp(w / "out" / "batch_report.json"));
  EXPECT_EQ(j["ok"], 2);
  EXPECT_EQ(j["refused_by_input_check"]["swapped"], 1);
  ASSERT_EQ(orthoface("eval out/plates --truth clutter", w).code, 0);  // without plates: 10.9 %
  EXPECT_LT(
      nlohmann::json::parse(slurp(w / "out/plates/eval.json"))["relative_error"].get<double>(),
      0.005);
  for (const auto& it : j["items"])
    if (it["name"] == "swapped") {
      EXPECT_EQ(it["refused_by"], "swapped");
    }
  const Result f = run("'" + batch.string() + "'", "pairs pairs -o forced --force", w);
  EXPECT_EQ(f.code, 0) << f.err;
  EXPECT_TRUE(fs::exists(w / "forced" / "swapped" / "head.obj"));
}

}  // namespace
}  // namespace orthoface::app
