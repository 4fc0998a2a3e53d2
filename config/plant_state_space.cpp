// Reading `state_space:` (formats.md section 4.5): the matrices, checked for
// shape against the plant's inputs and outputs and located on error, turned
// into the per-channel transfer functions (and per-output disturbance
// models) the monitor uses by core/state_space.hpp.
#include <cmath>
#include <stdexcept>
#include <string>

#include "config/plant_entries.hpp"
#include "core/state_space.hpp"

namespace mpm::config::detail {
namespace {

std::string dims(Eigen::Index r, Eigen::Index c) { return std::to_string(r) + " x " + std::to_string(c); }

// A matrix as a list of rows of numbers, `rows` x `cols` (cols < 0: any,
// the same in every row).
Eigen::MatrixXd read_matrix(const YamlReader& reader, const Field& field, Eigen::Index rows, Eigen::Index cols,
                            const std::string& shape) {
  const std::size_t n = reader.list_size(field, false);
  if (static_cast<Eigen::Index>(n) != rows)
    reader.fail(field, "expected " + shape + " (a list of " + std::to_string(rows) + " rows), got " +
                           std::to_string(n) + " rows");
  Eigen::MatrixXd m;
  for (std::size_t r = 0; r < n; ++r) {
    const Field row = reader.element(field, r);
    const std::vector<double> v = reader.numbers(row);
    if (cols < 0) cols = static_cast<Eigen::Index>(v.size());
    if (static_cast<Eigen::Index>(v.size()) != cols)
      reader.fail(row, "expected " + std::to_string(cols) + " numbers in each row of " + shape + ", got " +
                           std::to_string(v.size()));
    if (r == 0) m.resize(rows, cols);
    for (Eigen::Index c = 0; c < cols; ++c) m(static_cast<Eigen::Index>(r), c) = v[static_cast<std::size_t>(c)];
  }
  return m;
}

std::vector<double> read_list(const YamlReader& reader, const Field& field, std::size_t size, double least,
                              const std::string& what) {
  const std::vector<double> v = reader.numbers(field);
  if (v.size() != size)
    reader.fail(field, "expected " + std::to_string(size) + " " + what + ", got " + std::to_string(v.size()));
  for (const double x : v)
    if (x < least) reader.fail(field, "expected " + what + " >= " + std::to_string(static_cast<int>(least)));
  return v;
}

double largest_root_of(const std::vector<double>& p) {
  double most = 0.0;
  for (const double m : root_magnitudes(p)) most = std::max(most, m);
  return most;
}

// noise: {w, v} with the (discretised) G into one NoiseModel per output.
void read_disturbance(const YamlReader& reader, const Field& ss, const Field& g_field, StateSpace& s,
                      PlantModel& plant) {
  const Field noise = reader.child(ss, "noise");
  if (!noise.present()) reader.fail(noise, "missing: G needs noise: {w: [...], v: [...]} (variances of w and v)");
  reader.check_keys(noise, {"w", "v"});
  const Field w = reader.child(noise, "w");
  const auto nw = static_cast<std::size_t>(s.G.cols());
  const std::vector<double> wv = w.present() ? read_list(reader, w, nw, 0, "variances of w (one per column of G)")
                                             : std::vector<double>(nw, 1.0);
  s.W = Eigen::Map<const Eigen::VectorXd>(wv.data(), static_cast<Eigen::Index>(nw)).asDiagonal();
  const std::vector<double> vv =
      read_list(reader, reader.child(noise, "v"), plant.n_outputs(), 0, "measurement-noise variances (one per output)");
  s.R = Eigen::Map<const Eigen::VectorXd>(vv.data(), static_cast<Eigen::Index>(vv.size()));
  plant.noise.assign(plant.n_outputs(), std::nullopt);
  for (std::size_t j = 0; j < plant.n_outputs(); ++j) {
    NoiseModel nm;
    try {
      nm = innovations_model(s, j);
    } catch (const std::invalid_argument& e) {
      reader.fail(g_field, "disturbance model of output " + plant.outputs[j] + ": " + e.what());
    }
    if (largest_root_of(nm.tf.den) >= 1.0 - 1e-9 || largest_root_of(nm.tf.num) >= 1.0 - 1e-9)
      reader.fail(g_field, "the disturbance model of output " + plant.outputs[j] +
                               " is not stable with a stable inverse (A's disturbance part must be stable)");
    plant.noise[j] = std::move(nm);
  }
}

}  // namespace

void read_state_space(const YamlReader& reader, const Field& ss, const Limits& limits, PlantModel& plant) {
  reader.check_keys(ss, {"A", "B", "C", "D", "discrete", "G", "Bd", "noise", "input_delay"});
  const auto m = static_cast<Eigen::Index>(plant.n_inputs()), p = static_cast<Eigen::Index>(plant.n_outputs());
  const Field a = reader.child(ss, "A");
  const std::size_t n = reader.list_size(a, false);
  if (n < 1 || n > limits.max_states)
    reader.fail(a, "expected 1.." + std::to_string(limits.max_states) + " states (rows of A), got " +
                       std::to_string(n) + " (the limit is Limits::max_states)");
  const auto ni = static_cast<Eigen::Index>(n);
  StateSpace s;
  s.A = read_matrix(reader, a, ni, ni, "a " + dims(ni, ni) + " matrix");
  s.B = read_matrix(reader, reader.child(ss, "B"), ni, m, "an n x inputs matrix, " + dims(ni, m));
  s.C = read_matrix(reader, reader.child(ss, "C"), p, ni, "an outputs x n matrix, " + dims(p, ni));
  const Field d = reader.child(ss, "D");
  s.D = d.present() ? read_matrix(reader, d, p, m, "an outputs x inputs matrix, " + dims(p, m))
                    : Eigen::MatrixXd::Zero(p, m);
  const Field discrete = reader.child(ss, "discrete");
  if (!discrete.present() || !discrete.node.IsScalar() ||
      (discrete.node.Scalar() != "true" && discrete.node.Scalar() != "false"))
    reader.fail_expected(discrete, "true (x+ = A x + B u, one step per sample) or false (dx/dt = A x + B u)");
  const bool is_discrete = discrete.node.Scalar() == "true";
  if (reader.child(ss, "G").present() && reader.child(ss, "Bd").present())
    reader.fail(reader.child(ss, "Bd"), "give the disturbance input as G or as Bd, not both");
  const Field g = reader.child(ss, reader.child(ss, "Bd").present() ? "Bd" : "G");
  if (!g.present() && reader.child(ss, "noise").present())
    reader.fail(reader.child(ss, "noise"), "needs G (or Bd): the matrix through which w enters");
  s.G = g.present() ? read_matrix(reader, g, ni, -1, "an n x nw matrix (n = " + std::to_string(n) + " states)")
                    : Eigen::MatrixXd::Zero(ni, 0);
  if (!is_discrete) {
    try {
      s = discretize_zoh(s, plant.sample_time);
    } catch (const std::invalid_argument& e) {
      reader.fail(a, std::string("cannot discretise: ") + e.what());
    }
  }
  std::vector<double> delays(plant.n_inputs(), 0.0);
  if (const Field delay = reader.child(ss, "input_delay"); delay.present()) {
    delays = read_list(reader, delay, plant.n_inputs(), 0, "delays in samples (one per input)");
    for (const double x : delays)
      if (x != std::floor(x) || x > limits.max_delay_samples)
        reader.fail(delay, "expected whole delays in 0.." + std::to_string(limits.max_delay_samples) + " samples");
  }
  for (Eigen::Index j = 0; j < p; ++j)
    for (Eigen::Index i = 0; i < m; ++i) {
      ChannelModel ch;
      ch.output = static_cast<std::size_t>(j);
      ch.input = static_cast<std::size_t>(i);
      ch.tf = channel_tf(s, ch.output, ch.input);
      if (ch.tf.is_zero()) continue;  // u_i does not reach y_j: an absent channel
      ch.tf.delay = static_cast<int>(delays[ch.input]);
      check_model_stable(reader, a, ch.tf);
      plant.channels.push_back(std::move(ch));
    }
  if (g.present()) read_disturbance(reader, ss, g, s, plant);
}

}  // namespace mpm::config::detail
