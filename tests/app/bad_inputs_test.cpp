// The bad-input corpus (../shared/data/bad_inputs) through every command that takes that kind of
// file (issue 20, item 5): exactly one "error: " line on stderr naming the file, a non-zero exit
// that is not a signal or a timeout, and no output left behind (no output path, no *.tmp*).
// Also through orthoface-batch (the file in an item folder), `station --rig` and, as a landmark
// file, `reconstruct --front-landmarks`, with a few bad .pts files the fixture writes.
//
// With ORTHOFACE_BAD_INPUTS_TABLE=1, BadInputs.Table runs every case and prints the markdown
// table of docs/bad_inputs.md (rows: corpus files, columns: command and flag).
#include <unistd.h>
#include <algorithm>
#include <cctype>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/common/run_command.h"
#include "tests/common/test_data.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;

// Bad iBUG .pts landmark files (vision/pts_io.h) in `dir`: one thing wrong in each.
void write_bad_pts(const fs::path& dir) {
  fs::create_directories(dir);
  const auto pts = [](int declared, int points, const std::string& open, const std::string& close,
                      const std::string& first) {
    std::string s = "version: 1\nn_points: " + std::to_string(declared) + "\n" + open;
    for (int k = 0; k < points; ++k)
      s += (k == 0 && !first.empty() ? first : std::to_string(100 + k) + " 120") + "\n";
    return s + close;
  };
  std::ofstream(dir / "pts_67_points.pts") << pts(68, 67, "{\n", "}\n", "");
  std::ofstream(dir / "pts_5_points_declared.pts") << pts(5, 5, "{\n", "}\n", "");
  std::ofstream(dir / "pts_non_numeric.pts") << pts(68, 68, "{\n", "}\n", "12 abc");
  std::ofstream(dir / "pts_no_opening_brace.pts") << pts(68, 68, "", "}\n", "");
  std::ofstream(dir / "pts_no_closing_brace.pts") << pts(68, 68, "{\n", "", "");
  std::ofstream(dir / "pts_nan.pts") << pts(68, 68, "{\n", "}\n", "nan 120");
  std::ofstream(dir / "pts_outside_the_photo.pts") << pts(68, 68, "{\n", "}\n", "90000 120");
}

// A good front + side pair with its rig and truth (`simulate`), a reconstruction folder made from
// it (`reconstruct`) and a feature-point file: the valid inputs beside the bad one. Made once
// under a name shared by the test processes (ctest runs each case in its own process) and moved
// into place whole, so a half-made fixture is never seen.
fs::path fixture() {
  std::string why;
  const fs::path ready = testing::command_fixture(
      "bad_inputs_fixture", {"meshes/truth.mtl", "made"},
      [](const fs::path& work) {
        // orthoface-batch inputs: one pair item with its rig, a folder with one good mesh.
        fs::create_directories(work / "pairs" / "item");
        for (const char* f : {"front.png", "side.png", "rig.yaml"})
          fs::copy_file(work / "sim" / f, work / "pairs" / "item" / f);
        fs::create_directories(work / "meshes");
        for (const char* f : {"truth.obj", "truth.mtl", "truth.png"})  // the OBJ with its material
          fs::copy_file(work / "sim" / f, work / "meshes" / f);
        write_bad_pts(work / "made");
      },
      why);
  if (ready.empty()) ADD_FAILURE() << "fixture: " << why;
  return ready;
}

// One command run on one corpus file. `args` holds BAD (the corpus file), GOOD (the fixture),
// CASE (this case's fresh folder) and, for a file read from a folder, DIR (a copy of the
// fixture's folder `copy` with the bad file put in as `as`).
struct Use {
  std::string column;  // "detect --front", "render DIR/head.obj", ...
  std::string args;
  std::vector<std::string> outputs;  // must not exist afterwards (relative to CASE)
  std::string copy = "", as = "";    // folder read by the command, the name the bad file takes
  std::string drop = "";             // the folder's file the bad one replaces (default: `as`)
  bool batch = false;                // orthoface-batch: one error line among its progress lines
};

