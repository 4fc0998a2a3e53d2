// The wire definitions agree with the one field list of each message
// (transport/messages.hpp, for_each_field): mpm.lcm and mpm.idl are read as
// text and every struct's fields, types and order compared with what the
// list says they must be. The codecs and the JSON are driven by the list, so
// a field added to one place only fails here.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "sample_messages.hpp"
#include "transport/message_json.hpp"
#include "transport/messages.hpp"

namespace mpm::msg {
namespace {

using Structs = std::map<std::string, std::vector<std::string>>;

std::string read(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Every `struct NAME { ... }` of a .lcm or .idl file: its declarations,
// comments dropped and white space folded ("@key string controller_id",
// "double u[n_u]").
Structs structs_of(const std::string& path) {
  const std::string text = std::regex_replace(read(path), std::regex("//[^\n]*"), "");
  Structs out;
  const std::regex block(R"(struct\s+(\w+)\s*\{([^}]*)\})");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), block); it != std::sregex_iterator(); ++it) {
    std::vector<std::string>& fields = out[(*it)[1]];
    std::stringstream body((*it)[2].str());
    std::string declaration;
    while (std::getline(body, declaration, ';')) {
      declaration = std::regex_replace(declaration, std::regex(R"(\s+)"), " ");
      declaration = std::regex_replace(declaration, std::regex(R"(^ | $)"), "");
      if (!declaration.empty()) fields.push_back(declaration);
    }
  }
  return out;
}

struct WireTypes {
  std::string lcm;
  std::string idl;
};

template <class T>
WireTypes wire_types() {
  if constexpr (std::is_same_v<T, std::string>) return {"string", "string"};
  else if constexpr (std::is_same_v<T, std::int64_t>) return {"int64_t", "long long"};
  else if constexpr (std::is_same_v<T, std::int32_t>) return {"int32_t", "long"};
  else if constexpr (std::is_same_v<T, bool>) return {"boolean", "boolean"};
  else if constexpr (std::is_same_v<T, double>) return {"double", "double"};
  else return {Fields<T>::lcm, Fields<T>::idl};  // a nested message
}

template <class M, class Field>
using MemberOf = std::remove_cvref_t<decltype(std::declval<Field>().get(std::declval<M&>()))>;

// What mpm.lcm must declare for M, in order.
template <class M>
std::vector<std::string> expected_lcm() {
  std::vector<std::string> out;
  for_each_field<M>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (is<Field>(FieldKind::kScalar)) {
      out.push_back(wire_types<MemberOf<M, Field>>().lcm + " " + field.names.name);
    } else if constexpr (is<Field>(FieldKind::kArray)) {
      const std::string length = field.lcm_length_name;
      out.push_back("int32_t " + length);
      out.push_back(wire_types<ElementOf<M, Field>>().lcm + " " + field.names.name + "[" + length + "]");
    } else {
      const std::string length = field.lcm_length_name;
      out.push_back("int32_t " + length);
      out.push_back(std::string("string ") + field.names_name + "[" + length + "]");
      out.push_back(std::string("double ") + field.values_name + "[" + length + "]");
    }
  });
  return out;
}

// What mpm.idl must declare for M: the keys first, each part in list order.
template <class M>
std::vector<std::string> expected_idl() {
  std::vector<std::string> keys;
  std::vector<std::string> rest;
  for_each_field<M>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (is<Field>(FieldKind::kScalar)) {
      const std::string declaration = wire_types<MemberOf<M, Field>>().idl + " " + field.names.name;
      if (field.names.key) keys.push_back("@key " + declaration);
      else rest.push_back(declaration);
    } else if constexpr (is<Field>(FieldKind::kArray)) {
      rest.push_back("sequence<" + wire_types<ElementOf<M, Field>>().idl + "> " + field.names.name);
    } else {
      rest.push_back(std::string("sequence<NamedValue> ") + field.dds_name);
    }
  });
  keys.insert(keys.end(), rest.begin(), rest.end());
  return keys;
}

template <class... M>
void expect_files_match() {
  const Structs lcm = structs_of(MPM_SOURCE_DIR "/transport/messages/mpm.lcm");
  const Structs idl = structs_of(MPM_SOURCE_DIR "/transport/messages/mpm.idl");
  Structs want_lcm{{Fields<M>::lcm, expected_lcm<M>()}...};
  Structs want_idl{{Fields<M>::idl, expected_idl<M>()}...};
  want_idl["NamedValue"] = {"string name", "double value"};
  EXPECT_EQ(lcm, want_lcm);
  EXPECT_EQ(idl, want_idl);
}

TEST(MessageFields, LcmAndIdlFilesDeclareEveryListedFieldInOrder) {
  expect_files_match<Sample, Alarm, Diagnosis, Status, ChannelStatus, LoopStatus>();
}

// The reader above is not vacuous: it sees a struct's fields and their order.
TEST(MessageFields, TheFileReaderSeesFieldsAndOrder) {
  const Structs lcm = structs_of(MPM_SOURCE_DIR "/transport/messages/mpm.lcm");
  ASSERT_EQ(lcm.count("sample_t"), 1u);
  ASSERT_GE(lcm.at("sample_t").size(), 5u);
  EXPECT_EQ(lcm.at("sample_t")[0], "string controller_id");
  EXPECT_EQ(lcm.at("sample_t")[4], "int32_t n_u");
  const Structs idl = structs_of(MPM_SOURCE_DIR "/transport/messages/mpm.idl");
  ASSERT_EQ(idl.count("Alarm"), 1u);
  EXPECT_EQ(idl.at("Alarm")[1], "@key string output");
}

// The JSON lines: every number finite or null (never nan or inf), the
// keys and words of the field lists.
TEST(MessageJson, NonFiniteNumbersAreNullAndKeysFollowTheLists) {
  Alarm alarm = test::full_alarm();
  alarm.gamma = std::numeric_limits<double>::quiet_NaN();
  alarm.f = -std::numeric_limits<double>::quiet_NaN();
  alarm.raised = false;
  EXPECT_EQ(to_json(alarm),
            R"({"type":"alarm","controller":"column-7","utime":1700000000999999,"sample_sequence":4300,)"
            R"("output":"y2","input":"u1","output_index":1,"input_index":0,"state":"cleared","F":null,)"
            R"("p_value":1e-09,"gamma":null,"physics":"gain","text":"model-plant mismatch on u1 -> y2"})");
  Diagnosis d;
  d.controller_id = "c\"\n";
  d.parameter_names = {"gain", "tau"};
  d.parameter_values = {1.5, std::numeric_limits<double>::infinity()};
  d.holdout_improvement = -std::numeric_limits<double>::infinity();
  const std::string json = to_json(d);
  EXPECT_NE(json.find(R"("controller":"c\"\n")"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("parameters":{"gain":1.5,"tau":null})"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("holdout_improvement":null)"), std::string::npos) << json;
  Status status = test::full_status();
  for (ChannelStatus& c : status.channels) c.lr = std::numeric_limits<double>::quiet_NaN();
  Sample sample = test::full_sample();
  sample.u[0] = -std::numeric_limits<double>::infinity();
  const std::regex non_finite(R"([:,\[]-?(nan|inf))", std::regex::icase);  // a value, not a key
  for (const std::string& line : {json, to_json(alarm), to_json(status), to_json(sample)}) {
    EXPECT_FALSE(std::regex_search(line, non_finite)) << line;
    EXPECT_NE(line.find("null"), std::string::npos) << line;
  }
}

}  // namespace
}  // namespace mpm::msg
