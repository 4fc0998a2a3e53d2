#include "core/nested_rls.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <variant>

#include "core/givens.hpp"

namespace mpm {
namespace {

// Lower factors updated together (UdRls::update_staged): enough
// independent rotation chains to hide the divisions' latency.
constexpr std::size_t kLockstep = 8;
// Factors with more regressors than this are updated alone: their rows are
// long enough to hide the latency by themselves, and one factor at a time
// walks its rows in memory order (a stream the prefetchers follow) instead
// of hopping between eight factors' short row segments.
constexpr std::size_t kLockstepMaxRegressors = 64;

}  // namespace

NestedRls::NestedRls(std::size_t prefix, std::size_t blocks, std::size_t block_size, double forgetting,
                     double regularization, bool wald_tests)
    : a_(prefix),
      m_(blocks),
      nb_(block_size),
      cols_(prefix + blocks * block_size + 1),
      lambda_(forgetting),
      delta_(regularization),
      first_pair_(wald_tests ? 0 : 1) {
  if (prefix == 0 || blocks == 0 || block_size == 0)
    throw std::invalid_argument("NestedRls: need a prefix and at least one block of regressors");
  if (!(forgetting > 0.0 && forgetting <= 1.0)) throw std::invalid_argument("NestedRls: forgetting must be in (0, 1]");
  if (!(regularization > 0.0)) throw std::invalid_argument("NestedRls: regularization must be > 0");
  prior_ = KeptAlivePrior(a_, forgetting, delta_);
  // One spare block of lanes past the padded width (always zero): whole-lane
  // reads of a block of B columns may run past the last one.
  top_.resize(static_cast<Eigen::Index>(a_), static_cast<Eigen::Index>(givens::padded(cols_) + givens::kLanes));
  top_d_.resize(static_cast<Eigen::Index>(a_));
  if (wald_tests) lower_ = BiermanRls(m_ * nb_, nb_, forgetting, regularization);
  else lower_ = UdRls(m_ * nb_, forgetting, regularization);
  pairs_.assign(m_ - first_pair_, UdRls(nb_, forgetting, regularization));
  row_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(givens::padded(cols_)));
  apriori_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m_ * nb_ + 1));
  pair_rhs_.resize(static_cast<Eigen::Index>(a_), static_cast<Eigen::Index>(m_));
  coef_b_.resize(static_cast<Eigen::Index>(m_ * nb_));
  pair_beta_b_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(givens::padded(nb_)), static_cast<Eigen::Index>(m_));
  pair_prefix_.resize(static_cast<Eigen::Index>(givens::padded(a_)), static_cast<Eigen::Index>(m_));
  reset();
}

void NestedRls::reset() noexcept {
  top_.setZero();
  for (std::size_t i = 0; i < a_; ++i) top_(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) = 1.0;
  top_d_.setConstant(delta_);
  std::visit([](auto& lower) { lower.reset(); }, lower_);
  for (UdRls& p : pairs_) p.reset();
  prior_.reset();
  apriori_.setZero();
  apriori_weight_ = 0.0;
}

void NestedRls::absorb_top(std::size_t first, double lambda) noexcept {
  const std::size_t end = givens::padded(cols_);
  for (std::size_t i = first; i < a_; ++i)
    givens::rotate_sqrt_free(top_.row(static_cast<Eigen::Index>(i)).data(), top_d_[static_cast<Eigen::Index>(i)],
                             row_.data(), row_weight_, i, end, lambda);
}

void NestedRls::stage_lowers() noexcept {
  const double* w = row_.data();
  const double y = w[cols_ - 1];
  std::visit(
      [&](auto& lower) {
        std::copy(w + a_, w + cols_, lower.staged_row());  // B_1 .. B_m, y
        lower.stage_weight(row_weight_);
      },
      lower_);
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const std::size_t i = first_pair_ + k;  // the input of pairs_[k]
    UdRls& pair = pairs_[k];
    double* q = pair.staged_row();
    std::copy(w + a_ + i * nb_, w + a_ + (i + 1) * nb_, q);
    q[nb_] = y;
    pair.stage_weight(row_weight_);
  }
}

void NestedRls::add_to_lowers() noexcept {
  const double* w = row_.data();
  const double y = w[cols_ - 1];
  std::visit([&](auto& lower) { lower.add_row(w + a_, y, row_weight_); }, lower_);
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const std::size_t i = first_pair_ + k;
    pairs_[k].add_row(w + a_ + i * nb_, y, row_weight_);
  }
}