enum class Kind { Image, Mesh, Rig, Json, Pts };

Kind kind_of(const std::string& file) {
  if (file.rfind("made/pts_", 0) == 0) return Kind::Pts;
  if (file.rfind("image_", 0) == 0) return Kind::Image;
  if (file.rfind("mesh_", 0) == 0) return Kind::Mesh;
  if (file.rfind("rig_", 0) == 0) return Kind::Rig;
  return Kind::Json;
}

const std::vector<std::string>& corpus() {
  static const std::vector<std::string> files = {
      "image_1x1.png",
      "image_blank_no_face.png",
      "image_empty.jpg",
      "image_gray16.png",
      "image_huge_header.png",
      "image_noise.png",
      "image_rgba.png",
      "image_text_named_jpg.jpg",
      "image_truncated.jpg",
      "image_wide_20000x8.png",
      "mesh_degenerate_only.obj",
      "mesh_empty.obj",
      "mesh_face_index_out_of_range.obj",
      "mesh_garbage.ply",
      "mesh_nan_vertex.obj",
      "mesh_negative_index_too_far.obj",
      "mesh_non_manifold_edge.obj",
      "mesh_points_only.obj",
      "mesh_truncated.ply",
      "rig_missing_fields.yaml",
      "rig_nan_focal.yaml",
      "rig_not_yaml.yaml",
      "json_malformed.json",
      "json_wrong_types.json",
      "made/pts_67_points.pts",
      "made/pts_5_points_declared.pts",
      "made/pts_non_numeric.pts",
      "made/pts_no_opening_brace.pts",
      "made/pts_no_closing_brace.pts",
      "made/pts_nan.pts",
      "made/pts_outside_the_photo.pts",
  };
  return files;
}

// Where a case's bad file is: the corpus, or (made/...) the fixture.
fs::path bad_file(const fs::path& good, const std::string& file) {
  return file.rfind("made/", 0) == 0 ? good / file
                                     : fs::path(testing::shared_data("bad_inputs/" + file));
}

