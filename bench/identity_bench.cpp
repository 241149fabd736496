// identity_bench: the same_person_face check (reconstruct --check-identity, reconstruct/identity.h)
// on real photos. Every FRMDB person in DIR (DIR/<id>/Img_33 front, Img_53 side) gives its right
// pair and wrong pairings: the front with the side of the person 1, 2, ... ids on (sorted ids,
// wrapping). Each pair is reconstructed as `reconstruct --check-identity --side-camera right
// --force` would (FRMDB's Img_53 is from the right; --force so that a pair the gate refuses is
// still scored) and the check's face-descriptor distance is read from the report.
// usage: identity_bench DIR [OUTDIR] [--people a,b] [--offsets 0,1,2]
// JSON on stdout (every pairing's distance), Markdown on stderr, both in OUTDIR when given.
// The photos are real people: OUTDIR holds numbers only.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "bench/bench_report.h"
#include "io/json_text.h"
#include "reconstruct/reconstruction.h"

namespace {

using namespace orthoface;
using json = nlohmann::json;
namespace fs = std::filesystem;

cv::Mat img(const fs::path& p) {
  cv::Mat m = cv::imread(p.string());
  if (m.empty()) throw std::runtime_error("unreadable " + p.string());
  return m;
}

// One pair's identity distance (NaN when the check gave none: no face placed in a view) and the
// names of every input check it failed, same_person_face included.
struct Verdict {
  double distance = NAN;
  std::vector<std::string> failed;
};

Verdict check_pair(const cv::Mat& front, const cv::Mat& side) {
  reconstruct::ReconstructOptions o;
  o.observe.side_camera = vision::SideCamera::Right;
  o.check_identity = true;
  o.force = true;
  const reconstruct::Reconstruction r = reconstruct::from_photos(front, side, o);
  Verdict v;
  for (const auto& c : r.report.input_checks) {
    if (c.name == "same_person_face") v.distance = c.value;
    if (!c.passed) v.failed.push_back(c.name);
  }
  return v;
}

std::string fixed(double v, int digits = 3) {
  std::ostringstream s;
  s.precision(digits);
  s << std::fixed << v;
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: identity_bench DIR [OUTDIR] [--people a,b] [--offsets 0,1,2]\n";
    return 2;
  }
  const std::string dir = argv[1];
  std::string out_dir;
  std::vector<std::string> only_people;
  std::vector<int> offsets = {0, 1, 2};
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--people" && i + 1 < argc) {
      only_people = bench::split_list(argv[++i]);
    } else if (a == "--offsets" && i + 1 < argc) {
      offsets.clear();
      for (const std::string& x : bench::split_list(argv[++i])) {
        try {
          offsets.push_back(std::stoi(x));
        } catch (const std::exception&) {
          std::cerr << "error: --offsets: not a whole number: " << x << "\n";
          return 2;
        }
      }
    } else if (a.rfind("--", 0) != 0 && out_dir.empty()) {
      out_dir = a;
    } else {
      std::cerr << "error: unknown argument " << a << "\n";
      return 2;
    }
  }
  if (!fs::is_directory(dir)) {
    std::cout << json{{"skipped", "no FRMDB folder at " + dir}}.dump() << "\n";
    return 0;
  }
  try {
    bench::make_out_dir(out_dir);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  std::vector<std::string> people;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_directory() && fs::exists(e.path() / "Img_33.JPG") &&
        fs::exists(e.path() / "Img_53.JPG"))
      people.push_back(e.path().filename());
  std::sort(people.begin(), people.end());
  const double limit = vision::PairCheckLimits{}.max_face_distance;

  json pairs = json::array();
  std::vector<double> right, wrong;
  std::vector<std::string> right_refused;
  int unscored_right = 0, unscored_wrong = 0;
  int right_any = 0, wrong_any = 0,
      wrong_total = 0;  // refused by any check (the product's verdict)
  std::vector<double> seconds;
  for (size_t i = 0; i < people.size(); ++i) {
    if (!only_people.empty() && !std::count(only_people.begin(), only_people.end(), people[i]))
      continue;
    for (const int k : offsets) {
      const int n = int(people.size());  // the person k ids on, wrapping (k may be negative)
      const size_t j = size_t(((int(i) + k) % n + n) % n);
      const bool same = j == i;
      json r = {{"front", people[i]}, {"side", people[j]}, {"same_person", same}};
      Verdict v;
      const auto t0 = std::chrono::steady_clock::now();
      try {
        v = check_pair(img(fs::path(dir) / people[i] / "Img_33.JPG"),
                       img(fs::path(dir) / people[j] / "Img_53.JPG"));
      } catch (const std::exception& e) {
        r["error"] = e.what();
      }
      const double d = v.distance;
      r["failed_checks"] = v.failed;
      if (same)
        right_any += !v.failed.empty();
      else
        wrong_any += !v.failed.empty(), ++wrong_total;
      seconds.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      r["distance"] = io::number_or_null(d);
      if (std::isnan(d)) {
        ++(same ? unscored_right : unscored_wrong);
      } else if (same) {
        right.push_back(d);
        if (d > limit) right_refused.push_back(people[i]);
      } else {
        wrong.push_back(d);
      }
      std::cerr << people[i] << " + side of " << people[j] << ": "
                << (std::isnan(d) ? std::string("no value") : fixed(d)) << "\n";
      pairs.push_back(r);
    }
  }

  const double right_max = right.empty() ? NAN : *std::max_element(right.begin(), right.end());
  const double right_min = right.empty() ? NAN : *std::min_element(right.begin(), right.end());
  auto beyond = [&](double x) {
    return int(std::count_if(wrong.begin(), wrong.end(), [x](double v) { return v > x; }));
  };
  const int refused = beyond(limit);
  const int refused_at_right_max = std::isnan(right_max) ? 0 : beyond(right_max);
  json summary = {{"limit", limit},
                  {"right_pairs", right.size()},
                  {"right_unscored", unscored_right},
                  {"right_min", io::number_or_null(right_min)},
                  {"right_max", io::number_or_null(right_max)},
                  {"right_refused", right_refused},
                  {"wrong_pairings", wrong.size()},
                  {"wrong_unscored", unscored_wrong},
                  {"wrong_mean", io::number_or_null(bench::mean(wrong))},
                  {"wrong_refused", refused},
                  {"wrong_refused_at_right_max", refused_at_right_max},
                  {"right_refused_by_any_check", right_any},
                  {"wrong_refused_by_any_check", wrong_any},
                  {"median_seconds_per_pair", io::number_or_null(bench::median(seconds))}};
  const double share = wrong.empty() ? NAN : 100.0 * refused / double(wrong.size());
  std::string refused_names;
  for (const auto& p : right_refused) refused_names += (refused_names.empty() ? "" : ", ") + p;
  std::string md = "| same_person_face (limit " + fixed(limit, 2) +
                   ") | pairs scored | distance | refused |\n|---|---|---|---|\n";
  md += "| right pairs | " + std::to_string(right.size()) + " (" + std::to_string(unscored_right) +
        " no value) | " + fixed(right_min) + " .. " + fixed(right_max) + " | " +
        std::to_string(right_refused.size()) +
        (refused_names.empty() ? "" : " (" + refused_names + ")") + " |\n";
  md += "| wrong pairings | " + std::to_string(wrong.size()) + " (" +
        std::to_string(unscored_wrong) + " no value) | mean " + fixed(bench::mean(wrong)) + " | " +
        std::to_string(refused) + " (" + fixed(share, 0) + " %); " +
        std::to_string(refused_at_right_max) + " beyond the right pairs' largest |\n";
  md += "\nRefused by any input check (the gate before modelling, then this one): right pairs " +
        std::to_string(right_any) + ", wrong pairings " + std::to_string(wrong_any) + " of " +
        std::to_string(wrong_total) + ".\n";
  try {
    bench::write_report(out_dir, "identity", {{"summary", summary}, {"pairs", pairs}}, md);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