void NestedRls::update(const double* x, double y) noexcept {
  std::copy(x, x + (cols_ - 1), row_.data());
  row_[static_cast<Eigen::Index>(cols_ - 1)] = y;
  update_staged(this, 1);
}

void NestedRls::update_staged(NestedRls* models, std::size_t count) noexcept {
  // The trapezoids' rotation i of every model, then rotation i + 1, so the
  // models' chains of dependent divisions overlap.
  std::size_t rows = 0;
  for (std::size_t k = 0; k < count; ++k) {
    rows = std::max(rows, models[k].a_);
    models[k].row_weight_ = 1.0;
  }
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t k = 0; k < count; ++k) {
      NestedRls& n = models[k];
      if (i < n.a_)
        givens::rotate_sqrt_free(n.top_.row(static_cast<Eigen::Index>(i)).data(), n.top_d_[static_cast<Eigen::Index>(i)],
                                 n.row_.data(), n.row_weight_, i, givens::padded(n.cols_), n.lambda_);
    }
  // Then every lower factor: the small ones a few at a time, a covariance-
  // form one alone (its one pass over its columns has latency to spare).
  UdRls* group[kLockstep] = {};
  std::size_t in_group = 0;
  const auto add = [&](UdRls& lower) {
    if (lower.n_regressors() > kLockstepMaxRegressors) {
      UdRls* alone = &lower;
      UdRls::update_staged(&alone, 1);
      return;
    }
    group[in_group++] = &lower;
    if (in_group == kLockstep) {
      UdRls::update_staged(group, in_group);
      in_group = 0;
    }
  };
  for (std::size_t k = 0; k < count; ++k) {
    NestedRls& n = models[k];
    std::copy(n.row_.data() + n.a_, n.row_.data() + n.cols_, n.apriori_.data());
    n.apriori_weight_ = n.row_weight_;
    n.stage_lowers();
    if (auto* wald = std::get_if<BiermanRls>(&n.lower_)) wald->update_staged();
    else add(std::get<UdRls>(n.lower_));
    for (UdRls& p : n.pairs_) add(p);
  }
  if (in_group > 0) UdRls::update_staged(group, in_group);
  for (std::size_t k = 0; k < count; ++k) models[k].refresh_prior();
}

void NestedRls::refresh_prior() noexcept {
  if (const auto row = prior_.due(row_.data(), cols_)) {
    row_weight_ = 1.0;
    absorb_top(*row, 1.0);
    add_to_lowers();
  }
}

double NestedRls::rss_head(std::size_t k) const noexcept {
  const auto target = static_cast<Eigen::Index>(cols_ - 1);
  double s = rss_prefix_only();
  for (std::size_t r = k; r < a_; ++r) {
    const auto rr = static_cast<Eigen::Index>(r);
    const double z = top_(rr, target);
    s += top_d_[rr] * (z * z);
  }
  return s;
}

double NestedRls::rss_pair(std::size_t i) const noexcept {
  return i < first_pair_ ? information_lower()->rss_prefix(nb_) : pairs_[i - first_pair_].rss();
}

double NestedRls::rss_pair_prefix_only(std::size_t i) const noexcept {
  return pair_factor(i).rss_prefix(0);
}

double NestedRls::rss_without_block(std::size_t i, Matrix& scratch) const noexcept {
  if (m_ == 1) return rss_prefix_only();
  // Two inputs: the model without one is the pairwise model of the other.
  if (m_ == 2) return rss_pair(1 - i);
  if (const UdRls* ud = information_lower()) return ud->rss_without(i * nb_, nb_, scratch);
  return std::get<BiermanRls>(lower_).rss_without_block(i, scratch);
}

void NestedRls::solve_top_unit(const double* rhs, std::size_t count, double* out, std::size_t out_stride) const noexcept {
  // Back substitution with the unit diagonal of U_AA, column by column (one
  // product and one update per coefficient on the dependency chain), two
  // right-hand sides sharing each load of U.
  const double* __restrict u = top_.data();
  const auto ld = static_cast<std::size_t>(top_.cols());
  for (std::size_t i = 0; i < count; i += 2) {
    const bool two = i + 1 < count;
    double* __restrict x0 = out + i * out_stride;
    double* __restrict x1 = two ? x0 + out_stride : x0;
    std::copy(rhs + i * a_, rhs + (i + 1) * a_, x0);
    if (two) std::copy(rhs + (i + 1) * a_, rhs + (i + 2) * a_, x1);
    for (std::size_t c = a_; c-- > 0;) {
      const double* col = u + c;
      const double b0 = x0[c];
      if (two) {
        const double b1 = x1[c];
        for (std::size_t r = 0; r < c; ++r) {
          const double v = col[r * ld];
          x0[r] -= v * b0;
          x1[r] -= v * b1;
        }
      } else {
        for (std::size_t r = 0; r < c; ++r) x0[r] -= col[r * ld] * b0;
      }
    }
  }
}

