#include "core/lie_coefficients.hpp"

#include <array>
#include <cmath>
#include <numbers>

namespace parallax::lie_detail {
namespace {

constexpr int kQuadratureNodes = 16;

struct GaussLegendreRule {
  std::array<double, kQuadratureNodes> nodes{};    // on [0, 1]
  std::array<double, kQuadratureNodes> weights{};  // sum to 1
};

// Nodes are roots of the Legendre polynomial P_n, found by Newton's method from the
// classical cosine initial guess; weights 2 / ((1 - x^2) P_n'(x)^2), mapped from [-1, 1].
GaussLegendreRule MakeGaussLegendreRule() {
  GaussLegendreRule rule;
  const int n = kQuadratureNodes;
  for (int i = 0; i < n; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p_prev = 1.0;
      double p = x;
      for (int k = 2; k <= n; ++k) {
        const double p_next = ((2.0 * k - 1.0) * x * p - (k - 1.0) * p_prev) / k;
        p_prev = p;
        p = p_next;
      }
      derivative = n * (x * p - p_prev) / (x * x - 1.0);
      const double step = p / derivative;
      x -= step;
      if (std::abs(step) < 1e-16) break;
    }
    const auto index = static_cast<std::size_t>(i);
    rule.nodes[index] = 0.5 * (x + 1.0);
    rule.weights[index] = 1.0 / ((1.0 - x * x) * derivative * derivative);
  }
  return rule;
}

const GaussLegendreRule& Rule() {
  static const GaussLegendreRule rule = MakeGaussLegendreRule();
  return rule;
}

}  // namespace

double Sinc(double x) {
  if (std::abs(x) < 1e-3) {
    const double x2 = x * x;
    return 1.0 - x2 / 6.0 * (1.0 - x2 / 20.0);
  }
  return std::sin(x) / x;
}

double OneMinusCosOverSq(double theta) {
  const double s = Sinc(0.5 * theta);
  return 0.5 * s * s;
}

double ThetaMinusSinOverCube(double theta) {
  if (std::abs(theta) < 1e-2) {
    const double t2 = theta * theta;
    return 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  }
  return (theta - std::sin(theta)) / (theta * theta * theta);
}

double LeftJacobianInverseCoefficient(double theta) {
  if (std::abs(theta) < 1e-2) {
    const double t2 = theta * theta;
    return 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  }
  const double half = 0.5 * theta;
  return (1.0 - half * std::cos(half) / std::sin(half)) / (theta * theta);
}

SimilarityCoefficients ComputeSimilarityCoefficients(double theta, double sigma) {
  const GaussLegendreRule& rule = Rule();
  SimilarityCoefficients out{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < rule.nodes.size(); ++i) {
    const double tau = rule.nodes[i];
    const double w = rule.weights[i] * std::exp(sigma * tau);
    out.a += w;
    // sin(theta tau)/theta = tau sinc(theta tau); (1 - cos(theta tau))/theta^2 likewise.
    out.b += w * tau * Sinc(theta * tau);
    out.c += w * tau * tau * OneMinusCosOverSq(theta * tau);
  }
  return out;
}

}  // namespace parallax::lie_detail