std::vector<Use> orthoface_uses(Kind kind, const std::string& file) {
  const std::vector<std::string> out = {"out"};
  const std::vector<std::string> view = {"view.png"};
  const std::vector<std::string> eval_out = {"DIR/eval.json", "DIR/error.ply", "DIR/error.png"};
  const std::string pair = "--front GOOD/sim/front.png --side GOOD/sim/side.png";
  const std::string cams = "--front sim:0/front --side sim:0/side --timeout 5";
  const std::string render = "render DIR --yaw 20 -o CASE/view.png";
  const std::string eval = "eval DIR --truth GOOD/sim";
  switch (kind) {
    case Kind::Image:
      return {
          {"detect --front", "detect --front BAD --side GOOD/sim/side.png --out CASE/out", out},
          {"detect --side", "detect --front GOOD/sim/front.png --side BAD --out CASE/out", out},
          {"detect --background-front", "detect " + pair + " --background-front BAD --out CASE/out",
           out},
          {"detect --background-side", "detect " + pair + " --background-side BAD --out CASE/out",
           out},
          {"reconstruct --front",
           "reconstruct --front BAD --side GOOD/sim/side.png --rig GOOD/sim/rig.yaml --out "
           "CASE/out",
           out},
          {"reconstruct --side",
           "reconstruct --front GOOD/sim/front.png --side BAD --rig GOOD/sim/rig.yaml --out "
           "CASE/out",
           out},
          {"reconstruct --front-background",
           "reconstruct " + pair + " --front-background BAD --out CASE/out", out},
          {"reconstruct --side-background",
           "reconstruct " + pair + " --side-background BAD --out CASE/out", out},
          {"capture --front-background",
           "capture " + cams + " --front-background BAD --out CASE/out", out},
          {"render DIR/front.png", render, view, "rec", "front.png"},
          {"render DIR/side.png", render, view, "rec", "side.png"},
          {"eval DIR/front.png", eval, eval_out, "rec", "front.png"},
      };
    case Kind::Mesh: {
      std::vector<Use> u = {
          {"features", "features BAD -o CASE/out", out},
          {"segment", "segment BAD --points GOOD/points.json -o CASE/out", out},
          {"similarity", "similarity BAD GOOD/sim/truth.obj -o CASE/out", out},
          {"eval --truth", "eval DIR --truth BAD", eval_out, "rec", ""},
      };
      // The folder's mesh is head.obj: an OBJ put there as it is (a PLY would be another test).
      if (fs::path(file).extension() == ".obj") {
        u.push_back({"render DIR/head.obj", render, view, "rec", "head.obj"});
        u.push_back({"eval DIR/head.obj", eval, eval_out, "rec", "head.obj"});
      }
      return u;
    }
    case Kind::Rig:
      return {
          {"reconstruct --rig", "reconstruct " + pair + " --rig BAD --out CASE/out", out},
          {"capture --rig", "capture " + cams + " --rig BAD --out CASE/out", out},
          {"render DIR/rig.yaml", render, view, "rec", "rig.yaml"},
          {"eval DIR/rig.yaml", eval, eval_out, "rec", "rig.yaml"},
      };
    case Kind::Json:
      return {
          {"segment --points", "segment GOOD/sim/truth.obj --points BAD -o CASE/out", out},
          {"render DIR/landmarks.json", render, view, "rec", "landmarks.json"},
          {"eval DIR/landmarks.json", eval, eval_out, "rec", "landmarks.json"},
          {"eval --truth SIMDIR/landmarks.json", "eval TRUTH --truth DIR", eval_out, "sim",
           "landmarks.json"},
          {"render DIR/observation.json", render, view, "rec", "observation.json"},
      };
    case Kind::Pts:
      return {};
  }
  return {};
}

// orthoface-batch: the bad file in an item folder (pairs) or beside a good mesh (similarity).
// Every item is tried and reported, so batch_report.json and the similarity tables are its
// answer; what must not be left is the failed item's reconstruction folder.
std::vector<Use> batch_uses(Kind kind, const std::string& file) {
  const std::string ext = fs::path(file).extension().string();
  const std::string pairs = "pairs DIR -o CASE/out";
  const std::vector<std::string> item_out = {"out/item"};
  switch (kind) {
    case Kind::Image: {
      std::vector<Use> u;
      for (const std::string stem : {"front", "side", "front_background", "side_background"})
        u.push_back({"batch pairs " + stem + ".*", pairs, item_out, "pairs", "item/" + stem + ext,
                     "item/" + stem + ".png", true});
      return u;
    }
    case Kind::Rig:
      return {{"batch pairs rig.yaml", pairs, item_out, "pairs", "item/rig.yaml", "", true}};
    case Kind::Mesh:
      return {{"batch similarity", "similarity DIR -o CASE/out", {}, "meshes", file, "", true}};
    default:
      return {};
  }
}

std::vector<Use> uses(Kind kind, const std::string& file) {
  std::vector<Use> u = orthoface_uses(kind, file);
  for (const Use& b : batch_uses(kind, file)) u.push_back(b);
  // Refused before a port is bound, the output folder made or a camera opened.
  if (kind == Kind::Rig)
    u.push_back({"station --rig",
                 "station --front sim:1/front --side sim:1/side --duration 1 --output http:" +
                     std::to_string(30000 + ::getpid() % 20000) + " --rig BAD --out CASE/out",
                 {"out"}});
  // Any file given as the front photo's landmarks (iBUG .pts).
  u.push_back({"reconstruct --front-landmarks",
               "reconstruct --front GOOD/sim/front.png --side GOOD/sim/side.png --front-landmarks "
               "BAD --out CASE/out",
               {"out"}});
  return u;
}

