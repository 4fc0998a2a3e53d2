#include "config/yaml_reader.hpp"

#include <cmath>
#include <limits>
#include <map>

#include "config/number_text.hpp"
#include "config/plant_loader.hpp"

namespace mpm::config::detail {
namespace {

std::string position(const YAML::Mark& mark) {
  if (mark.is_null()) return "";
  // yaml-cpp counts from 0; editors and users count from 1.
  return std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1) + ":";
}

// A missing node has no position: point at the map that lacks the key. An
// empty value's own mark is where the next token starts (often the next
// line): point at its key instead.
YAML::Mark mark_of_value(const Field& map, const std::string& key, const YAML::Node& node) {
  if (!node.IsDefined()) return map.mark;
  if (!node.IsNull()) return node.Mark();
  for (const auto& kv : map.node)
    if (kv.first.IsScalar() && kv.first.Scalar() == key) return kv.first.Mark();
  return map.mark;
}

// YAML's own spellings of the non-finite floats (.nan, -.inf, ...); from_chars
// already reads "nan" and "inf".
bool is_yaml_non_finite(std::string_view text) {
  if (!text.empty() && (text.front() == '+' || text.front() == '-')) text.remove_prefix(1);
  for (std::string_view word : {".nan", ".NaN", ".NAN", ".inf", ".Inf", ".INF"})
    if (text == word) return true;
  return false;
}

bool is_extension_key(std::string_view key) { return key.rfind("x-", 0) == 0; }

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (auto w : words) {
    if (!out.empty()) out += ", ";
    out += w;
  }
  return out;
}

}  // namespace

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined()) return "nothing (the key is missing)";
  switch (node.Type()) {
    case YAML::NodeType::Null:
      return "nothing (an empty value)";
    case YAML::NodeType::Sequence:
      return node.size() == 0 ? "an empty list" : "a list";
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Scalar: {
      const std::string& text = node.Scalar();
      if (parse_double(trim(text))) return "the number " + text;
      return "a string \"" + text + "\"";
    }
    default:
      return "an undefined value";
  }
}

Field YamlReader::root(const YAML::Node& document) const {
  return Field{document, "", document.IsDefined() ? document.Mark() : YAML::Mark::null_mark()};
}

Field YamlReader::child(const Field& map, const std::string& key) const {
  require_map(map);
  const YAML::Node& parent = map.node;
  YAML::Node node = parent[key];
  std::string path = map.path.empty() ? key : map.path + "." + key;
  return Field{node, std::move(path), mark_of_value(map, key, node)};
}

Field YamlReader::element(const Field& list, std::size_t index) const {
  YAML::Node node = list.node[index];
  return Field{node, list.path + "[" + std::to_string(index) + "]",
               node.IsDefined() ? node.Mark() : list.mark};
}

void YamlReader::fail(const Field& at, const std::string& what) const {
  std::string message = source_ + ":" + position(at.mark);
  message += " ";
  if (!at.path.empty()) message += at.path + ": ";
  message += what;
  throw ConfigError(message);
}

void fail_from_yaml(const YAML::Exception& e, const std::string& source, const char* what) {
  throw ConfigError(source + ":" + position(e.mark) + " " + what + ": " + e.msg);
}

YAML::Node load_document(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    fail_from_yaml(e, source, "invalid YAML");
  }
}

void YamlReader::fail_expected(const Field& at, const std::string& expected) const {
  fail(at, "expected " + expected + ", got " + describe(at.node));
}

void YamlReader::require_map(const Field& field) const {
  if (!field.present() || !field.node.IsMap()) fail_expected(field, "a map of keys");
}

std::size_t YamlReader::list_size(const Field& field, bool null_is_empty) const {
  if (null_is_empty && (!field.present() || field.node.IsNull())) return 0;
  if (!field.present() || !field.node.IsSequence()) fail_expected(field, "a list");
  return field.node.size();
}

double YamlReader::number(const Field& field) const {
  if (!field.present() || !field.node.IsScalar()) fail_expected(field, "a number");
  const std::string& text = field.node.Scalar();
  if (is_yaml_non_finite(trim(text))) fail(field, "expected a finite number, got " + text);
  const auto value = parse_double(trim(text));
  if (!value) fail_expected(field, "a number");
  if (!std::isfinite(*value)) fail(field, "expected a finite number, got " + text);
  return *value;
}

int YamlReader::integer(const Field& field) const {
  if (!field.present() || !field.node.IsScalar()) fail_expected(field, "an integer");
  const auto value = parse_double(trim(field.node.Scalar()));
  const double limit = std::numeric_limits<int>::max();
  if (!value || !std::isfinite(*value) || std::floor(*value) != *value || std::abs(*value) > limit)
    fail_expected(field, "an integer");
  return static_cast<int>(*value);
}

std::vector<double> YamlReader::numbers(const Field& field) const {
  if (!field.present() || !field.node.IsSequence() || field.node.size() == 0)
    fail_expected(field, "a non-empty list of numbers");
  std::vector<double> out;
  out.reserve(field.node.size());
  for (std::size_t i = 0; i < field.node.size(); ++i) out.push_back(number(element(field, i)));
  return out;
}

std::string YamlReader::name(const Field& field) const {
  if (!field.present() || !field.node.IsScalar() || trim(field.node.Scalar()).empty())
    fail_expected(field, "a name");
  return std::string(trim(field.node.Scalar()));
}

std::vector<std::string> YamlReader::names(const Field& field) const {
  if (!field.present() || !field.node.IsSequence() || field.node.size() == 0)
    fail_expected(field, "a non-empty list of names");
  std::vector<std::string> out;
  out.reserve(field.node.size());
  for (std::size_t i = 0; i < field.node.size(); ++i) out.push_back(name(element(field, i)));
  return out;
}

void YamlReader::check_keys(const Field& map, const std::vector<std::string>& allowed) const {
  require_map(map);
  std::map<std::string, int> seen_on_line;
  for (const auto& kv : map.node) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
    Field key_field{kv.first, map.path.empty() ? key : map.path + "." + key, kv.first.Mark()};
    if (!kv.first.IsScalar())
      fail(Field{kv.first, map.path, kv.first.Mark()}, "keys must be plain names");
    if (const auto it = seen_on_line.find(key); it != seen_on_line.end())
      fail(key_field, "key given twice (first on line " + std::to_string(it->second) + ")");
    seen_on_line.emplace(key, kv.first.Mark().line + 1);
    if (is_extension_key(key)) continue;
    bool known = false;
    for (const auto& a : allowed) known = known || a == key;
    if (!known)
      fail(key_field,
           "unknown key (allowed here: " + join(allowed) + "; extension keys start with \"x-\")");
  }
}

}  // namespace mpm::config::detail
