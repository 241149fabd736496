// input_check_bench: the input check (vision/pair_check.h) on real photos. Every FRMDB person in
// DIR (DIR/<id>/Img_33 front, Img_53 side, Img_43 / Img_23 at +-45 degrees) gives one correct
// pair and wrong ones, each observed by vision (side camera auto-detected, as a user without a
// rig would run it) and checked:
//   correct      Img_33 + Img_53                      must pass
//   side_45      Img_33 + Img_43 (a 45-degree photo as the side)
//   swapped      Img_53 + Img_33
//   other_person Img_33 of this person + Img_53 of the next one (sorted ids, wrapping)
//   front_45     Img_43 + Img_53 (the front photo turned 45 degrees)
//   two_people   this front beside the next person's front, + Img_53
//   blurred      Img_33 blurred (Gaussian, sigma 1.2 % of the image height) + Img_53
//   dark         Img_33 at 12 % brightness + Img_53
//   small        Img_33 and Img_53 at 25 % size
// usage: input_check_bench DIR [OUTDIR] [--people 031,032] [--kinds correct,swapped]
// [--side-camera left|right] (default: detected; FRMDB's Img_53 is from the right)
// [--draw DRAWDIR] (side photos with the network's points drawn: real people, keep it outside
// the repository)
// JSON on stdout (every measure of every pair), Markdown on stderr, both in OUTDIR when given.
// The photos are real people: OUTDIR holds numbers only.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/bench_report.h"
#include "io/json_text.h"
#include "vision/foreground.h"
#include "vision/observe.h"
#include "vision/pair_check.h"

