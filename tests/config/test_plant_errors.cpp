// Every way a plant file can be wrong gives a ConfigError that names the
// file, the 1-based line and the key, and says what was expected. The line
// expected in each case is marked in the YAML text with a "#!" comment.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"
#include "config_test_util.hpp"

namespace mpm::config {
namespace {

const std::string kHeader = R"(plant: p
sample_time: 1
inputs: [u1, u2]
outputs: [y1, y2]
)";

const std::string kGoodChannel = R"(model:
  - output: y1
    input: u1
    num: [0.5]
    den: [1, -0.5]
    delay: 1
)";

struct ErrorCase {
  std::string name;
  std::string yaml;
  std::string key;    // key path the message must name
  std::string words;  // what the message must say
};

// 1-based number of the line carrying the "#!" marker.
int marked_line(const std::string& yaml) {
  const auto at = yaml.find("#!");
  if (at == std::string::npos) return -1;
  return 1 + static_cast<int>(std::count(yaml.begin(), yaml.begin() + static_cast<long>(at), '\n'));
}

std::string thrown_message(const std::string& yaml, const std::string& source) {
  return testing_util::config_error([&] { parse_plant(yaml, source); });
}

std::vector<ErrorCase> error_cases() {
  const std::string h = kHeader;
  return {
      {"UnknownOutput", h + "model:\n  - output: y9   #!\n    input: u1\n    num: [1]\n",
       "model[0].output", "unknown output \"y9\""},
      {"UnknownInput", h + "model:\n  - output: y1\n    input: u7   #!\n    num: [1]\n",
       "model[0].input", "unknown input \"u7\""},
      {"DuplicateChannel", h + kGoodChannel + "  - output: y1   #!\n    input: u1\n    num: [2]\n",
       "model[1]", "duplicate channel y1 <- u1"},
      {"DuplicateInputName",
       "plant: p\nsample_time: 1\ninputs: [u1, u1]   #!\noutputs: [y1]\nmodel: []\n", "inputs[1]",
       "already used"},
      {"InputNamedLikeOutput",
       "plant: p\nsample_time: 1\ninputs: [u1]\noutputs: [y1, u1]   #!\nmodel: []\n", "outputs[1]",
       "already used by inputs[0]"},
      {"ReservedTimeName", "plant: p\nsample_time: 1\ninputs: [t]   #!\noutputs: [y1]\nmodel: []\n",
       "inputs[0]", "reserved"},
      {"EmptyInputs", "plant: p\nsample_time: 1\ninputs: []   #!\noutputs: [y1]\nmodel: []\n",
       "inputs", "expected a non-empty list of names"},
      {"EmptyOutputs", "plant: p\nsample_time: 1\ninputs: [u]\noutputs: []   #!\nmodel: []\n",
       "outputs", "expected a non-empty list of names"},
      {"NegativeDelay",
       h + "model:\n  - output: y1\n    input: u1\n    num: [1]\n    delay: -2   #!\n",
       "model[0].delay", "delay in 0..1000 samples, got -2"},
      {"FractionalDelay",
       h + "model:\n  - output: y1\n    input: u1\n    num: [1]\n    delay: 1.5   #!\n",
       "model[0].delay", "expected an integer"},
      {"LeadingDenZero",
       h + "model:\n  - output: y1\n    input: u1\n    num: [1]\n    den: [0, 1]   #!\n",
       "model[0].den[0]", "must be nonzero"},
      {"DenIsAString",
       h + "model:\n  - output: y1\n    input: u1\n    num: [1]\n    den: fast   #!\n",
       "model[0].den", "expected a non-empty list of numbers, got a string"},
      {"NumHasAWord", h + "model:\n  - output: y1\n    input: u1\n    num: [1, two]   #!\n",
       "model[0].num[1]", "expected a number, got a string \"two\""},
      {"MissingNum", h + "model:\n  - output: y1   #!\n    input: u1\n    den: [1, -0.5]\n",
       "model[0].num", "missing"},
      {"NanCoefficient", h + "model:\n  - output: y1\n    input: u1\n    num: [.nan]   #!\n",
       "model[0].num[0]", "finite number"},
      {"InfCoefficient",
       h + "model:\n  - output: y1\n    input: u1\n    num: [1]\n    den: [1, -.inf]   #!\n",
       "model[0].den[1]", "finite number"},
      {"ImproperContinuous",
       h + "model:\n  - output: y1\n    input: u1\n    continuous:\n      num: [1, 0, 0]   #!\n"
           "      den: [5, 1]\n",
       "model[0].continuous.num", "improper"},
      {"NegativeDeadTime",
       h + "model:\n  - output: y1\n    input: u1\n    continuous: {num: [1], den: [5, 1],\n"
           "                 dead_time: -3}   #!\n",
       "model[0].continuous.dead_time", "dead time >= 0"},
      {"ContinuousWithDiscreteKeys",
       h + "model:\n  - output: y1\n    input: u1\n    delay: 2   #!\n"
           "    continuous: {num: [1], den: [5, 1]}\n",
       "model[0].delay", "does not go with 'continuous'"},
      {"UnknownKeyInChannel",
       h + "model:\n  - output: y1\n    input: u1\n    num: [1]\n    dealy: 2   #!\n",
       "model[0].dealy", "unknown key"},
      {"ZeroSampleTime", "plant: p\nsample_time: 0   #!\ninputs: [u]\noutputs: [y]\nmodel: []\n",
       "sample_time", "sample time > 0"},
      {"NegativeSampleTime",
       "plant: p\nsample_time: -1   #!\ninputs: [u]\noutputs: [y]\nmodel: []\n", "sample_time",
       "sample time > 0"},
      {"MissingSampleTime", "plant: p   #!\ninputs: [u]\noutputs: [y]\nmodel: []\n", "sample_time",
       "expected a number, got nothing"},
      {"SampleTimeNan", "plant: p\nsample_time: .NaN   #!\ninputs: [u]\noutputs: [y]\nmodel: []\n",
       "sample_time", "finite number"},
      {"UnknownTopLevelKey", h + kGoodChannel + "modle:   #!\n  - output: y2\n", "modle",
       "unknown key"},
      {"DuplicateTopLevelKey", h + kGoodChannel + "sample_time: 2   #!\n", "sample_time",
       "given twice"},
      {"NoiseForUnknownOutput",
       h + kGoodChannel + "noise:\n  - output: y3   #!\n    num: [1]\n    den: [1, -0.5]\n",
       "noise[0].output", "unknown output \"y3\""},
      {"UnstableNoise",
       h + kGoodChannel + "noise:\n  - output: y1\n    num: [1]\n    den: [1, -1.2]   #!\n",
       "noise[0].den", "N must be stable"},
      {"IntegratingNoise",
       h + kGoodChannel + "noise:\n  - output: y1\n    num: [1]\n    den: [1, -1]   #!\n",
       "noise[0].den", "N must be stable"},
      {"NoiseNotInvertible",
       h + kGoodChannel + "noise:\n  - output: y1\n    num: [0, 1]   #!\n    den: [1, -0.5]\n",
       "noise[0].num[0]", "invertible"},
      {"NoiseNonMinimumPhase",
       h + kGoodChannel + "noise:\n  - output: y1\n    num: [1, -2.5]   #!\n    den: [1, -0.5]\n",
       "noise[0].num", "stable inverse"},
      {"NoiseWithDelay",
       h + kGoodChannel + "noise:\n  - output: y1\n    num: [1]\n    delay: 1   #!\n",
       "noise[0].delay", "must be 0"},
      {"NoiseVarianceNotPositive",
       h + kGoodChannel + "noise:\n  - output: y1\n    num: [1]\n    variance: 0   #!\n",
       "noise[0].variance", "variance > 0"},
      {"DuplicateNoise",
       h + kGoodChannel +
           "noise:\n  - output: y2\n    num: [1]\n  - output: y2   #!\n    num: [1]\n",
       "noise[1]", "duplicate noise model for output y2"},
      {"OperatingPointTooShort",
       h + kGoodChannel + "operating_point:\n  inputs: [1]   #!\n  outputs: [2, 3]\n",
       "operating_point.inputs", "expected 2 values"},
      {"OperatingPointMissingOutputs",
       h + kGoodChannel + "operating_point:\n  inputs: [1, 2]   #!\n", "operating_point.outputs",
       "got nothing"},
      {"RootIsAList", "- plant: p   #!\n", "", "expected a map of keys, got a list"},
      {"BrokenYaml", "plant: p\nsample_time: 1\ninputs: [u1, u2]\noutputs: y1: y2   #!\n", "",
       "invalid YAML"},
      {"NanWordCoefficient",
       h + "model:\n  - output: y1\n    input: u1\n    num: [1]\n    den: [1, nan]   #!\n",
       "model[0].den[1]", "finite number"},
  };
}