void NestedRls::solve_top(std::size_t b0, std::size_t count, const double* beta_b, double* beta_a) const noexcept {
  // U_AA beta_A = U_Ay - U_AB beta_B (the rows' weights cancel).
  const auto target = static_cast<Eigen::Index>(cols_ - 1);
  double* rhs = pair_rhs_.col(0).data();
  for (std::size_t r = 0; r < a_; ++r) {
    const double* row = top_.row(static_cast<Eigen::Index>(r)).data() + a_ + b0;
    double v = top_(static_cast<Eigen::Index>(r), target);
    for (std::size_t c = 0; c < count; ++c) v -= row[c] * beta_b[c];
    rhs[r] = v;
  }
  solve_top_unit(rhs, 1, beta_a, a_);
}

const Eigen::MatrixXd& NestedRls::solve_pairs_prefix() const noexcept {
  using givens::Lanes;
  using givens::load;
  constexpr std::size_t kLanes = givens::kLanes;
  const std::size_t target = cols_ - 1;
  const std::size_t nb_padded = givens::padded(nb_);
  // beta_B_i of every pairwise model, each zero-padded to whole lanes.
  for (std::size_t i = 0; i < m_; ++i) {
    double* beta_b = pair_beta_b_.col(static_cast<Eigen::Index>(i)).data();
    pair_factor(i).solve_prefix_padded(nb_, beta_b);
  }
  // Right-hand sides U_Ay - U_AB_i beta_B_i, one column each: a dot product
  // of whole lanes per row (the lanes past B_i meet beta's zero padding;
  // top_ has a spare block of lanes so the last block stays inside the row),
  // four rows' reductions done together.
  const double* top = top_.data();
  const auto top_ld = static_cast<std::size_t>(top_.cols());
  const double* betas = pair_beta_b_.data();
  double* rhs = pair_rhs_.data();
  const auto rhs_column = [&]<std::size_t kBlocks>(std::size_t i) {
    // kBlocks lanes per dot product when known at compile time (the short
    // blocks of the paper's orders: straight-line code), else nb_padded.
    const std::size_t blocks = kBlocks > 0 ? kBlocks : nb_padded / kLanes;
    const double* beta = betas + i * nb_padded;
    const auto dot = [&](std::size_t r) {
      const double* bi = top + r * top_ld + a_ + i * nb_;
      Lanes acc = {};
      for (std::size_t b = 0; b < blocks; ++b) acc += load(bi + b * kLanes) * load(beta + b * kLanes);
      return acc;
    };
    double* out = rhs + i * a_;
    std::size_t r = 0;
    for (; r + 4 <= a_; r += 4) {
      const Lanes y = {top[r * top_ld + target], top[(r + 1) * top_ld + target], top[(r + 2) * top_ld + target],
                       top[(r + 3) * top_ld + target]};
      givens::store(out + r, y - givens::sum4(dot(r), dot(r + 1), dot(r + 2), dot(r + 3)));
    }
    for (; r < a_; ++r) out[r] = top[r * top_ld + target] - givens::sum(dot(r));
  };
  for (std::size_t i = 0; i < m_; ++i) {
    switch (nb_padded / kLanes) {
      case 1: rhs_column.template operator()<1>(i); break;
      case 2: rhs_column.template operator()<2>(i); break;
      case 3: rhs_column.template operator()<3>(i); break;
      case 4: rhs_column.template operator()<4>(i); break;
      default: rhs_column.template operator()<0>(i); break;
    }
  }
  // pair_prefix = U_AA^-1 rhs, zero past a.
  const std::size_t a_padded = givens::padded(a_);
  double* prefix = pair_prefix_.data();
  for (std::size_t i = 0; i < m_; ++i) std::fill(prefix + i * a_padded + a_, prefix + (i + 1) * a_padded, 0.0);
  solve_top_unit(rhs, m_, prefix, a_padded);
  return pair_prefix_;
}

void NestedRls::solve_pair_prefix(std::size_t i, Eigen::Ref<Eigen::VectorXd> out) const noexcept {
  auto beta_b = coef_b_.head(static_cast<Eigen::Index>(nb_));
  pair_factor(i).solve_prefix(nb_, beta_b);
  solve_top(i * nb_, nb_, beta_b.data(), out.data());
}

