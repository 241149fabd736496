#pragma once
// Plain words for what is wrong in a JSON input, so an error names the field and the type it had
// instead of the JSON library's own text.

#include <exception>
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace orthoface::io {

// "a number", "a string", "a boolean", "an array", "an object" or "null".
std::string json_type_name(const nlohmann::json& value);

// "FIELD: expected EXPECTED, got TYPE", e.g. "points.nose_tip: expected a number, got a string".
std::string json_type_error(const std::string& field, const std::string& expected,
                            const nlohmann::json& got);

// `value` as a finite number. Throws std::invalid_argument "FIELD: expected a number, got a
// string" or "FIELD: expected a finite number" (the caller names the file).
double json_number(const nlohmann::json& value, const std::string& field);

// `v` as a JSON number, or null when it is not finite (a measure that was not taken).
nlohmann::json number_or_null(double v);

// The text of a JSON library exception without its "[json.exception.parse_error.101] " tag.
std::string json_error_text(const std::exception& e);

}  // namespace orthoface::io