// Readable test names in failure output instead of a byte dump.
void PrintTo(const ErrorCase& c, std::ostream* os) { *os << c.name; }

class PlantErrors : public ::testing::TestWithParam<ErrorCase> {};

TEST_P(PlantErrors, MessageNamesFileLineKeyAndExpectation) {
  const ErrorCase& c = GetParam();
  const int line = marked_line(c.yaml);
  ASSERT_GT(line, 0) << "test case lacks a #! marker";
  const std::string message = thrown_message(c.yaml, "bad-plant.yaml");
  SCOPED_TRACE(message);
  EXPECT_EQ(message.rfind("bad-plant.yaml:" + std::to_string(line) + ":", 0), 0u);
  if (!c.key.empty()) {
    EXPECT_NE(message.find(" " + c.key + ": "), std::string::npos);
  }
  EXPECT_NE(message.find(c.words), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Cases, PlantErrors, ::testing::ValuesIn(error_cases()),
                         [](const auto& test) { return test.param.name; });

TEST(PlantErrorsFromFiles, MessageNamesThePathGiven) {
  const auto path = testing_util::temp_dir("plant_errors") / "typo.yaml";
  testing_util::write_text(path, kHeader + "model:\n  - output: y1\n    input: u1\n    num: []\n");
  const std::string e = testing_util::config_error([&] { load_plant(path.string()); });
  EXPECT_EQ(e.rfind(path.string() + ":8:", 0), 0u) << e;
  EXPECT_NE(e.find("model[0].num"), std::string::npos) << e;
}

TEST(PlantErrorsFromFiles, MissingFileIsNamed) {
  const auto path = testing_util::temp_dir("plant_errors") / "does-not-exist.yaml";
  const std::string e = testing_util::config_error([&] { load_plant(path.string()); });
  EXPECT_NE(e.find(path.string()), std::string::npos) << e;
  EXPECT_NE(e.find("No such file"), std::string::npos) << e;
}

}  // namespace
}  // namespace mpm::config
