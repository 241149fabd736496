#include "io/json_text.h"

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

std::string json_error_text(const std::exception& e) {
  const std::string text = e.what();
  if (text.rfind("[json.exception.", 0) != 0) return text;
  const size_t end = text.find("] ");
  return end == std::string::npos ? text : text.substr(end + 2);
}

}  // namespace orthoface::io
