#include "backend/relative_pose_refinement.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "core/check.hpp"

namespace parallax {
namespace {

using Vector5d = Eigen::Matrix<double, 5, 1>;
using Matrix5d = Eigen::Matrix<double, 5, 5>;

/// Two unit vectors completing t (unit) to an orthonormal basis: the translation's tangent plane.
Eigen::Matrix<double, 3, 2> TangentBasis(const Eigen::Vector3d& t) {
  const Eigen::Vector3d helper =
      std::abs(t.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = t.cross(helper).normalized();
  basis.col(1) = t.cross(basis.col(0));
  return basis;
}

RelativePose Retract(const RelativePose& pose, const Vector5d& delta) {
  RelativePose out;
  out.R_cur_ref = SO3d::Exp(delta.head<3>()) * pose.R_cur_ref;
  out.t_cur_ref = (pose.t_cur_ref + TangentBasis(pose.t_cur_ref) * delta.tail<2>()).normalized();
  return out;
}

Eigen::Matrix3d Essential(const RelativePose& pose) {
  return SO3d::Hat(pose.t_cur_ref) * pose.R_cur_ref.Matrix();
}

double HuberCost(double r, double k) {
  const double a = std::abs(r);
  return a <= k ? 0.5 * r * r : k * (a - 0.5 * k);
}

struct NormalEquations {
  Matrix5d H = Matrix5d::Zero();
  Vector5d g = Vector5d::Zero();
  double weighted_squares = 0.0;  ///< sum of w r^2, pixels^2
};

struct Problem {
  const std::vector<Eigen::Vector2d>& x_ref;
  const std::vector<Eigen::Vector2d>& x_cur;
  double focal_px, huber_px;

  /// Residuals in pixels.
  Eigen::VectorXd Residuals(const RelativePose& pose) const {
    const Eigen::Matrix3d E = Essential(pose);
    Eigen::VectorXd r(static_cast<Eigen::Index>(x_ref.size()));
    for (std::size_t i = 0; i < x_ref.size(); ++i)
      r[static_cast<Eigen::Index>(i)] = focal_px * SampsonDistance(E, x_ref[i], x_cur[i]);
    return r;
  }
  /// Gauss-Newton normal equations with Huber (IRLS) weights at `pose`, whose residuals are
  /// `r`; the Jacobian by central differences (the residual is smooth and cheap).
  NormalEquations Linearise(const RelativePose& pose, const Eigen::VectorXd& r) const {
    constexpr double kStep = 1e-6;
    Eigen::MatrixXd J(r.size(), 5);
    for (int k = 0; k < 5; ++k) {
      Vector5d h = Vector5d::Zero();
      h[k] = kStep;
      J.col(k) = (Residuals(Retract(pose, h)) - Residuals(Retract(pose, -h))) / (2.0 * kStep);
    }
    NormalEquations eq;
    for (Eigen::Index i = 0; i < r.size(); ++i) {
      const double a = std::abs(r[i]);
      const double w = a <= huber_px ? 1.0 : huber_px / a;
      eq.H.noalias() += w * J.row(i).transpose() * J.row(i);
      eq.g.noalias() += w * J.row(i).transpose() * r[i];
      eq.weighted_squares += w * r[i] * r[i];
    }
    return eq;
  }
  double Cost(const Eigen::VectorXd& r) const {
    double c = 0.0;
    for (Eigen::Index i = 0; i < r.size(); ++i) c += HuberCost(r[i], huber_px);
    return c;
  }
};

}  // namespace

void RelativePoseRefinementOptions::Check() const {
  const char* s = "RelativePoseRefinementOptions";
  CheckOption(max_iterations >= 0, s, "max_iterations", "must be >= 0");
  CheckOption(huber_px > 0.0, s, "huber_px", "must be > 0");
  CheckOption(min_step >= 0.0, s, "min_step", "must be >= 0");
}

double SampsonDistance(const Eigen::Matrix3d& E, const Eigen::Vector2d& x_ref,
                       const Eigen::Vector2d& x_cur) {
  const Eigen::Vector3d a = x_ref.homogeneous(), b = x_cur.homogeneous();
  const Eigen::Vector3d Ea = E * a, Etb = E.transpose() * b;
  const double denominator = Ea.head<2>().squaredNorm() + Etb.head<2>().squaredNorm();
  if (!(denominator > 0.0)) return 0.0;
  return b.dot(Ea) / std::sqrt(denominator);
}

double RelativePoseCost(const std::vector<Eigen::Vector2d>& x_ref,
                        const std::vector<Eigen::Vector2d>& x_cur, const RelativePose& pose,
                        double focal_px, double huber_px) {
  CheckArgument(x_ref.size() == x_cur.size() && !x_ref.empty(),
                "RelativePoseCost: point counts differ or are zero");
  const Problem problem{x_ref, x_cur, focal_px, huber_px};
  return problem.Cost(problem.Residuals(pose)) / static_cast<double>(x_ref.size());
}

RelativePose RefineRelativePose(const std::vector<Eigen::Vector2d>& x_ref,
                                const std::vector<Eigen::Vector2d>& x_cur,
                                const RelativePose& initial, double focal_px,
                                const RelativePoseRefinementOptions& options) {
  options.Check();
  CheckArgument(x_ref.size() == x_cur.size(), "RefineRelativePose: point counts differ");
  CheckArgument(focal_px > 0.0, "RefineRelativePose: focal_px must be > 0");
  if (x_ref.size() < 5) return initial;
  const Problem problem{x_ref, x_cur, focal_px, options.huber_px};
  RelativePose pose = initial;
  Eigen::VectorXd r = problem.Residuals(pose);
  double cost = problem.Cost(r);
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    const NormalEquations eq = problem.Linearise(pose, r);
    const Vector5d delta = -eq.H.ldlt().solve(eq.g);
    if (!delta.allFinite()) break;
    // Halve the step until the robust cost decreases (Gauss-Newton can overshoot).
    bool improved = false;
    for (double scale = 1.0; scale > 1e-3 && !improved; scale *= 0.5) {
      const RelativePose candidate = Retract(pose, scale * delta);
      const Eigen::VectorXd r_candidate = problem.Residuals(candidate);
      const double c = problem.Cost(r_candidate);
      if (c < cost) {
        pose = candidate;
        r = r_candidate;
        cost = c;
        improved = true;
      }
    }
    if (!improved || delta.norm() < options.min_step) break;
  }
  return pose;
}

Eigen::Matrix<double, 5, 5> RelativePoseCovariance(const std::vector<Eigen::Vector2d>& x_ref,
                                                   const std::vector<Eigen::Vector2d>& x_cur,
                                                   const RelativePose& pose, double focal_px,
                                                   double huber_px) {
  CheckArgument(x_ref.size() == x_cur.size() && x_ref.size() > 5,
                "RelativePoseCovariance: point counts differ or are below 6");
  const Problem problem{x_ref, x_cur, focal_px, huber_px};
  const NormalEquations eq = problem.Linearise(pose, problem.Residuals(pose));
  const double variance = eq.weighted_squares / static_cast<double>(x_ref.size() - 5);
  const Eigen::LDLT<Matrix5d> ldlt(eq.H);
  const Matrix5d inverse = ldlt.solve(Matrix5d::Identity());
  if (ldlt.info() != Eigen::Success || !inverse.allFinite()) {
    return Matrix5d::Constant(std::numeric_limits<double>::infinity());
  }
  return variance * inverse;
}

}  // namespace parallax
