#include "io/json_text.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace orthoface::io {
namespace {

using nlohmann::json;

std::string refusal(const json& value, const std::string& field) {
  try {
    json_number(value, field);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(JsonText, NumbersAreReadAndEverythingElseIsNamed) {
  EXPECT_EQ(json_number(json(2.5), "a"), 2.5);
  EXPECT_EQ(json_number(json(-3), "a"), -3.0);
  EXPECT_EQ(refusal(json("2.5"), "points.x"), "points.x: expected a number, got a string");
  EXPECT_EQ(refusal(json(true), "f"), "f: expected a number, got a boolean");
  EXPECT_EQ(refusal(json::array({1}), "f"), "f: expected a number, got an array");
  EXPECT_EQ(refusal(json::object(), "f"), "f: expected a number, got an object");
  EXPECT_EQ(refusal(json(), "f"), "f: expected a number, got null");
  EXPECT_EQ(refusal(json(std::numeric_limits<double>::infinity()), "f"),
            "f: expected a finite number");
  EXPECT_EQ(refusal(json(std::nan("")), "f"), "f: expected a finite number");
  EXPECT_EQ(json_type_error("top level", "an object", json::array()),
            "top level: expected an object, got an array");
}

TEST(JsonText, AMeasureNotTakenIsNull) {
  EXPECT_EQ(number_or_null(2.5), nlohmann::json(2.5));
  EXPECT_TRUE(number_or_null(std::numeric_limits<double>::quiet_NaN()).is_null());
  EXPECT_TRUE(number_or_null(-std::numeric_limits<double>::infinity()).is_null());
}

TEST(JsonText, LibraryMessagesLoseTheirTag) {
  try {
    const json j = json::parse("{ \"a\": ");
    ADD_FAILURE() << "parsed " << j.dump();
  } catch (const json::exception& e) {
    const std::string text = json_error_text(e);
    EXPECT_EQ(text.find("[json.exception"), std::string::npos) << text;
    EXPECT_NE(text.find("parse error"), std::string::npos) << text;
  }
  EXPECT_EQ(json_error_text(std::runtime_error("plain")), "plain");
  EXPECT_EQ(json_error_text(std::runtime_error("[json.exception.x] no end")), "no end");
  EXPECT_EQ(json_error_text(std::runtime_error("[json.exception.x")), "[json.exception.x");
}

}  // namespace
}  // namespace orthoface::io
