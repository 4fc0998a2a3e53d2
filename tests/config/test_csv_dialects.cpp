// CSV as historians export it (issue 14, item 3; formats.md section 4.4):
// ISO-8601 times in t, ';' separators with decimal commas, RFC 4180
// quoting, a UTF-8 BOM and CRLF, each read the same by the whole-file and
// the streaming reader; every other dialect a clear error naming the file
// and the line.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"
#include "config_test_util.hpp"

namespace mpm::config {
namespace {

using testing_util::read_both;

constexpr double k20261125T08 = 1795593600.0;  // 2026-11-25T08:00:00Z, seconds since the epoch

const PlantModel& plant() {  // sample_time 1, inputs u1, outputs y1
  static const PlantModel p = parse_plant(
      "plant: p\nsample_time: 1\ninputs: [u1]\noutputs: [y1]\nmodel:\n  - {output: y1, input: u1, num: [1]}\n",
      "p.yaml");
  return p;
}

Recording read_ok(const std::string& text, const std::string& tag) {
  const auto both = read_both(text, tag);
  EXPECT_EQ(both.error, "") << tag;
  return both.rec;
}

std::string read_error(const std::string& text, const std::string& tag) {
  const auto both = read_both(text, tag);
  EXPECT_NE(both.error, "") << tag << " was accepted";
  return both.error;
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// `rec` has these columns and these rows (kNaN where a field is empty or nan).
void expect_table(const Recording& rec, const std::vector<std::string>& names,
                  const std::vector<std::vector<double>>& rows) {
  ASSERT_EQ(rec.names, names);
  ASSERT_EQ(rec.samples(), rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    for (std::size_t c = 0; c < names.size(); ++c) {
      const double got = rec.data(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(c));
      if (std::isnan(rows[k][c])) {
        EXPECT_TRUE(std::isnan(got)) << "row " << k << ", column " << names[c] << ": " << got;
      } else {
        EXPECT_EQ(got, rows[k][c]) << "row " << k << ", column " << names[c];
      }
    }
  }
}

TEST(CsvDialects, Iso8601TimesBecomeSecondsAndTheStepIsChecked) {
  const Recording good = read_ok(
      "t,u1,y1\n2026-11-25T08:00:00Z,1,2\n2026-11-25 08:00:01,1,2\n2026-11-25T09:00:02+01:00,1,2\n"
      "2026-11-25T08:00:03.000Z,1,2\n2026-11-25T07:30:04-00:30,1,2\n",
      "iso_good");
  ASSERT_EQ(good.samples(), 5u);
  for (Eigen::Index k = 0; k < 5; ++k) EXPECT_EQ(good.data(k, 0), k20261125T08 + static_cast<double>(k)) << k;
  EXPECT_NO_THROW((void)bind(plant(), read_ok("t,u1,y1\n2026-11-25T08:00:00.5Z,1,2\n2026-11-25T08:00:01.5Z,1,2\n",
                                              "iso_step")));
  try {
    (void)bind(plant(), read_ok("t,u1,y1\n2026-11-25T08:00:00Z,1,2\n2026-11-25T08:00:02Z,1,2\n", "iso_gap"));
    ADD_FAILURE() << "a 2 s step passed a 1 s sample time";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("iso_gap.csv:3: column 't': time goes from"), std::string::npos) << e.what();
  }
}

TEST(CsvDialects, ImpossibleTimesAndDatesOutsideTAreLocatedErrors) {
  for (const char* bad : {"2026-02-30T00:00:00Z", "2026-11-25T24:00:00Z", "2026-11-25T08:00:60Z",
                          "2026-11-25T08:00Z+1", "2026-13-01T00:00:00Z", "2026-11-25"}) {
    const std::string e = read_error(std::string("t,u1,y1\n0,1,2\n") + bad + ",1,2\n", "bad_time");
    EXPECT_NE(e.find("bad_time.csv:3: column 't': expected a time in seconds or an ISO-8601 time"), std::string::npos)
        << e;
  }
  const std::string e = read_error("t,u1,y1\n0,2026-11-25T08:00:00Z,2\n", "date_in_u");
  EXPECT_NE(e.find("date_in_u.csv:2: column 'u1': expected a finite number"), std::string::npos) << e;
}

TEST(CsvDialects, SemicolonSeparatorIsDetectedAndTakesDecimalCommas) {
  expect_table(read_ok("t;u1;y1\n0;1,5;-2.25\n1;;nan\n", "semicolon"), {"t", "u1", "y1"},
               {{0, 1.5, -2.25}, {1, kNaN, kNaN}});
  // A comma is not a separator there: a row split by commas has too few fields.
  const std::string e = read_error("t;u1;y1\n0,1,2\n", "semicolon_commas");
  EXPECT_NE(e.find("semicolon_commas.csv:2: expected 3 fields (as in the header), got 1"), std::string::npos) << e;
}

TEST(CsvDialects, Rfc4180QuotesAreStrippedAndDoubledQuotesUnescaped) {
  expect_table(read_ok("\"t\",\"u1\",\"y \"\"hot\"\", C\"\n\"0\",\"1.5\", \"2\" \n1,,\"\"\n", "quoted"),
               {"t", "u1", "y \"hot\", C"}, {{0, 1.5, 2.0}, {1, kNaN, kNaN}});
  // A quoted name with ';' inside does not make the file ';'-separated.
  EXPECT_EQ(read_ok("t,\"a;b\",u1\n0,1,2\n", "quoted_semicolon").names[1], "a;b");
}

TEST(CsvDialects, BomCrlfAndQuotesTogether) {
  expect_table(read_ok("\xEF\xBB\xBF\"t\";\"u1\";\"y1\"\r\n2026-11-25T08:00:00Z;\"3,25\";4\r\n", "bom_crlf"),
               {"t", "u1", "y1"}, {{k20261125T08, 3.25, 4.0}});
}

TEST(CsvDialects, OtherDialectsAreRefusedByName) {
  const struct {
    const char* text;
    const char* message;
  } cases[] = {
      {"t,u1;y1\n", "both.csv:1: header: both ',' and ';' outside quotes"},
      {"t\tu1\ty1\n0\t1\t2\n", "tabs.csv:1: header: tab-separated columns are not read"},
      {"\xFF\xFEt\0,\0", "utf16.csv:1: UTF-16 text is not read"},
      {"t,u1,y1\r0,1,2\r", "cr.csv:1: a carriage return inside a line"},
      {"t,u1,y1\n0,\"1,2\n", "open_quote.csv:2: column 'u1': a quoted field has no closing quote"},
      {"t,u1,y1\n0,\"1\"x,2\n", "after_quote.csv:2: column 'u1': text after a quoted field's closing quote"},
      {"t,\"u1\n", "header_quote.csv:1: header, column 2: a quoted field has no closing quote"},
  };
  const char* tags[] = {"both", "tabs", "utf16", "cr", "open_quote", "after_quote", "header_quote"};
  for (std::size_t k = 0; k < std::size(cases); ++k) {
    const std::string text(cases[k].text, k == 2 ? 6 : std::char_traits<char>::length(cases[k].text));
    const std::string e = read_error(text, tags[k]);
    EXPECT_NE(e.find(cases[k].message), std::string::npos) << e;
    for (const char c : e) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20) << "control character in: " << e;
  }
}

}  // namespace
}  // namespace mpm::config