void NestedRls::solve_full(Eigen::Ref<Eigen::VectorXd> out) const noexcept {
  if (const UdRls* ud = information_lower()) ud->solve_prefix(m_ * nb_, coef_b_);
  else coef_b_ = std::get<BiermanRls>(lower_).coefficients();
  solve_top(0, m_ * nb_, coef_b_.data(), out.data());
  std::copy(coef_b_.data(), coef_b_.data() + m_ * nb_, out.data() + a_);
}

double NestedRls::information_quadratic(const double* s, double* z) const noexcept {
  const std::size_t d = m_ * nb_;
  const UdRls* ud = information_lower();
  if (!ud) return std::get<BiermanRls>(lower_).covariance_quadratic(s);
  // S = U^T D U over the first d regressors: z = U^-T s by forward
  // substitution (rows of U are contiguous), then sum z_i^2 / D_i.
  const auto u = ud->unit_factor();
  const double* base = u.data();
  const auto ld = static_cast<std::size_t>(u.outerStride());
  const Eigen::VectorXd& dd = ud->weights();
  std::copy(s, s + d, z);
  double q = 0.0;
  for (std::size_t i = 0; i < d; ++i) {
    const double zi = z[i];
    const double* row = base + i * ld;
    for (std::size_t k = i + 1; k < d; ++k) z[k] -= row[k] * zi;
    q += zi * zi / dd[static_cast<Eigen::Index>(i)];
  }
  return q;
}

void NestedRls::inputs_covariance(double* out, std::size_t ld) const noexcept {
  const std::size_t d = m_ * nb_;
  const UdRls* ud = information_lower();
  if (!ud) {
    std::get<BiermanRls>(lower_).covariance_into(out, ld);
    return;
  }
  // P = U^-1 D^-1 U^-T: V = U^-1 column by column into the upper triangle of
  // out (back substitution), then P_ab = sum_j V_aj V_bj / D_j.
  const auto u = ud->unit_factor();
  const double* base = u.data();
  const auto lu = static_cast<std::size_t>(u.outerStride());
  const Eigen::VectorXd& dd = ud->weights();
  const auto v = [&](std::size_t a, std::size_t j) -> double& { return out[a + j * ld]; };
  for (std::size_t j = 0; j < d; ++j) {
    v(j, j) = 1.0;
    for (std::size_t a = j; a-- > 0;) {
      double x = 0.0;
      for (std::size_t k = a + 1; k <= j; ++k) x -= base[a * lu + k] * v(k, j);
      v(a, j) = x;
    }
  }
  // P into the lower triangle, column b after column b: P_ab (a <= b) reads
  // V_aj and V_bj for j >= b only, none of which the lower triangle's
  // earlier entries (or this diagonal, read before written) overwrote.
  for (std::size_t b = 0; b < d; ++b)
    for (std::size_t a = 0; a <= b; ++a) {
      double x = 0.0;
      for (std::size_t j = b; j < d; ++j) x += v(a, j) * v(b, j) / dd[static_cast<Eigen::Index>(j)];
      out[b + a * ld] = x;  // lower triangle (row b, column a)
    }
  for (std::size_t b = 0; b < d; ++b)
    for (std::size_t a = 0; a < b; ++a) out[a + b * ld] = out[b + a * ld];
}

void NestedRls::inputs_information(double* out, std::size_t ld) const noexcept {
  // S = U^T D U over the inputs' block (U unit upper): row i of D U is D_i
  // times row i of U, so S = sum_i D_i u_i^T u_i, one rank-one update per row
  // on the upper triangle (row i of U is zero before column i), mirrored.
  const auto d = static_cast<Eigen::Index>(m_ * nb_);
  const UdRls& lower = std::get<UdRls>(lower_);
  const auto u = lower.unit_factor();
  const Eigen::VectorXd& dd = lower.weights();
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> s(out, d, d, Eigen::OuterStride<>(static_cast<Eigen::Index>(ld)));
  s.setZero();
  for (Eigen::Index i = 0; i < d; ++i) {
    const auto row = u.row(i).segment(i, d - i);
    for (Eigen::Index b = i; b < d; ++b) s.col(b).segment(i, b - i + 1).noalias() += (dd[i] * row[b - i]) * row.head(b - i + 1).transpose();
  }
  for (Eigen::Index b = 0; b < d; ++b)
    for (Eigen::Index a = b + 1; a < d; ++a) s(a, b) = s(b, a);
}

}  // namespace mpm
