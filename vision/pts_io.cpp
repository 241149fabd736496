#include "vision/pts_io.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "io/atomic_file.h"

namespace orthoface::vision {
namespace {

// File pixel indices <-> capture convention (pixel centre = index + 0.5).
constexpr double kHalf = 0.5;

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

// Lines without surrounding blanks, blank lines dropped, with their 1-based line numbers.
std::vector<std::pair<int, std::string>> content_lines(std::istream& in) {
  std::vector<std::pair<int, std::string>> out;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n)
    if (const std::string t = trim(line); !t.empty()) out.emplace_back(n, t);
  return out;
}

// "key: value" -> value, when the line starts with `key`.
bool header_value(const std::string& line, const std::string& key, std::string& value) {
  if (line.rfind(key, 0) != 0) return false;
  std::string rest = trim(line.substr(key.size()));
  if (rest.empty() || rest[0] != ':') return false;
  value = trim(rest.substr(1));
  return true;
}

// The whole token as a number; strtod also reads "nan", "inf" and overflows to inf, which the
// caller then reports as non-finite rather than as text.
bool parse_double(const std::string& token, double& v) {
  char* end = nullptr;
  v = std::strtod(token.c_str(), &end);
  return !token.empty() && end == token.c_str() + token.size();
}

}  // namespace

void write_pts(const Ibug68& points, const std::string& path) {
  for (int k = 0; k < kIbug68Count; ++k) {
    if (!points[k]) continue;
    const cv::Point2d q = *points[k] - cv::Point2d(kHalf, kHalf);
    if (!std::isfinite(q.x) || !std::isfinite(q.y))
      throw std::invalid_argument("write_pts " + path + ": point " + std::to_string(k) +
                                  " is not finite");
    if (q.x == -1 && q.y == -1)
      throw std::invalid_argument("write_pts " + path + ": point " + std::to_string(k) +
                                  " is at the missing-point marker (-1, -1)");
  }
  std::ostringstream s;
  s << "version: 1\nn_points: " << kIbug68Count << "\n{\n";
  char buf[64];
  for (const auto& p : points) {
    if (!p) {
      s << "-1 -1\n";
      continue;
    }
    std::snprintf(buf, sizeof buf, "%.17g %.17g\n", p->x - kHalf, p->y - kHalf);
    s << buf;
  }
  s << "}\n";
  io::write_text_atomically(path, s.str());
}

Ibug68 read_pts(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("landmark file " + path + ": cannot be read");
  const auto lines = content_lines(in);
  auto fail = [&](int line, const std::string& what) {
    throw std::runtime_error("landmark file " + path +
                             (line > 0 ? " line " + std::to_string(line) : std::string()) + ": " +
                             what);
  };
  std::string value;
  if (lines.empty()) fail(0, "empty; expected an iBUG .pts file ('version: 1', 'n_points: 68')");
  if (!header_value(lines[0].second, "version", value) || value != "1")
    fail(lines[0].first, "bad header: expected 'version: 1', got '" + lines[0].second + "'");
  if (lines.size() < 2 || !header_value(lines[1].second, "n_points", value))
    fail(lines.size() < 2 ? 0 : lines[1].first, "bad header: expected 'n_points: 68'");
  if (value != "68")
    fail(lines[1].first, "n_points is '" + value + "'; only the 68-point iBUG layout is accepted");
  if (lines.size() < 3 || lines[2].second != "{")
    fail(lines.size() < 3 ? 0 : lines[2].first, "missing opening brace '{' after the header");
  Ibug68 out;
  size_t i = 3;
  int k = 0;
  for (; i < lines.size() && lines[i].second != "}"; ++i, ++k) {
    const auto& [n, text] = lines[i];
    if (k >= kIbug68Count) fail(n, "more than 68 points (or a missing closing brace '}')");
    std::istringstream s(text);
    std::string xs, ys, extra;
    s >> xs >> ys >> extra;
    double x = 0, y = 0;
    if (ys.empty() || !extra.empty() || !parse_double(xs, x) || !parse_double(ys, y))
      fail(n, "point " + std::to_string(k) + ": expected two numbers 'x y', got '" + text + "'");
    if (!std::isfinite(x) || !std::isfinite(y))
      fail(n, "point " + std::to_string(k) + ": coordinate is not finite");
    if (x == -1 && y == -1) continue;  // missing
    out[k] = cv::Point2d(x + kHalf, y + kHalf);
  }
  if (i == lines.size()) {
    if (k < kIbug68Count)
      fail(0, "only " + std::to_string(k) + " points before the end; expected 68 and '}'");
    fail(0, "missing closing brace '}'");
  }
  if (k != kIbug68Count) fail(lines[i].first, "only " + std::to_string(k) + " points; expected 68");
  if (i + 1 != lines.size()) fail(lines[i + 1].first, "text after the closing brace '}'");
  return out;
}

void check_pts_in_image(const Ibug68& points, int width, int height, const std::string& what) {
  for (int k = 0; k < kIbug68Count; ++k) {
    if (!points[k]) continue;
    const cv::Point2d p = *points[k];
    if (!(p.x >= 0 && p.y >= 0 && p.x <= width && p.y <= height))
      throw std::invalid_argument(what + ": point " + std::to_string(k) + " at (" +
                                  std::to_string(p.x - kHalf) + ", " + std::to_string(p.y - kHalf) +
                                  ") lies outside the " + std::to_string(width) + "x" +
                                  std::to_string(height) + " image");
  }
}

}  // namespace orthoface::vision