namespace {

using namespace orthoface;
using json = nlohmann::json;
namespace fs = std::filesystem;

json points(const std::vector<cv::Point2d>& p) {
  json a = json::array();
  for (const auto& q : p) a.push_back({q.x, q.y});
  return a;
}

json measures_json(const vision::PairMeasures& m) {
  return {{"front_faces", m.front.faces},
          {"front_face_px", m.front.box.width},
          {"front_score", io::number_or_null(m.front.score)},
          {"front_turn", io::number_or_null(m.front.turn)},
          {"front_blur", io::number_or_null(m.front_blur)},
          {"front_clipped", io::number_or_null(m.front_clipped)},
          {"front_luma", io::number_or_null(m.front_luma)},
          {"side_faces", m.side.faces},
          {"side_score", io::number_or_null(m.side.score)},
          {"side_turn", io::number_or_null(m.side.turn)},
          {"side_angle_deg", io::number_or_null(m.side_angle_deg)},
          {"height_residual", io::number_or_null(m.height_residual)},
          {"skin_delta_e", io::number_or_null(m.skin_delta_e)},
          {"side_facing_against", m.side_facing_against},
          {"colour_distance", io::number_or_null(m.colour_distance)},
          {"side_points", points(m.side.points)},
          {"front_points", points(m.front.points)}};
}

cv::Mat side_by_side(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat bb, out;
  cv::resize(b, bb, cv::Size(int(std::lround(double(b.cols) * a.rows / b.rows)), a.rows));
  cv::hconcat(a, bb, out);
  return out;
}

struct Kind {
  const char* name;
  bool correct;
  // front, side of person i (next = the next person's folder)
  std::function<std::pair<cv::Mat, cv::Mat>(const fs::path& me, const fs::path& next)> make;
};

cv::Mat img(const fs::path& p, const char* name) {
  cv::Mat m = cv::imread((p / name).string());
  if (m.empty()) throw std::runtime_error("unreadable " + (p / name).string());
  return m;
}

const std::vector<Kind>& kinds() {
  static const std::vector<Kind> k = {
      {"correct", true,
       [](auto& me, auto&) {
         return std::pair{img(me, "Img_33.JPG"), img(me, "Img_53.JPG")};
       }},
      {"side_45", false,
       [](auto& me, auto&) {
         return std::pair{img(me, "Img_33.JPG"), img(me, "Img_43.JPG")};
       }},
      {"swapped", false,
       [](auto& me, auto&) {
         return std::pair{img(me, "Img_53.JPG"), img(me, "Img_33.JPG")};
       }},
      {"other_person", false,
       [](auto& me, auto& nx) {
         return std::pair{img(me, "Img_33.JPG"), img(nx, "Img_53.JPG")};
       }},
      {"front_45", false,
       [](auto& me, auto&) {
         return std::pair{img(me, "Img_43.JPG"), img(me, "Img_53.JPG")};
       }},
      {"two_people", false,
       [](auto& me, auto& nx) {
         return std::pair{side_by_side(img(me, "Img_33.JPG"), img(nx, "Img_33.JPG")),
                          img(me, "Img_53.JPG")};
       }},
      {"blurred", false,
       [](auto& me, auto&) {
         cv::Mat f = img(me, "Img_33.JPG"), b;
         cv::GaussianBlur(f, b, cv::Size(), 0.012 * f.rows);
         return std::pair{b, img(me, "Img_53.JPG")};
       }},
      {"dark", false,
       [](auto& me, auto&) {
         cv::Mat f = img(me, "Img_33.JPG"), d;
         f.convertTo(d, -1, 0.12);
         return std::pair{d, img(me, "Img_53.JPG")};
       }},
      {"small", false,
       [](auto& me, auto&) {
         cv::Mat f, s;
         cv::resize(img(me, "Img_33.JPG"), f, cv::Size(), 0.25, 0.25, cv::INTER_AREA);
         cv::resize(img(me, "Img_53.JPG"), s, cv::Size(), 0.25, 0.25, cv::INTER_AREA);
         return std::pair{f, s};
       }},
  };
  return k;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: input_check_bench DIR [OUTDIR] [--people a,b] [--kinds k1,k2]\n";
    return 2;
  }
  const std::string dir = argv[1];
  std::string out_dir;
  std::vector<std::string> only_people, only_kinds;
  std::string draw_dir;  // side photos with the network's points, to look at
  vision::SideCamera side_camera = vision::SideCamera::Auto;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--people" && i + 1 < argc)
      only_people = bench::split_list(argv[++i]);
    else if (a == "--side-camera" && i + 1 < argc) {
      try {
        side_camera = vision::parse_side_camera(argv[++i]);
      } catch (const std::invalid_argument& e) {
        std::cerr << "error: --side-camera: " << e.what() << "\n";
        return 2;
      }
    } else if (a == "--draw" && i + 1 < argc)
      draw_dir = argv[++i];
    else if (a == "--kinds" && i + 1 < argc)
      only_kinds = bench::split_list(argv[++i]);
    else if (a.rfind("--", 0) != 0 && out_dir.empty())
      out_dir = a;
    else {
      std::cerr << "error: unknown argument " << a << "\n";
      return 2;
    }
  }
  if (!fs::is_directory(dir)) {
    std::cout << json{{"skipped", "no FRMDB folder at " + dir}}.dump() << "\n";
    return 0;
  }
  if (!out_dir.empty()) fs::create_directories(out_dir);
  std::vector<std::string> people;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_directory() && fs::exists(e.path() / "Img_33.JPG"))
      people.push_back(e.path().filename());
  std::sort(people.begin(), people.end());
  const vision::PairCheckLimits limits;
  json pairs = json::array();
  std::map<std::string, std::pair<int, int>> tally;              // kind -> (right outcome, pairs)
  std::map<std::string, std::map<std::string, int>> refused_by;  // kind -> check -> count
  for (size_t i = 0; i < people.size(); ++i) {
    if (!only_people.empty() && !std::count(only_people.begin(), only_people.end(), people[i]))
      continue;
    const fs::path me = fs::path(dir) / people[i];
    const fs::path next = fs::path(dir) / people[(i + 1) % people.size()];
    for (const Kind& k : kinds()) {
      if (!only_kinds.empty() && !std::count(only_kinds.begin(), only_kinds.end(), k.name))
        continue;
      json r = {{"person", people[i]}, {"kind", k.name}};
      std::string failure;
      try {
        const auto [front, side] = k.make(me, next);
        vision::ObserveOptions oo;
        oo.side_camera = side_camera;
        const vision::FaceObservation obs = vision::observe(front, side, oo);
        const vision::PairCheck c =
            vision::check_pair(vision::measure_pair(front, side, obs), limits);
        r["measures"] = measures_json(c.measures);
        for (const auto& [n, f] : obs.front_trained)
          if (obs.side.features.count(n))
            r["heights"][n] = {f.px.y, obs.side.features.at(n).px.y,
                               obs.side.features.at(n).confidence, f.px.x,
                               obs.side.features.at(n).px.x};
        if (!draw_dir.empty()) {
          fs::create_directories(draw_dir);
          cv::Mat shown = side.clone();
          if (c.measures.side.points.size() == 68) {
            cv::rectangle(shown, c.measures.side.box, {0, 255, 255}, 2);
            for (size_t j = 0; j < 68; ++j)
              cv::circle(shown, c.measures.side.points[j], 3,
                         j == 30 ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 255, 0), cv::FILLED);
          }
          // The side photo's head blob (what the facing and colour measures see), dimmed outside.
          const cv::Mat mk = vision::head_mask(vision::foreground_probability(side, {}));
          if (!mk.empty()) {
            cv::Mat dim = shown * 0.3;
            shown.copyTo(dim, mk);
            shown = dim;
          }
          cv::putText(shown, obs.side_seen_faces_left ? "seen facing left" : "seen facing right",
                      {10, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.8, {0, 0, 255}, 2);
          cv::imwrite(draw_dir + "/" + people[i] + "_" + k.name + "_side.jpg", shown);
          // The two blobs the colour measures read (observation.front_blob / side_blob).
          for (const auto& [photo, blob, tag] : {std::tuple{front, obs.front_blob, "front_blob"},
                                                 std::tuple{side, obs.side_blob, "side_blob"}}) {
            if (blob.empty()) continue;
            cv::Mat dim = photo * 0.3;
            photo.copyTo(dim, blob);
            cv::imwrite(draw_dir + "/" + people[i] + "_" + k.name + "_" + tag + ".jpg", dim);
            cv::imwrite(draw_dir + "/" + people[i] + "_" + k.name + "_" + tag + ".png", blob);
          }
        }
        for (const auto& x : c.checks)
          if (!x.passed) r["failed"].push_back(x.name);
        failure = c.first_failure();
        if (!c.passed())
          ++refused_by[k.name][c.checks.size() ? r["failed"][0].get<std::string>() : ""];
      } catch (const std::exception& e) {
        failure = std::string("observe: ") + e.what();
        ++refused_by[k.name]["observe"];
      }
      r["refused"] = !failure.empty();
      if (!failure.empty()) r["reason"] = failure;
      auto& t = tally[k.name];
      t.second += 1;
      t.first += k.correct ? failure.empty() : !failure.empty();
      std::cerr << people[i] << " " << k.name << ": " << (failure.empty() ? "passed" : failure)
                << "\n";
      pairs.push_back(r);
    }
  }
  json summary = json::object();
  std::string md = "| pairs | should | got it right | first failed check |\n|---|---|---|---|\n";
  for (const Kind& k : kinds()) {
    if (!tally.count(k.name)) continue;
    const auto [right, n] = tally[k.name];
    std::string by;
    for (const auto& [check, count] : refused_by[k.name])
      by += (by.empty() ? "" : ", ") + check + " " + std::to_string(count);
    summary[k.name] = {{"right", right}, {"pairs", n}, {"refused_by", refused_by[k.name]}};
    md += std::string("| ") + k.name + " | " + (k.correct ? "pass" : "be refused") + " | " +
          std::to_string(right) + " / " + std::to_string(n) + " | " + by + " |\n";
  }
  bench::write_report(out_dir, "input_check", {{"summary", summary}, {"pairs", pairs}}, md);
  return 0;
}
