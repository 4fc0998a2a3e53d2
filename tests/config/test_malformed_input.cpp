// Damaged files never crash the loaders and never leak another exception
// type: every truncation and many random byte edits of a valid plant file and
// recording either load or throw ConfigError.
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"
#include "config_test_util.hpp"

namespace mpm::config {
namespace {

// "ok", "config error", or the foreign exception's message.
template <typename Parse>
std::string outcome(Parse parse) {
  try {
    parse();
    return "ok";
  } catch (const ConfigError&) {
    return "config error";
  } catch (const std::exception& e) {
    return std::string("foreign exception: ") + e.what();
  }
}

std::string plant_text() {
  const auto path = std::filesystem::path(MPM_SOURCE_DIR) / "config" / "wood-berry-continuous.yaml";
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(MalformedPlant, EveryTruncationLoadsOrThrowsConfigError) {
  const std::string full = plant_text();
  ASSERT_GT(full.size(), 500u);
  EXPECT_EQ(outcome([&] { parse_plant(full, "wb.yaml"); }), "ok");
  for (std::size_t n = 0; n < full.size(); ++n) {
    const std::string result = outcome([&] { parse_plant(full.substr(0, n), "wb.yaml"); });
    ASSERT_TRUE(result == "ok" || result == "config error") << "prefix " << n << ": " << result;
  }
}

// `trials` copies of `full` with one to three bytes replaced by characters
// of `alphabet`: each loads or throws ConfigError.
template <typename Parse>
void expect_random_edits_load_or_config_error(const std::string& full, const std::string& alphabet,
                                              unsigned seed, int trials, Parse parse) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < trials; ++trial) {
    std::string text = full;
    for (int edits = 1 + trial % 3; edits > 0; --edits) {
      const std::size_t at = rng() % text.size();
      text[at] = alphabet[rng() % alphabet.size()];
    }
    const std::string result = outcome([&] { parse(text); });
    ASSERT_TRUE(result == "ok" || result == "config error") << result << "\n" << text;
  }
}

TEST(MalformedPlant, RandomByteEditsLoadOrThrowConfigError) {
  expect_random_edits_load_or_config_error(plant_text(), "0123456789-.:,[]{}#- \n\tabxyz\"'e", 42, 1500,
                                           [](const std::string& text) { parse_plant(text, "wb.yaml"); });
}

TEST(MalformedRecording, RandomByteEditsLoadOrThrowConfigError) {
  expect_random_edits_load_or_config_error("t,u1,y1,sim_y1\n0,1.5,2,\n1,-3e2,nan,4\n2,0.25,1e-300,5\n",
                                           "0123456789-+.,eE\r\n nNaAiI", 7, 3000,
                                           [](const std::string& text) { parse_recording(text, "r.csv"); });
}

}  // namespace
}  // namespace mpm::config
