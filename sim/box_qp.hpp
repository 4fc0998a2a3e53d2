// A small dense quadratic program with bounds on every variable:
//
//   minimise 1/2 v'Hv + g'v   subject to  lo <= v <= hi,  H symmetric positive definite.
//
// OVERVIEW. MPC input limits become such bounds once the decision variables
// are the future inputs themselves (not their moves). The problems are small
// (control horizon x inputs, tens of variables), so a primal-dual active-set
// method (Hintermueller, Ito & Kunisch 2002) is exact in a handful of
// iterations: fix the active variables at their bounds, solve the free ones by
// Cholesky, then free any bound whose multiplier has the wrong sign and bind
// any free variable that left its box. Should the active set ever cycle, an
// accelerated projected gradient finishes the job. All storage is sized at
// setup; solve() allocates nothing.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Dense>

namespace mpm::sim {

struct BoxQpResult {
  int active_set_iterations = 0;
  int gradient_iterations = 0;  // > 0 only when the active-set method gave up
  bool converged = false;
};

class BoxQp {
 public:
  BoxQp() = default;
  // Throws std::invalid_argument if h is not square, symmetric positive definite.
  explicit BoxQp(const Eigen::MatrixXd& h, int max_active_set_iterations = 50, int max_gradient_iterations = 5000);

  std::size_t size() const noexcept { return static_cast<std::size_t>(h_.rows()); }
  // Real-time safe. v: in, a starting guess (e.g. the unconstrained optimum);
  // out, the solution. lo <= hi elementwise (infinite bounds allowed).
  BoxQpResult solve(const Eigen::VectorXd& g, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                    Eigen::VectorXd& v) noexcept;

 private:
  bool solve_free(const Eigen::VectorXd& g, Eigen::VectorXd& v) noexcept;
  bool update_active_set(const Eigen::VectorXd& lo, const Eigen::VectorXd& hi, const Eigen::VectorXd& v) noexcept;
  // Returns true when converged; counts its iterations into `iterations`.
  bool projected_gradient(const Eigen::VectorXd& g, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                          Eigen::VectorXd& v, int& iterations) noexcept;

  Eigen::MatrixXd h_;
  double lipschitz_ = 1.0;  // largest eigenvalue of H
  int max_active_set_iterations_ = 50;
  int max_gradient_iterations_ = 5000;
  // Workspace.
  std::vector<int> state_;  // -1 at lower bound, +1 at upper, 0 free
  std::vector<std::size_t> free_;
  Eigen::MatrixXd chol_;
  Eigen::VectorXd rhs_, grad_, y_, v_prev_;
};

}  // namespace mpm::sim
