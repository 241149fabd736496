#include "io/json_text.h"

#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace orthoface::io {

std::string json_type_name(const nlohmann::json& value) {
  if (value.is_number()) return "a number";
  if (value.is_string()) return "a string";
  if (value.is_boolean()) return "a boolean";
  if (value.is_array()) return "an array";
  if (value.is_object()) return "an object";
  return "null";
}

std::string json_type_error(const std::string& field, const std::string& expected,
                            const nlohmann::json& got) {
  return field + ": expected " + expected + ", got " + json_type_name(got);
}

nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

double json_number(const nlohmann::json& value, const std::string& field) {
  if (!value.is_number()) throw std::invalid_argument(json_type_error(field, "a number", value));
  const double d = value.get<double>();
  if (!std::isfinite(d)) throw std::invalid_argument(field + ": expected a finite number");
  return d;
}

std::string json_error_text(const std::exception& e) {
  const std::string text = e.what();
  if (text.rfind("[json.exception.", 0) != 0) return text;
  const size_t end = text.find("] ");
  return end == std::string::npos ? text : text.substr(end + 2);
}

}  // namespace orthoface::io
