#pragma once
// Scalar coefficient functions shared by the SO(3), SE(3) and Sim(3) exponential maps.
// They are evaluated in double whatever the group's scalar, with Taylor branches where the
// closed forms cancel catastrophically; derivations in docs/math/lie_groups.md.

namespace parallax::lie_detail {

/// sin(x) / x, exact to double precision for every x (Taylor branch for |x| < 1e-3).
double Sinc(double x);

/// (1 - cos(theta)) / theta^2, written as 0.5 * sinc(theta/2)^2 so it never cancels.
double OneMinusCosOverSq(double theta);

/// (theta - sin(theta)) / theta^3 (Taylor branch for theta < 1e-2).
double ThetaMinusSinOverCube(double theta);

/// (1 - (theta/2) * cot(theta/2)) / theta^2: the Omega^2 coefficient of the inverse left
/// Jacobian of SO(3). Finite for theta in [0, 2*pi).
double LeftJacobianInverseCoefficient(double theta);

/// Coefficients of W = a I + b Omega + c Omega^2, the matrix that maps the translational part
/// of a sim(3) tangent to the group translation: W = integral_0^1 exp(sigma*tau) R(tau*omega)
/// dtau, with theta = |omega|. Evaluated by 16-point Gauss-Legendre quadrature of smooth,
/// cancellation-free integrands (accurate to ~1e-16 for |sigma|, theta <= 10).
struct SimilarityCoefficients {
  double a = 1.0;
  double b = 0.5;
  double c = 1.0 / 6.0;
};
SimilarityCoefficients ComputeSimilarityCoefficients(double theta, double sigma);

}  // namespace parallax::lie_detail
