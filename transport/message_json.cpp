#include "transport/message_json.hpp"

#include <cmath>
#include <cstdio>
#include <type_traits>

namespace mpm::msg {

namespace {

// Builds one JSON object; keys are ours (plain ASCII), values are escaped.
class JsonObject {
 public:
  JsonObject() : text_("{") {}

  JsonObject& field(const std::string& key, const std::string& value) {
    start(key);
    quote(value);
    return *this;
  }
  JsonObject& field(const std::string& key, const char* value) { return field(key, std::string(value)); }
  JsonObject& field(const std::string& key, bool value) {
    start(key);
    text_ += value ? "true" : "false";
    return *this;
  }
  JsonObject& field(const std::string& key, std::int64_t value) {
    start(key);
    text_ += std::to_string(value);
    return *this;
  }
  JsonObject& field(const std::string& key, std::int32_t value) { return field(key, static_cast<std::int64_t>(value)); }
  JsonObject& field(const std::string& key, double value) {
    start(key);
    number(value);
    return *this;
  }
  JsonObject& field(const std::string& key, const std::vector<double>& values) {
    start(key);
    text_ += '[';
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i) text_ += ',';
      number(values[i]);
    }
    text_ += ']';
    return *this;
  }
  // A raw, already formatted JSON value (nested arrays of objects).
  JsonObject& raw(const std::string& key, const std::string& json) {
    start(key);
    text_ += json;
    return *this;
  }

  std::string str() const { return text_ + "}"; }

 private:
  void start(const std::string& key) {
    if (text_.size() > 1) text_ += ',';
    quote(key);
    text_ += ':';
  }

  void number(double value) {
    if (!std::isfinite(value)) {
      text_ += "null";
      return;
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", value);
    text_ += buf;
  }

  void quote(const std::string& s) {
    text_ += '"';
    for (const char ch : s) {
      const auto c = static_cast<unsigned char>(ch);  // bytes >= 0x80 (UTF-8) pass as they are
      switch (c) {
        case '"': text_ += "\\\""; break;
        case '\\': text_ += "\\\\"; break;
        case '\n': text_ += "\\n"; break;
        case '\r': text_ += "\\r"; break;
        case '\t': text_ += "\\t"; break;
        default:
          if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            text_ += buf;
          } else {
            text_ += static_cast<char>(c);
          }
      }
    }
    text_ += '"';
  }

  std::string text_;
};

// Writes every field of `m` (the names and word choices of its field list),
// after "type" for a top-level message.
template <class M>
void write_fields(JsonObject& object, const M& m) {
  if constexpr (Fields<M>::json_type != nullptr) object.field("type", Fields<M>::json_type);
  for_each_field<M>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (is<Field>(FieldKind::kArray)) {
      using Element = ElementOf<M, Field>;
      if constexpr (std::is_arithmetic_v<Element>) {
        object.field(field.names.json_key(), field.get(m));
      } else {
        std::string items = "[";
        for (const Element& item : field.get(m)) {
          if (items.size() > 1) items += ',';
          JsonObject nested;
          write_fields(nested, item);
          items += nested.str();
        }
        object.raw(field.names.json_key(), items + "]");
      }
    } else if constexpr (is<Field>(FieldKind::kNamedValues)) {
      JsonObject pairs;
      const auto& names = field.names(m);
      const auto& values = field.values(m);
      for (std::size_t i = 0; i < names.size() && i < values.size(); ++i) pairs.field(names[i], values[i]);
      object.raw(field.json, pairs.str());
    } else if constexpr (std::is_same_v<std::remove_cvref_t<decltype(field.get(m))>, bool>) {
      if (field.names.json_true != nullptr) {
        object.field(field.names.json_key(), field.get(m) ? field.names.json_true : field.names.json_false);
      } else {
        object.field(field.names.json_key(), field.get(m));
      }
    } else {
      object.field(field.names.json_key(), field.get(m));
    }
  });
}

template <class M>
std::string json_of(const M& m) {
  JsonObject object;
  write_fields(object, m);
  return object.str();
}

}  // namespace

std::string to_json(const Alarm& alarm) { return json_of(alarm); }
std::string to_json(const Status& status) { return json_of(status); }
std::string to_json(const Sample& sample) { return json_of(sample); }
std::string to_json(const Diagnosis& diagnosis) { return json_of(diagnosis); }

}  // namespace mpm::msg
