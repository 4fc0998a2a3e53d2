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

// Streams `path` into a Recording, or returns the error text.
std::string stream_all(const std::string& path, std::vector<std::string>& names, std::vector<double>& values) {
  try {
    CsvRowReader reader(path);
    names = reader.names();
    std::vector<double> row;
    while (reader.next(row)) values.insert(values.end(), row.begin(), row.end());
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

void expect_same(const std::string& text, const std::string& tag) {
  const auto path = (testing_util::temp_dir("csv_stream") / (tag + ".csv")).string();
  testing_util::write_text(path, text);
  std::string whole_error;
  Recording rec;
  try {
    rec = load_recording(path);
  } catch (const ConfigError& e) {
    whole_error = e.what();
  }
  std::vector<std::string> names;
  std::vector<double> values;
  EXPECT_EQ(stream_all(path, names, values), whole_error) << tag;
  if (!whole_error.empty()) return;
  EXPECT_EQ(names, rec.names) << tag;
  ASSERT_EQ(values.size(), static_cast<std::size_t>(rec.data.size())) << tag;
  std::size_t k = 0;
  for (Eigen::Index r = 0; r < rec.data.rows(); ++r)
    for (Eigen::Index c = 0; c < rec.data.cols(); ++c, ++k) {
      const double a = rec.data(r, c), b = values[k];
      EXPECT_TRUE((std::isnan(a) && std::isnan(b)) || a == b) << tag << " row " << r << " col " << c;
    }
}

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
