// CSV recordings: parsing, missing samples, exact round trip, errors, and
// binding columns to a plant.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"
#include "config_test_util.hpp"

namespace mpm::config {
namespace {

std::string thrown_message(const std::string& csv) {
  return testing_util::config_error([&] { parse_recording(csv, "run.csv"); });
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(RecordingParse, ReadsHeaderAndValues) {
  const Recording rec = parse_recording("t,u1,y1\n0,1.5,-2e-3\n1,+2,3.25\n", "a.csv");
  EXPECT_EQ(rec.source, "a.csv");
  ASSERT_EQ(rec.names, (std::vector<std::string>{"t", "u1", "y1"}));
  ASSERT_EQ(rec.samples(), 2u);
  ASSERT_EQ(rec.data.cols(), 3);
  EXPECT_EQ(rec.data(0, 1), 1.5);
  EXPECT_EQ(rec.data(0, 2), -2e-3);
  EXPECT_EQ(rec.data(1, 0), 1.0);
  EXPECT_EQ(rec.data(1, 1), 2.0);
  EXPECT_EQ(rec.find("y1"), std::optional<std::size_t>(2));
  EXPECT_FALSE(rec.find("y2").has_value());
}

TEST(RecordingParse, EmptyFieldsAndNanWordsAreMissing) {
  const Recording rec = parse_recording("t,a,b,c\n0,,nan,NaN\n1,NAN,-nan,4\n2,1,2,\n", "m.csv");
  ASSERT_EQ(rec.samples(), 3u);
  EXPECT_TRUE(std::isnan(rec.data(0, 1)));
  EXPECT_TRUE(std::isnan(rec.data(0, 2)));
  EXPECT_TRUE(std::isnan(rec.data(0, 3)));
  EXPECT_TRUE(std::isnan(rec.data(1, 1)));
  EXPECT_TRUE(std::isnan(rec.data(1, 2)));
  EXPECT_EQ(rec.data(1, 3), 4.0);
  EXPECT_TRUE(std::isnan(rec.data(2, 3)));  // empty last field
  EXPECT_EQ(rec.data(2, 2), 2.0);
}

TEST(RecordingParse, ToleratesCrlfBomBlanksAndMissingFinalNewline) {
  const std::string variants[] = {
      "t,y\r\n0,1\r\n1,2\r\n",
      "\xEF\xBB\xBFt,y\n0,1\n1,2\n",
      "t , y\n 0 , 1\n1,2",
      "t,y\n0,1\n1,2\n\n\n",
  };
  for (const auto& csv : variants) {
    SCOPED_TRACE(csv);
    const Recording rec = parse_recording(csv, "v.csv");
    ASSERT_EQ(rec.names, (std::vector<std::string>{"t", "y"}));
    ASSERT_EQ(rec.samples(), 2u);
    EXPECT_EQ(rec.data(1, 1), 2.0);
  }
}

TEST(RecordingParse, HeaderOnlyGivesNoSamples) {
  const Recording rec = parse_recording("t,y\n", "h.csv");
  EXPECT_EQ(rec.samples(), 0u);
  EXPECT_EQ(rec.data.cols(), 2);
}

TEST(RecordingErrors, BadNumberNamesLineAndColumn) {
  const std::string m = thrown_message("t,u1,y1\n0,1,2\n1,1.2.3,2\n");
  EXPECT_EQ(m.rfind("run.csv:3:", 0), 0u) << m;
  EXPECT_TRUE(contains(m, "column 'u1'")) << m;
  EXPECT_TRUE(contains(m, "1.2.3")) << m;
}

TEST(RecordingErrors, InfinityIsNotASample) {
  const std::string m = thrown_message("t,y\n0,1\n1,2\n2,inf\n");
  EXPECT_EQ(m.rfind("run.csv:4:", 0), 0u) << m;
  EXPECT_TRUE(contains(m, "column 'y'")) << m;
}

TEST(RecordingErrors, WrongFieldCountNamesLineAndExpectedCount) {
  const std::string few = thrown_message("t,a,b\n0,1,2\n1,2\n");
  EXPECT_EQ(few.rfind("run.csv:3:", 0), 0u) << few;
  EXPECT_TRUE(contains(few, "expected 3 fields")) << few;
  EXPECT_TRUE(contains(few, "got 2")) << few;
  const std::string many = thrown_message("t,a,b\n0,1,2,3\n");
  EXPECT_EQ(many.rfind("run.csv:2:", 0), 0u) << many;
  EXPECT_TRUE(contains(many, "got 4")) << many;
  const std::string blank = thrown_message("t,a\n0,1\n\n2,3\n");
  EXPECT_EQ(blank.rfind("run.csv:3:", 0), 0u) << blank;
}

TEST(RecordingErrors, HeaderProblems) {
  const std::string dup = thrown_message("t,y,u,y\n0,1,2,3\n");
  EXPECT_EQ(dup.rfind("run.csv:1:", 0), 0u) << dup;
  EXPECT_TRUE(contains(dup, "duplicate column name 'y'")) << dup;
  EXPECT_TRUE(contains(dup, "columns 2 and 4")) << dup;
  EXPECT_TRUE(contains(thrown_message("t,,y\n"), "column 2")) << thrown_message("t,,y\n");
  EXPECT_TRUE(contains(thrown_message(""), "empty file"));
  EXPECT_TRUE(contains(thrown_message("\n\n"), "empty file"));
}

TEST(RecordingFiles, MissingFileIsNamed) {
  const auto path = testing_util::temp_dir("recording") / "absent.csv";
  const std::string e = testing_util::config_error([&] { load_recording(path.string()); });
  EXPECT_TRUE(contains(e, path.string())) << e;
}

// Random bit patterns cover subnormals, signed zeros and extreme exponents;
// non-finite patterns become NaN (a missing sample).
TEST(RecordingFiles, WriteThenReadIsBitExact) {
  std::mt19937_64 rng(20210817);
  Recording rec;
  rec.names = {"t", "u1", "y1", "odd"};
  rec.data.resize(500, 4);
  for (Eigen::Index r = 0; r < rec.data.rows(); ++r) {
    rec.data(r, 0) = static_cast<double>(r) * 0.1;
    for (Eigen::Index c = 1; c < 4; ++c) {
      const double x = std::bit_cast<double>(rng());
      rec.data(r, c) = std::isfinite(x) ? x : std::numeric_limits<double>::quiet_NaN();
    }
  }
  rec.data(0, 1) = -0.0;
  rec.data(1, 1) = std::numeric_limits<double>::denorm_min();
  rec.data(2, 1) = std::numeric_limits<double>::max();
  rec.data(3, 1) = 1.0 / 3.0;
  rec.data(4, 1) = std::numeric_limits<double>::quiet_NaN();
  const auto path = testing_util::temp_dir("recording") / "roundtrip.csv";
  write_recording(path.string(), rec);
  const Recording back = load_recording(path.string());
  EXPECT_EQ(back.names, rec.names);
  ASSERT_EQ(back.data.rows(), rec.data.rows());
  ASSERT_EQ(back.data.cols(), rec.data.cols());
  int mismatches = 0;
  for (Eigen::Index r = 0; r < rec.data.rows(); ++r)
    for (Eigen::Index c = 0; c < rec.data.cols(); ++c) {
      const double a = rec.data(r, c), b = back.data(r, c);
      const bool same = std::isnan(a)
                            ? std::isnan(b)
                            : std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
      if (!same) ++mismatches;
    }
  EXPECT_EQ(mismatches, 0);
}

TEST(RecordingFiles, WriterRefusesWhatCannotBeReadBack) {
  const auto dir = testing_util::temp_dir("recording");
  Recording rec;
  rec.names = {"t", "y"};
  rec.data = Eigen::MatrixXd::Zero(2, 2);
  rec.data(1, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(write_recording((dir / "inf.csv").string(), rec), ConfigError);
  rec.data(1, 1) = 0.0;
  rec.names = {"t", "a,b"};
  EXPECT_THROW(write_recording((dir / "comma.csv").string(), rec), ConfigError);
  rec.names = {"t"};
  EXPECT_THROW(write_recording((dir / "size.csv").string(), rec), ConfigError);
}

TEST(RecordingFiles, LargeFileLoadsCompletely) {
  // 200 000 rows x 5 columns: checks the one-pass reader on a big input
  // (every value checked, no timing assertion).
  const Eigen::Index rows = 200'000;
  Recording rec;
  rec.names = {"t", "u1", "u2", "y1", "y2"};
  rec.data.resize(rows, 5);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise;
  for (Eigen::Index r = 0; r < rows; ++r) {
    rec.data(r, 0) = static_cast<double>(r);
    for (Eigen::Index c = 1; c < 5; ++c) rec.data(r, c) = 50.0 + noise(rng);
  }
  const auto path = testing_util::temp_dir("recording") / "large.csv";
  write_recording(path.string(), rec);
  const Recording back = load_recording(path.string());
  ASSERT_EQ(back.data.rows(), rows);
  EXPECT_TRUE(back.data == rec.data);
}

PlantModel two_by_one_plant() {
  return parse_plant(R"(plant: p
sample_time: 0.5
inputs: [u1, u2]
outputs: [y1]
model:
  - {output: y1, input: u1, num: [1]}
)",
                     "p.yaml");
}

TEST(Bind, MatchesColumnsByName) {
  const Recording rec =
      parse_recording("r_y1,u2,t,feed,y1,sim_y1,u1\n1,2,0,3,4,5,6\n1,2,0.5,3,4,5,6\n", "b.csv");
  const BoundRecording b = bind(two_by_one_plant(), rec);
  EXPECT_EQ(b.time, 2u);
  EXPECT_EQ(b.inputs, (std::vector<std::size_t>{6, 1}));
  EXPECT_EQ(b.outputs, (std::vector<std::size_t>{4}));
  ASSERT_EQ(b.sim.size(), 1u);
  EXPECT_EQ(b.sim[0], std::optional<std::size_t>(5));
  EXPECT_EQ(b.setpoints[0], std::optional<std::size_t>(0));
  EXPECT_EQ(b.extra, (std::vector<std::size_t>{3}));
}

TEST(Bind, OptionalColumnsMayBeAbsent) {
  const Recording rec = parse_recording("t,u1,u2,y1\n0,1,2,3\n", "b.csv");
  const BoundRecording b = bind(two_by_one_plant(), rec);
  EXPECT_FALSE(b.sim[0].has_value());
  EXPECT_FALSE(b.setpoints[0].has_value());
  EXPECT_TRUE(b.extra.empty());
}

std::string bind_message(const std::string& csv) {
  return testing_util::config_error([&] { bind(two_by_one_plant(), parse_recording(csv, "run.csv")); });
}

TEST(Bind, MissingColumnsAreNamed) {
  const std::string no_input = bind_message("t,u1,y1\n0,1,2\n");
  EXPECT_TRUE(contains(no_input, "run.csv")) << no_input;
  EXPECT_TRUE(contains(no_input, "'u2'")) << no_input;
  EXPECT_TRUE(contains(bind_message("u1,u2,y1\n0,1,2\n"), "'t'"));
  EXPECT_TRUE(contains(bind_message("t,u1,u2\n0,1,2\n"), "'y1'"));
}

TEST(Bind, TimeMustStepBySampleTime) {
  EXPECT_EQ(bind_message("t,u1,u2,y1\n0,1,2,3\n0.5,1,2,3\n1.0000001,1,2,3\n"),
            "(no ConfigError thrown)");  // within the 1e-6 relative tolerance
  const std::string skip = bind_message("t,u1,u2,y1\n0,1,2,3\n0.5,1,2,3\n1.5,1,2,3\n");
  EXPECT_EQ(skip.rfind("run.csv:4:", 0), 0u) << skip;
  EXPECT_TRUE(contains(skip, "column 't'")) << skip;
  const std::string back = bind_message("t,u1,u2,y1\n0,1,2,3\n-0.5,1,2,3\n");
  EXPECT_EQ(back.rfind("run.csv:3:", 0), 0u) << back;
  const std::string hole = bind_message("t,u1,u2,y1\n0,1,2,3\n,1,2,3\n");
  EXPECT_EQ(hole.rfind("run.csv:3:", 0), 0u) << hole;
  EXPECT_TRUE(contains(hole, "missing")) << hole;
}

}  // namespace
}  // namespace mpm::config