// Cases where the file is not wrong for that command, so success is the right answer: the
// photos of a reconstruction folder are textures (a valid image without a face is fine there); a
// clean plate is an empty scene by definition, and capture keeps the pair it took when modelling
// it fails afterwards (by design); a non-manifold edge is analysed with a warning
// (AnalysisCli.FeaturesSayWhenTheMeshIsNotAManifold). These must still not crash or hang, and a
// refusal must still be one error line. Returns why, or "".
std::string accepted_because(const std::string& file, const std::string& column) {
  const bool faceless = file == "image_blank_no_face.png" || file == "image_noise.png" ||
                        file == "image_gray16.png" || file == "image_rgba.png";
  if (faceless && (column.rfind("render DIR/", 0) == 0 || column.rfind("eval DIR/", 0) == 0))
    return "a folder photo is a texture";
  if (faceless && column == "capture --front-background") return "pair kept by design";
  if (file == "image_rgba.png" && column.find("background") != std::string::npos)
    return "a valid clean plate";
  const bool analysed = column == "features" || column == "segment" || column == "eval --truth" ||
                        column == "render DIR/head.obj" || column == "eval DIR/head.obj";
  if (file == "mesh_non_manifold_edge.obj" && analysed)
    return "analysed, with a non-manifold warning";
  return "";
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t i = s.find(from); i != std::string::npos; i = s.find(from, i + to.size()))
    s.replace(i, from.size(), to);
  return s;
}

// The lines of `err` that start with "error: " (orthoface-batch prints each after a newline,
// between the lines of its progress bar).
std::vector<std::string> error_lines(const std::string& err) {
  std::vector<std::string> out;
  std::istringstream in(err);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("error: ", 0) == 0) out.push_back(line);
  return out;
}

struct Outcome {
  testing::CommandResult result;
  std::vector<std::string> problems;  // the rules broken; empty when the case passes
};

