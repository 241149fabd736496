#include "vision/observation_io.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/json_text.h"
#include "vision/landmarks.h"

namespace orthoface::vision {

namespace {

using nlohmann::json;

json features_json(const std::map<std::string, Feature2d>& features) {
  json f = json::object();
  for (const auto& [n, x] : features)
    f[n] = {{"x", x.px.x},
            {"y", x.px.y},
            {"confidence", x.confidence},
            {"method", x.method},
            {"mirrored", x.mirrored}};
  return f;
}

json view_json(const ViewObservation& v) {
  json b = json::array();
  for (const auto& p : v.boundary) b.push_back({p.x, p.y});
  return {{"width", v.width},
          {"height", v.height},
          {"boundary", b},
          {"boundary_confidence", v.boundary_confidence},
          {"features", features_json(v.features)}};
}

// Field `name` of the object `j` found at `where` ("front.", "" at the top level).
const json& field(const json& j, const char* name, const std::string& where) {
  if (!j.is_object())
    throw std::invalid_argument(io::json_type_error(
        where.empty() ? "top level" : where.substr(0, where.size() - 1), "an object", j));
  if (!j.contains(name)) throw std::invalid_argument(where + name + ": missing");
  return j.at(name);
}

double number(const json& j, const char* name, const std::string& where) {
  return io::json_number(field(j, name, where), where + name);
}

// A features object ({name: {x, y, confidence, method, mirrored}}) at `where`.
std::map<std::string, Feature2d> features_from(const json& f, const std::string& where) {
  if (!f.is_object()) throw std::invalid_argument(io::json_type_error(where, "an object", f));
  std::map<std::string, Feature2d> out;
  for (const auto& [name, x] : f.items()) {
    if (!is_landmark_name(name))
      throw std::invalid_argument(where + "." + name + ": unknown landmark name");
    const std::string w = where + "." + name + ".";
    Feature2d g;
    g.px = {number(x, "x", w), number(x, "y", w)};
    g.confidence = number(x, "confidence", w);
    const json& m = field(x, "method", w);
    const json& mi = field(x, "mirrored", w);
    if (!m.is_string())
      throw std::invalid_argument(io::json_type_error(w + "method", "a string", m));
    if (!mi.is_boolean())
      throw std::invalid_argument(io::json_type_error(w + "mirrored", "true or false", mi));
    g.method = m.get<std::string>();
    g.mirrored = mi.get<bool>();
    out[name] = g;
  }
  return out;
}

ViewObservation view_from(const json& j, const std::string& where) {
  ViewObservation v;
  v.width = int(number(j, "width", where));
  v.height = int(number(j, "height", where));
  v.boundary_confidence = number(j, "boundary_confidence", where);
  const json& b = field(j, "boundary", where);
  if (!b.is_array())
    throw std::invalid_argument(io::json_type_error(where + "boundary", "an array", b));
  for (size_t i = 0; i < b.size(); ++i) {
    const json& p = b[i];
    const std::string item = where + "boundary[" + std::to_string(i) + "]";
    if (!p.is_array() || p.size() != 2)
      throw std::invalid_argument(io::json_type_error(item, "a point [x, y]", p));
    v.boundary.emplace_back(io::json_number(p[0], item + "[0]"),
                            io::json_number(p[1], item + "[1]"));
  }
  v.features = features_from(field(j, "features", where), where + "features");
  return v;
}

}  // namespace

json to_json(const FaceObservation& o) {
  return {{"front", view_json(o.front)},
          {"side", view_json(o.side)},
          {"centre_line",
           {{"x_px", o.centre_x_px},
            {"y_px", o.centre_y_px},
            {"roll_rad", o.roll_rad},
            {"confidence", o.centre_confidence}}},
          {"side_faces_left", o.side_faces_left},
          {"front_trained", features_json(o.front_trained)},
          {"warnings", o.warnings}};
}

FaceObservation observation_from_json(const json& j) {
  FaceObservation o;
  o.front = view_from(field(j, "front", ""), "front.");
  o.side = view_from(field(j, "side", ""), "side.");
  const json& c = field(j, "centre_line", "");
  o.centre_x_px = number(c, "x_px", "centre_line.");
  o.centre_y_px = number(c, "y_px", "centre_line.");
  o.roll_rad = number(c, "roll_rad", "centre_line.");
  o.centre_confidence = number(c, "confidence", "centre_line.");
  const json& s = field(j, "side_faces_left", "");
  if (!s.is_boolean())
    throw std::invalid_argument(io::json_type_error("side_faces_left", "true or false", s));
  o.side_faces_left = s.get<bool>();
  if (j.contains("front_trained"))  // optional: observations written before it existed
    o.front_trained = features_from(j.at("front_trained"), "front_trained");
  const json& w = field(j, "warnings", "");
  if (!w.is_array()) throw std::invalid_argument(io::json_type_error("warnings", "an array", w));
  for (size_t i = 0; i < w.size(); ++i) {
    if (!w[i].is_string())
      throw std::invalid_argument(
          io::json_type_error("warnings[" + std::to_string(i) + "]", "a string", w[i]));
    o.warnings.push_back(w[i].get<std::string>());
  }
  return o;
}

void write_observation(const FaceObservation& obs, const std::string& path) {
  io::write_text_atomically(path, to_json(obs).dump(1) + "\n");
}

FaceObservation read_observation(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("observation file '" + path + "': cannot be read");
  try {
    return observation_from_json(json::parse(f));
  } catch (const json::exception& e) {
    throw std::runtime_error("observation file '" + path + "': not valid JSON (" +
                             io::json_error_text(e) + ")");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("observation file '" + path + "': " + e.what());
  }
}

}  // namespace orthoface::vision
