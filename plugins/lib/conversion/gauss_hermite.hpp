// Purpose: test-only reference: Gaussian expectations by tensor-product Gauss–Hermite cubature (independent of the converters' closed forms).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include <cmath>
#include <utility>
#include <vector>

namespace trackflow::test {

// Nodes and weights of the n-point rule for the standard normal density (probabilists'
// Hermite), by Golub–Welsch: eigenvalues of the Jacobi matrix with off-diagonals sqrt(k).
// Exact for polynomials of degree 2n-1; for trigonometric integrands the error falls like
// σ^(2n)/(2n)!.
inline std::pair<std::vector<double>, std::vector<double>> gauss_hermite_rule(int n) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k < n; ++k) J(k, k - 1) = J(k - 1, k) = std::sqrt(static_cast<double>(k));
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(J);
  std::vector<double> x(n), w(n);
  for (int i = 0; i < n; ++i) {
    x[i] = es.eigenvalues()(i);
    w[i] = es.eigenvectors()(0, i) * es.eigenvectors()(0, i);
  }
  return {x, w};
}

// Calls f(point, weight) over the tensor rule for N(mean, cov) in D dimensions.
template <int D, class F>
void for_each_gauss_hermite(const Eigen::Matrix<double, D, 1>& mean, const Eigen::Matrix<double, D, D>& cov,
                            int order, F&& f) {
  const auto [x, w] = gauss_hermite_rule(order);
  // Zero variances are allowed (a degenerate dimension): LDLT-free square root by eigen-decomposition.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>> es(cov);
  const Eigen::Matrix<double, D, D> L =
      es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  int idx[D] = {};
  while (true) {
    Eigen::Matrix<double, D, 1> xi;
    double weight = 1.0;
    for (int d = 0; d < D; ++d) {
      xi(d) = x[idx[d]];
      weight *= w[idx[d]];
    }
    f(Eigen::Matrix<double, D, 1>(mean + L * xi), weight);
    int d = 0;
    while (d < D && ++idx[d] == order) idx[d++] = 0;
    if (d == D) break;
  }
}

// Mean and covariance of g(X), X ~ N(mean, cov), g: R^D -> R^K.
template <int K>
struct Moments {
  Eigen::Matrix<double, K, 1> mean = Eigen::Matrix<double, K, 1>::Zero();
  Eigen::Matrix<double, K, K> covariance = Eigen::Matrix<double, K, K>::Zero();
};
template <int K, int D, class G>
Moments<K> gauss_hermite_moments(const Eigen::Matrix<double, D, 1>& mean, const Eigen::Matrix<double, D, D>& cov,
                                 int order, G&& g) {
  // Two passes (mean, then centred products): no cancellation between E[yyᵀ] and E[y]E[y]ᵀ.
  Moments<K> m;
  for_each_gauss_hermite<D>(mean, cov, order,
                            [&](const Eigen::Matrix<double, D, 1>& x, double w) { m.mean += w * g(x); });
  for_each_gauss_hermite<D>(mean, cov, order, [&](const Eigen::Matrix<double, D, 1>& x, double w) {
    const Eigen::Matrix<double, K, 1> y = g(x) - m.mean;
    m.covariance += w * y * y.transpose();
  });
  return m;
}

}  // namespace trackflow::test