// Runs one use of the corpus file `file` in a fresh folder and checks the rules.
Outcome run_case(const fs::path& good, const std::string& file, const Use& use,
                 const std::string& name) {
  const fs::path bad = bad_file(good, file);
  std::string lower = name;  // upper-case words in args are placeholders
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const fs::path work = testing::temp_dir("bad_inputs_" + lower);
  std::string args = use.args;
  std::string named = file;  // what the error line must name
  fs::path dir;
  if (!use.copy.empty()) {
    dir = work / ("folder_" + use.copy);
    fs::copy(good / use.copy, dir, fs::copy_options::recursive);
    if (!use.as.empty()) {
      fs::remove(dir / (use.drop.empty() ? use.as : use.drop));
      fs::copy_file(bad, dir / use.as);
      named = use.as;
    }
    if (use.copy == "sim") {  // eval of a copy of the reconstruction against this truth folder
      fs::copy(good / "rec", work / "rec", fs::copy_options::recursive);
      args = replace_all(args, "TRUTH", "'" + (work / "rec").string() + "'");
      dir = work / "rec";  // the outputs land in the reconstruction folder
      args = replace_all(args, "--truth DIR", "--truth '" + (work / "folder_sim").string() + "'");
    }
  }
  args = replace_all(args, "BAD", "'" + bad.string() + "'");
  args = replace_all(args, "GOOD", good.string());
  args = replace_all(args, "CASE", work.string());
  args = replace_all(args, "DIR", "'" + dir.string() + "'");

  Outcome o;
  const fs::path program = use.batch ? fs::path(ORTHOFACE_BINARY).parent_path() / "orthoface-batch"
                                     : fs::path(ORTHOFACE_BINARY);
  o.result = testing::run_in(work, "timeout 60 '" + program.string() + "' " + args);
  const testing::CommandResult& r = o.result;
  const bool lenient = !accepted_because(file, use.column).empty();
  if (lenient) {
    if (r.code < 0 || r.code >= 124)
      o.problems.push_back("exit " + std::to_string(r.code) + " (signal or timeout)");
    const bool one_line = use.batch ? error_lines(r.err).size() == 1
                                    : r.err.rfind("error: ", 0) == 0 &&
                                          std::count(r.err.begin(), r.err.end(), '\n') == 1;
    if (r.code != 0 && !one_line) o.problems.push_back("refused, but not with one error line");
    if (o.problems.empty()) fs::remove_all(work);
    return o;
  }
  if (r.code == 0) o.problems.push_back("exit 0");
  if (r.code < 0 || r.code >= 124)
    o.problems.push_back("exit " + std::to_string(r.code) + " (signal or timeout)");
  if (use.batch) {  // its progress bar shares stderr: one error line among them
    const std::vector<std::string> errors = error_lines(r.err);
    if (errors.size() != 1)
      o.problems.push_back("stderr has " + std::to_string(errors.size()) + " error lines");
    else if (errors[0].find(fs::path(named).filename().string()) == std::string::npos ||
             errors[0].find(dir.string()) == std::string::npos)
      o.problems.push_back("the error line does not name " + named + " in its folder");
  } else {
    if (r.err.rfind("error: ", 0) != 0)
      o.problems.push_back("stderr does not start with 'error: '");
    const size_t newlines = std::count(r.err.begin(), r.err.end(), '\n');
    if (newlines != 1 || r.err.back() != '\n')
      o.problems.push_back("stderr has " + std::to_string(newlines) + " lines");
    if (r.err.find(named) == std::string::npos)
      o.problems.push_back("stderr does not name " + named);
  }
  if (r.err.find("[json.exception") != std::string::npos)
    o.problems.push_back("the JSON library's own text in the error");
  for (const std::string& output : use.outputs) {
    const fs::path p = output.rfind("DIR/", 0) == 0 ? dir / output.substr(4) : work / output;
    if (fs::exists(p)) o.problems.push_back("left " + output);
  }
  for (const auto& e : fs::recursive_directory_iterator(work))
    if (e.path().filename().string().find(".tmp") != std::string::npos)
      o.problems.push_back("left " + fs::relative(e.path(), work).string());
  if (o.problems.empty()) fs::remove_all(work);  // kept for a look when a rule is broken
  return o;
}

struct Param {
  std::string file;
  Use use;
};

// What gtest prints for a case (not its bytes).
void PrintTo(const Param& p, std::ostream* os) { *os << p.use.column << " " << p.file; }

std::vector<Param> all_params() {
  std::vector<Param> p;
  for (const std::string& f : corpus())
    for (const Use& u : uses(kind_of(f), f)) p.push_back({f, u});
  return p;
}

