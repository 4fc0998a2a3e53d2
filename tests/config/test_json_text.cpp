// The JSON scalar text shared by the report writers (config/json_text.hpp).
#include "config/json_text.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace mpm::config {
namespace {

TEST(JsonText, StringsEscapeQuotesBackslashesAndControls) {
  EXPECT_EQ(json_string("plain"), "\"plain\"");
  EXPECT_EQ(json_string("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(json_string("l1\nl2\tx"), "\"l1\\nl2\\tx\"");
  EXPECT_EQ(json_string(std::string("\x01\x1f", 2)), "\"\\u0001\\u001f\"");
  EXPECT_EQ(json_string("\xc3\xa9"), "\"\xc3\xa9\"");  // UTF-8 passes through
}

TEST(JsonText, NumbersHaveTheirDigitsAndNonFiniteIsNull) {
  EXPECT_EQ(json_number(1.0 / 3.0, 8), "0.33333333");
  EXPECT_EQ(json_number(1.0 / 3.0, 4), "0.3333");
  EXPECT_EQ(json_number(-2.5e-12, 6), "-2.5e-12");
  EXPECT_EQ(json_number(std::nan(""), 8), "null");
  EXPECT_EQ(json_number(std::numeric_limits<double>::infinity(), 8), "null");
  EXPECT_EQ(json_number_list({1.0, -0.9419, std::nan("")}, 10), "[1, -0.9419, null]");
  EXPECT_EQ(json_number_list({}, 10), "[]");
}

}  // namespace
}  // namespace mpm::config
