// Helpers shared by the config tests.
#pragma once

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "config/csv_stream.hpp"
#include "config/plant_loader.hpp"

namespace mpm::config::testing_util {

// A fresh directory under GoogleTest's temp dir, unique per process so that
// test executables running in parallel do not share files.
inline std::filesystem::path temp_dir(const std::string& tag) {
  const auto dir = std::filesystem::path(::testing::TempDir()) /
                   ("mpm_config_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

// The message of the ConfigError that `load()` throws, or "(no ConfigError
// thrown)" (any other exception escapes and fails the test).
template <class Load>
std::string config_error(Load&& load) {
  try {
    load();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no ConfigError thrown)";
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << "cannot write " << path;
}

// `text` as a file read by both CSV readers: load_recording and the
// streaming CsvRowReader must give the same names and values (NaN where
// missing) or the same located error. Returns the recording, or the error
// in `error`.
struct BothReaders {
  Recording rec;
  std::string error;
};
inline BothReaders read_both(const std::string& text, const std::string& tag) {
  const auto path = (temp_dir("csv_both") / (tag + ".csv")).string();
  write_text(path, text);
  BothReaders whole;
  try {
    whole.rec = load_recording(path);
  } catch (const ConfigError& e) {
    whole.error = e.what();
  }
  std::string stream_error;
  std::vector<std::string> names;
  std::vector<double> values;
  try {
    CsvRowReader reader(path);
    names = reader.names();
    std::vector<double> row;
    while (reader.next(row)) values.insert(values.end(), row.begin(), row.end());
  } catch (const ConfigError& e) {
    stream_error = e.what();
  }
  EXPECT_EQ(stream_error, whole.error) << tag;
  if (!whole.error.empty()) return whole;
  EXPECT_EQ(names, whole.rec.names) << tag;
  EXPECT_EQ(values.size(), static_cast<std::size_t>(whole.rec.data.size())) << tag;
  std::size_t k = 0;
  for (Eigen::Index r = 0; r < whole.rec.data.rows(); ++r)
    for (Eigen::Index c = 0; c < whole.rec.data.cols() && k < values.size(); ++c, ++k) {
      const double a = whole.rec.data(r, c), b = values[k];
      EXPECT_TRUE((std::isnan(a) && std::isnan(b)) || a == b) << tag << " row " << r << " col " << c;
    }
  return whole;
}

}  // namespace mpm::config::testing_util
