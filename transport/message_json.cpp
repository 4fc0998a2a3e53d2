#include "transport/message_json.hpp"

#include <cmath>
#include <cstdio>

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
    for (const unsigned char c : s) {
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

template <typename T, typename Fn>
std::string array_of(const std::vector<T>& items, Fn&& to_object) {
  std::string out = "[";
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i) out += ',';
    out += to_object(items[i]);
  }
  return out + "]";
}

}  // namespace

std::string to_json(const Alarm& a) {
  return JsonObject()
      .field("type", "alarm")
      .field("controller", a.controller_id)
      .field("utime", a.utime)
      .field("sample_sequence", a.sample_sequence)
      .field("output", a.output)
      .field("input", a.input)
      .field("output_index", a.output_index)
      .field("input_index", a.input_index)
      .field("state", a.raised ? "raised" : "cleared")
      .field("F", a.f)
      .field("p_value", a.p_value)
      .field("gamma", a.gamma)
      .field("physics", a.physics)
      .field("text", a.text)
      .str();
}

std::string to_json(const Diagnosis& d) {
  std::string parameters = "{";
  for (std::size_t i = 0; i < d.parameter_names.size() && i < d.parameter_values.size(); ++i) {
    if (i) parameters += ',';
    // One-field object, its braces dropped: a name-value pair with our escaping.
    const std::string pair = JsonObject().field(d.parameter_names[i].c_str(), d.parameter_values[i]).str();
    parameters += pair.substr(1, pair.size() - 2);
  }
  parameters += '}';
  return JsonObject()
      .field("type", "diagnosis")
      .field("controller", d.controller_id)
      .field("utime", d.utime)
      .field("sample_sequence", d.sample_sequence)
      .field("output", d.output)
      .field("input", d.input)
      .field("window", d.window)
      .field("found", d.found)
      .field("physics", d.physics)
      .field("channels", d.channels)
      .raw("parameters", parameters)
      .field("holdout_improvement", d.holdout_improvement)
      .field("text", d.text)
      .str();
}

std::string to_json(const Status& s) {
  const std::string channels = array_of(s.channels, [](const ChannelStatus& c) {
    return JsonObject()
        .field("output", c.output)
        .field("input", c.input)
        .field("F", c.f_pairwise)
        .field("F_conditional", c.f_conditional)
        .field("LR", c.lr)
        .field("p_value", c.p_value)
        .field("gamma", c.gamma)
        .field("alarm", c.alarm)
        .str();
  });
  const std::string loops = array_of(s.loops, [](const LoopStatus& l) {
    return JsonObject()
        .field("output", l.output)
        .field("residual_variance", l.residual_variance)
        .field("sigma1", l.sigma1)
        .field("sigma_full", l.sigma_full)
        .field("alarm", l.alarm)
        .field("diverging", l.diverging)
        .str();
  });
  return JsonObject()
      .field("type", "status")
      .field("controller", s.controller_id)
      .field("utime", s.utime)
      .field("uptime_ms", s.uptime_ms)
      .field("ready", s.ready)
      .field("effective_samples", s.effective_samples)
      .field("raise_threshold", s.raise_threshold)
      .field("clear_threshold", s.clear_threshold)
      .field("samples_seen", s.samples_seen)
      .field("samples_used", s.samples_used)
      .field("dropped", s.dropped)
      .field("gaps", s.gaps)
      .field("missing", s.missing)
      .field("duplicates", s.duplicates)
      .field("out_of_order", s.out_of_order)
      .field("restarts", s.restarts)
      .field("malformed", s.malformed)
      .field("nan_samples", s.nan_samples)
      .field("alarms_raised", s.alarms_raised)
      .raw("channels", channels)
      .raw("loops", loops)
      .str();
}

std::string to_json(const Sample& s) {
  JsonObject extra;
  for (std::size_t i = 0; i < s.extra_names.size() && i < s.extra_values.size(); ++i) {
    extra.field(s.extra_names[i], s.extra_values[i]);
  }
  return JsonObject()
      .field("type", "sample")
      .field("controller", s.controller_id)
      .field("session_id", s.session_id)
      .field("seq", s.seq)
      .field("utime", s.utime)
      .field("u", s.u)
      .field("y", s.y)
      .field("sim_y", s.sim_y)
      .raw("extra", extra.str())
      .str();
}

}  // namespace mpm::msg
