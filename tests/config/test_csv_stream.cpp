// The streaming row reader (csv_stream.hpp) against load_recording: the same
// names, the same values (NaN where missing) and the same located errors, on
// files that cross its 1 MiB read chunks.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "config/csv_stream.hpp"
#include "config/plant_loader.hpp"
#include "config_test_util.hpp"

namespace mpm::config {
namespace {

void expect_same(const std::string& text, const std::string& tag) { (void)testing_util::read_both(text, tag); }

TEST(CsvStream, SameAsWholeFileReader) {
  expect_same("t,u1,y1\n0,1,2\n1,,nan\n2,3.5,-1e-300\n", "plain");
  expect_same("\xEF\xBB\xBFt, u1 ,y1\r\n0,1,2\r\n1,1,2\r\n\r\n\n", "bom_crlf_trailing_blank");
  expect_same("t,u1,y1\n0,1,2", "no_final_newline");
  expect_same("t\n0\n\n2\n", "blank_row_one_column");
}

TEST(CsvStream, SameErrors) {
  expect_same("", "empty");
  expect_same("\n\n  \n", "only_blank");
  expect_same("\nt,u\n0,1\n", "blank_header");
  expect_same("t,u1,u1\n", "duplicate");
  expect_same("t,u1,y1\n0,1,2\n\n2,3,4\n", "blank_row_many_columns");
  expect_same("t,u1,y1\n0,1,2\n1,x,2\n", "bad_value");
  expect_same("t,u1,y1\n0,1,2\n1,2\n", "short_row");
  expect_same("t,u1,y1\n0,1,inf\n", "infinite");
  // A blank line of carriage returns before more data (found by fuzz_csv).
  expect_same("1\n\r\r\n1D,2,3\r\n1,,\r\n", "blank_cr_line_before_data");
  // A header of carriage returns before a line of data: the CR is the error
  // in both (found by fuzz_csv in the dialect-aware tokenizer).
  expect_same("\r\r\n'\r\n", "cr_header_before_data");
}

TEST(CsvStream, RowsAcrossReadChunks) {
  std::string text = "t,u1,u2,y1,y2\n";
  for (int k = 0; k < 80000; ++k)
    text += std::to_string(k) + "," + std::to_string(k * 0.25) + ",," + std::to_string(-k) + ",1e-7\n";
  ASSERT_GT(text.size(), 2u << 20);
  expect_same(text, "long");
}

TEST(CsvStream, RefusesNonRegularFiles) {
  EXPECT_THROW(CsvRowReader("/dev/zero"), ConfigError);
}

}  // namespace
}  // namespace mpm::config
