// Typed, located access to a parsed YAML document. Internal to config/.
//
// yaml-cpp's own conversions fail with a bare "bad conversion" that names no
// key and no line, and a missing key has no position at all. Every read here
// goes through a Field that remembers the key path that led to it and the
// nearest position in the file, so each error can say
// "plant.yaml:12:5: model[2].den: expected a list of numbers, got a string".
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace mpm::config::detail {

struct Field {
  YAML::Node node;   // undefined when the key is missing
  std::string path;  // "model[2].den"; empty for the document root
  YAML::Mark mark;   // the node's own position, or its parent's when missing

  bool present() const { return node.IsDefined(); }
};

class YamlReader {
 public:
  explicit YamlReader(std::string source) : source_(std::move(source)) {}

  Field root(const YAML::Node& document) const;
  Field child(const Field& map, const std::string& key) const;
  Field element(const Field& list, std::size_t index) const;

  // Throws ConfigError "<source>:<line>:<col>: <path>: <what>".
  [[noreturn]] void fail(const Field& at, const std::string& what) const;
  // Same, with "expected <expected>, got <what the node is>".
  [[noreturn]] void fail_expected(const Field& at, const std::string& expected) const;

  void require_map(const Field& field) const;
  // The number of elements of a list; a missing or null field counts as empty
  // only when `null_is_empty` (optional lists such as `noise:`).
  std::size_t list_size(const Field& field, bool null_is_empty) const;

  double number(const Field& field) const;                   // finite
  int integer(const Field& field) const;                     // integral value, fits an int
  std::vector<double> numbers(const Field& field) const;     // non-empty list of finite numbers
  std::string name(const Field& field) const;                // non-empty scalar text
  std::vector<std::string> names(const Field& field) const;  // non-empty list of names

  // Fails on a key not in `allowed` (keys starting with "x-" are extensions
  // and always allowed) and on a key given twice.
  void check_keys(const Field& map, const std::vector<std::string>& allowed) const;

  const std::string& source() const { return source_; }

 private:
  std::string source_;
};

// Human description of a node for "got ..." in messages.
std::string describe(const YAML::Node& node);

// Throws ConfigError "<source>:<line>:<col>: <what>: <yaml-cpp's message>"
// (e.what() repeats the position in yaml-cpp's own words: the bare msg).
[[noreturn]] void fail_from_yaml(const YAML::Exception& e, const std::string& source, const char* what);

// The document in `text`; a syntax error fails as "invalid YAML".
YAML::Node load_document(const std::string& text, const std::string& source);

// read(), whose every access is checked first: a yaml-cpp exception that
// still escapes is a case the checks missed, and must not leave without the
// file name, so it fails as "unexpected structure".
template <class Read>
auto read_checked(const std::string& source, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const YAML::Exception& e) {
    fail_from_yaml(e, source, "unexpected structure");
  }
}

}  // namespace mpm::config::detail
