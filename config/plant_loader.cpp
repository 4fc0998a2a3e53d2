// parse_plant / load_plant: the top level of the plant file (formats.md
// section 1). Entries of `model:` and `noise:` are read in plant_entries.cpp.
#include "config/plant_loader.hpp"

#include <map>
#include <utility>

#include "config/file_text.hpp"
#include "config/plant_entries.hpp"
#include "config/yaml_reader.hpp"

namespace mpm::config {
namespace {

using detail::Field;
using detail::YamlReader;

// Names become CSV column names: they must be unique across inputs and
// outputs, not clash with the time column or the sim_/r_ columns derived
// from output names, and be writable in a plain CSV header.
void check_names(const YamlReader& reader, const Field& root, const PlantModel& plant) {
  std::map<std::string, std::string> owner;  // name -> "inputs[0]"
  auto claim = [&](const std::string& name, const Field& at) {
    if (name.find_first_of(",\"\r\n") != std::string::npos)
      reader.fail(at,
                  "a name must not contain a comma, a quote or a line break "
                  "(it is a CSV column name)");
    if (name == "t") reader.fail(at, "the name \"t\" is reserved for the time column");
    const auto [it, fresh] = owner.emplace(name, at.path);
    if (!fresh) reader.fail(at, "name \"" + name + "\" is already used by " + it->second);
  };
  const Field inputs = reader.child(root, "inputs");
  const Field outputs = reader.child(root, "outputs");
  for (std::size_t i = 0; i < plant.inputs.size(); ++i)
    claim(plant.inputs[i], reader.element(inputs, i));
  for (std::size_t i = 0; i < plant.outputs.size(); ++i)
    claim(plant.outputs[i], reader.element(outputs, i));
  for (std::size_t i = 0; i < plant.outputs.size(); ++i) {
    for (const char* prefix : {"sim_", "r_"}) {
      const auto it = owner.find(prefix + plant.outputs[i]);
      if (it != owner.end())
        reader.fail(reader.element(outputs, i),
                    "the column " + it->first + " (" + it->second + ") would be taken for the " +
                        (prefix[0] == 's' ? "simulation" : "setpoint") + " of this output");
    }
  }
}

// The list of names under `key`, its length checked against `most` before
// anything is read (a 2000 x 2000 plant is refused here, not after its model).
std::vector<std::string> read_names(const YamlReader& reader, const Field& root, const char* key,
                                    std::size_t most) {
  const Field field = reader.child(root, key);
  if (field.present() && field.node.IsSequence() && field.node.size() > most)
    reader.fail(field, "expected 1.." + std::to_string(most) + " " + key + ", got " +
                           std::to_string(field.node.size()) +
                           " (the limit is Limits::max_" + key + ")");
  return reader.names(field);
}

void read_header(const YamlReader& reader, const Field& root, const Limits& limits,
                 PlantModel& plant) {
  plant.name = reader.name(reader.child(root, "plant"));
  const Field ts = reader.child(root, "sample_time");
  plant.sample_time = reader.number(ts);
  if (plant.sample_time <= 0.0)
    reader.fail(ts, "expected a sample time > 0 seconds, got " + ts.node.Scalar());
  plant.inputs = read_names(reader, root, "inputs", limits.max_inputs);
  plant.outputs = read_names(reader, root, "outputs", limits.max_outputs);
  check_names(reader, root, plant);
}

void read_model(const YamlReader& reader, const Field& root, const Limits& limits,
                PlantModel& plant) {
  const Field model = reader.child(root, "model");
  const Field state_space = reader.child(root, "state_space");
  if (state_space.present()) {
    if (model.present()) reader.fail(model, "give the model as `model:` channels or as `state_space:`, not both");
    detail::read_state_space(reader, state_space, limits, plant);
    return;
  }
  if (!model.present()) reader.fail(model, "missing (list the model's channels, [] for none, or give state_space:)");
  std::map<std::pair<std::size_t, std::size_t>, std::string> seen;  // channel -> path
  for (std::size_t i = 0, n = reader.list_size(model, true); i < n; ++i) {
    const Field entry = reader.element(model, i);
    ChannelModel ch = detail::read_channel(reader, entry, plant, limits);
    const auto [it, fresh] = seen.emplace(std::pair{ch.output, ch.input}, entry.path);
    if (!fresh)
      reader.fail(entry, "duplicate channel " + plant.outputs[ch.output] + " <- " +
                             plant.inputs[ch.input] + " (already given by " + it->second + ")");
    plant.channels.push_back(std::move(ch));
  }
}

void read_noise(const YamlReader& reader, const Field& root, const Limits& limits,
                PlantModel& plant) {
  const Field state_space = reader.child(root, "state_space");
  if (state_space.present() && (reader.child(state_space, "G").present() || reader.child(state_space, "Bd").present())) {
    if (reader.child(root, "noise").present())
      reader.fail(reader.child(root, "noise"), "the state_space's G and noise already give every output's N");
    return;
  }
  plant.noise.assign(plant.outputs.size(), std::nullopt);
  std::vector<std::string> given_by(plant.outputs.size());
  const Field noise = reader.child(root, "noise");
  for (std::size_t i = 0, n = reader.list_size(noise, true); i < n; ++i) {
    const Field entry = reader.element(noise, i);
    detail::NoiseEntry e = detail::read_noise(reader, entry, plant, limits);
    if (plant.noise[e.output])
      reader.fail(entry, "duplicate noise model for output " + plant.outputs[e.output] +
                             " (already given by " + given_by[e.output] + ")");
    plant.noise[e.output] = std::move(e.model);
    given_by[e.output] = entry.path;
  }
}

std::vector<double> read_point(const YamlReader& reader, const Field& op, const char* key,
                               std::size_t expected_size) {
  const Field field = reader.child(op, key);
  std::vector<double> values = reader.numbers(field);
  if (values.size() != expected_size)
    reader.fail(field, "expected " + std::to_string(expected_size) + " values (one per " +
                           std::string(key).substr(0, std::string(key).size() - 1) + "), got " +
                           std::to_string(values.size()));
  return values;
}

void read_operating_point(const YamlReader& reader, const Field& root, PlantModel& plant) {
  const Field op = reader.child(root, "operating_point");
  if (!op.present()) return;
  reader.check_keys(op, {"inputs", "outputs"});
  OperatingPoint point;
  point.inputs = read_point(reader, op, "inputs", plant.inputs.size());
  point.outputs = read_point(reader, op, "outputs", plant.outputs.size());
  plant.operating_point = std::move(point);
}

}  // namespace

PlantModel parse_plant(const std::string& yaml_text, const std::string& source_name,
                       const Limits& limits) {
  const YamlReader reader(source_name);
  const Field root = reader.root(detail::load_document(yaml_text, source_name));
  return detail::read_checked(source_name, [&] {
    reader.check_keys(
        root, {"plant", "sample_time", "inputs", "outputs", "model", "state_space", "noise", "operating_point"});
    PlantModel plant;
    read_header(reader, root, limits, plant);
    read_model(reader, root, limits, plant);
    read_noise(reader, root, limits, plant);
    read_operating_point(reader, root, plant);
    return plant;
  });
}

PlantModel load_plant(const std::string& path, const Limits& limits) {
  return parse_plant(detail::read_file(path, limits.max_yaml_bytes), path, limits);
}

}  // namespace mpm::config