std::string param_name(const Param& p) {
  std::string s = p.use.column + "__" + p.file;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

class BadInputs : public ::testing::TestWithParam<Param> {};

TEST_P(BadInputs, OneErrorLineNamingTheFileAndNoLeftovers) {
  if (testing::shared_data("bad_inputs").empty()) GTEST_SKIP() << "no ../shared/data/bad_inputs";
  const Param& p = GetParam();
  SCOPED_TRACE(p.use.column + " " + p.file);
  const fs::path good = fixture();
  ASSERT_FALSE(good.empty());
  const Outcome o = run_case(good, p.file, p.use, param_name(p));
  for (const std::string& problem : o.problems)
    ADD_FAILURE() << problem << "\nexit " << o.result.code << ", stderr:\n" << o.result.err;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInputs, ::testing::ValuesIn(all_params()),
                         [](const ::testing::TestParamInfo<Param>& i) {
                           return param_name(i.param);
                         });

// `station --rig` reads the rig before any camera opens: with a camera that does not exist, the
// error is still the rig file's, and no output folder is made.
TEST(BadInputsStation, RigRefusedBeforeAnyCameraOpens) {
  if (testing::shared_data("bad_inputs").empty()) GTEST_SKIP() << "no ../shared/data/bad_inputs";
  const fs::path work = testing::temp_dir("bad_inputs_station_rig");
  const std::string rig = testing::shared_data("bad_inputs/rig_not_yaml.yaml");
  const testing::CommandResult r = testing::run_orthoface(
      "station --front /dev/video_orthoface_missing --side sim:1/side --duration 1 --rig '" + rig +
          "' --out out",
      work);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("error: rig file " + rig + ":", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(work / "out"));
}

// A JSON field of the wrong type is named, with the type it should have had and the one it had,
// in each reader of a JSON input (landmarks.json and observation.json of a folder, feature
// points, a simulation's truth).
TEST(BadInputsJson, TypeErrorsNameTheFieldAndBothTypes) {
  const fs::path good = fixture();
  ASSERT_FALSE(good.empty());
  const fs::path work = testing::temp_dir("bad_inputs_json_types");
  const auto expect_error = [&](const std::string& args, const std::string& file,
                                const std::string& what) {
    const testing::CommandResult r = testing::run_orthoface(args, work);
    EXPECT_EQ(r.code, 1) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << r.err;
  };
  fs::copy(good / "rec", work / "rec", fs::copy_options::recursive);
  std::ofstream(work / "rec" / "landmarks.json")
      << R"({"landmarks": {"nose_tip": {"xyz_mm": [1, "2", 3]}}})";
  expect_error("render rec --yaw 20 -o view.png", "landmarks.json",
               "landmarks.nose_tip.xyz_mm[1]: expected a number, got a string");
  fs::copy_file(good / "rec" / "landmarks.json", work / "rec" / "landmarks.json",
                fs::copy_options::overwrite_existing);
  nlohmann::json obs = nlohmann::json::parse(testing::slurp(good / "rec" / "observation.json"));
  obs["front"]["width"] = "640";
  std::ofstream(work / "rec" / "observation.json") << obs.dump();
  expect_error("render rec --yaw 20 -o view.png", "observation.json",
               "front.width: expected a number, got a string");
  obs["front"]["width"] = 640;
  obs["side_faces_left"] = nullptr;
  std::ofstream(work / "rec" / "observation.json") << obs.dump();
  expect_error("render rec --yaw 20 -o view.png", "observation.json",
               "side_faces_left: expected true or false, got null");
  std::ofstream(work / "points.json") << R"({"9.3": [0, "-20", 110], "10.1": [80, 0, 0]})";
  expect_error(
      "segment '" + (good / "sim" / "truth.obj").string() + "' --points points.json -o seg",
      "points.json", "9.3[1]: expected a number, got a string");
  std::ofstream(work / "points.json") << R"({"points": [{"name": 93, "position": [0, 0, 0]}]})";
  expect_error(
      "segment '" + (good / "sim" / "truth.obj").string() + "' --points points.json -o seg",
      "points.json", "points[0].name: expected a string, got a number");
  fs::copy(good / "sim", work / "sim", fs::copy_options::recursive);
  nlohmann::json truth = nlohmann::json::parse(testing::slurp(good / "sim" / "landmarks.json"));
  truth["version"] = "1";
  std::ofstream(work / "sim" / "landmarks.json") << truth.dump();
  fs::copy(good / "rec", work / "rec2", fs::copy_options::recursive);
  expect_error("eval rec2 --truth sim", "landmarks.json",
               "version: expected a number, got a string");
  EXPECT_FALSE(fs::exists(work / "rec2" / "eval.json"));
}

// detect refuses a side photo whose subject has other colours than the front's (a skin-coloured
// ellipse passes the profile fit), with the check reconstruct refuses that pair with.
TEST(BadInputsDetect, BlobProfileIsRefusedByTheColourCheck) {
  if (testing::shared_data("bad_inputs").empty()) GTEST_SKIP() << "no ../shared/data/bad_inputs";
  const fs::path good = fixture();
  ASSERT_FALSE(good.empty());
  const fs::path work = testing::temp_dir("bad_inputs_detect_blob");
  const testing::CommandResult r = testing::run_orthoface(
      "detect --front '" + (good / "sim" / "front.png").string() + "' --side '" +
          testing::shared_data("bad_inputs/image_rgba.png") + "' --out out",
      work);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("error: input check same_person_colours: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("image_rgba.png"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(work / "out"));
}

// The table of docs/bad_inputs.md: ORTHOFACE_BAD_INPUTS_TABLE=1 ./app_test
// --gtest_filter=BadInputsTable.*
TEST(BadInputsTable, Print) {
  if (!std::getenv("ORTHOFACE_BAD_INPUTS_TABLE"))
    GTEST_SKIP() << "ORTHOFACE_BAD_INPUTS_TABLE unset";
  if (testing::shared_data("bad_inputs").empty()) GTEST_SKIP() << "no ../shared/data/bad_inputs";
  const fs::path good = fixture();
  ASSERT_FALSE(good.empty());
  int cases = 0, failed = 0;
  for (const Kind kind : {Kind::Image, Kind::Mesh, Kind::Rig, Kind::Json, Kind::Pts}) {
    std::vector<std::string> columns;
    std::map<std::string, std::map<std::string, std::string>> cells;
    std::vector<std::string> rows;
    for (const std::string& f : corpus()) {
      if (kind_of(f) != kind) continue;
      rows.push_back(f);
      for (const Use& u : uses(kind, f)) {
        if (std::find(columns.begin(), columns.end(), u.column) == columns.end())
          columns.push_back(u.column);
        const Outcome o = run_case(good, f, u, "table");
        const std::vector<std::string> errors = error_lines(o.result.err);
        std::string cell = u.batch ? (errors.empty() ? "" : errors[0])
                                   : o.result.err.substr(0, o.result.err.find('\n'));
        if (cell.rfind("error: ", 0) == 0) cell = cell.substr(7);
        const std::string scratch =
            (fs::temp_directory_path() /
             ("orthoface_test_bad_inputs_table_" + std::to_string(::getpid())))
                .string() +
            "/";
        cell = replace_all(cell, testing::shared_data("bad_inputs") + "/", "");
        cell = replace_all(replace_all(cell, scratch, ""), good.string() + "/", "");
        if (cell.size() > 100) cell = cell.substr(0, 97) + "...";
        cell = replace_all(cell, "|", "\\|");
        ++cases;
        const std::string why = accepted_because(f, u.column);
        if (o.problems.empty() && why.rfind("known gap", 0) == 0)
          cell = "**" + why + "** (exit " + std::to_string(o.result.code) + ")";
        else if (o.problems.empty() && !why.empty())
          cell = (o.result.code == 0 ? "ok: accepted (" : "refused (") + why + ")" +
                 (o.result.code == 0 ? "" : ": " + cell);
        if (!o.problems.empty()) {
          ++failed;
          cell = "**FAIL** (" + o.problems.front() + "): " + cell;
        }
        cells[f][u.column] = cell;
      }
    }
    std::cout << "\n|file|";
    for (const std::string& c : columns) std::cout << c << "|";
    std::cout << "\n|---|";
    for (size_t i = 0; i < columns.size(); ++i) std::cout << "---|";
    std::cout << "\n";
    for (const std::string& f : rows) {
      std::cout << "|" << f << "|";
      for (const std::string& c : columns)
        std::cout << (cells[f].count(c) ? cells[f][c] : std::string("—")) << "|";
      std::cout << "\n";
    }
  }
  std::cout << "\n" << cases << " cases, " << failed << " failing\n";
}

}  // namespace
}  // namespace orthoface::app
