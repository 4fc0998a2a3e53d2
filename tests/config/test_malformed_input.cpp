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

TEST(MalformedPlant, RandomByteEditsLoadOrThrowConfigError) {
  const std::string full = plant_text();
  const std::string alphabet = "0123456789-.:,[]{}#- \n\tabxyz\"'e";
  std::mt19937 rng(42);
  for (int trial = 0; trial < 1500; ++trial) {
    std::string text = full;
    for (int edits = 1 + trial % 3; edits > 0; --edits) {
      const std::size_t at = rng() % text.size();
      text[at] = alphabet[rng() % alphabet.size()];
    }
    const std::string result = outcome([&] { parse_plant(text, "wb.yaml"); });
    ASSERT_TRUE(result == "ok" || result == "config error") << result << "\n" << text;
  }
}

TEST(MalformedRecording, RandomByteEditsLoadOrThrowConfigError) {
  const std::string full = "t,u1,y1,sim_y1\n0,1.5,2,\n1,-3e2,nan,4\n2,0.25,1e-300,5\n";
  const std::string alphabet = "0123456789-+.,eE\r\n nNaAiI";
  std::mt19937 rng(7);
  for (int trial = 0; trial < 3000; ++trial) {
    std::string text = full;
    for (int edits = 1 + trial % 3; edits > 0; --edits) {
      const std::size_t at = rng() % text.size();
      text[at] = alphabet[rng() % alphabet.size()];
    }
    const std::string result = outcome([&] { parse_recording(text, "r.csv"); });
    ASSERT_TRUE(result == "ok" || result == "config error") << result << "\n" << text;
  }
}

}  // namespace
}  // namespace mpm::config
