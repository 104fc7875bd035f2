// Purpose: tests of the Singer model in motion.hpp: F and Q against a Van Loan matrix exponential, the small-alpha T series, and the CA / CV limits.
#include <trackflow/motion.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <cmath>

using namespace trackflow;

namespace {

// exp(M) by scaling and squaring with a 24-term Taylor series (||M / 2^s|| <= 1/2).
template <int K>
Eigen::Matrix<double, K, K> expm(const Eigen::Matrix<double, K, K>& M) {
  using Mat = Eigen::Matrix<double, K, K>;
  const double norm = M.cwiseAbs().rowwise().sum().maxCoeff();
  int s = 0;
  while (norm / std::ldexp(1.0, s) > 0.5) ++s;
  const Mat A = M / std::ldexp(1.0, s);
  Mat E = Mat::Identity(), term = Mat::Identity();
  for (int k = 1; k <= 24; ++k) {
    term = (term * A / k).eval();
    E += term;
  }
  for (int i = 0; i < s; ++i) E = (E * E).eval();
  return E;
}

struct Discrete {
  Eigen::Matrix3d F, Q;
};

// Van Loan (1978): exp([[-A, b b'], [0, A']] t) = [[., F^-1 Q], [0, F']] for unit PSD. The
// e^{-At} block overflows precision for large alpha t, so it is applied over a short step t
// and doubled: F(2t) = F(t)^2, Q(2t) = F(t) Q(t) F(t)' + Q(t).
Discrete van_loan(double alpha, double T) {
  Eigen::Matrix3d A;
  A << 0, 1, 0, 0, 0, 1, 0, 0, -alpha;
  int doublings = 0;
  double t = T;
  while (alpha * t > 0.5) {
    t /= 2;
    ++doublings;
  }
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  C.topLeftCorner<3, 3>() = -A * t;
  C(2, 5) = t;  // b b' at (a, a)
  C.bottomRightCorner<3, 3>() = A.transpose() * t;
  const Eigen::Matrix<double, 6, 6> E = expm<6>(C);
  Discrete d;
  d.F = E.bottomRightCorner<3, 3>().transpose();
  d.Q = d.F * E.topRightCorner<3, 3>();
  for (int i = 0; i < doublings; ++i) {
    d.Q = (d.F * d.Q * d.F.transpose() + d.Q).eval();
    d.F = (d.F * d.F).eval();
  }
  d.Q = 0.5 * (d.Q + d.Q.transpose()).eval();
  return d;
}

double max_rel_entry(const Eigen::Matrix3d& got, const Eigen::Matrix3d& ref) {
  double worst = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double scale = std::abs(ref(i, j));
      if (scale == 0.0) {
        worst = std::max(worst, std::abs(got(i, j)) > 1e-300 ? 1.0 : 0.0);
        continue;
      }
      worst = std::max(worst, std::abs(got(i, j) - ref(i, j)) / scale);
    }
  return worst;
}

}  // namespace

// Singer F and Q equal the Van Loan exponential for tiny to large alpha T
TEST_CASE("Singer F and Q equal the Van Loan exponential") {
  for (double T : {0.025, 1.0, 10.0})
    for (double x : {1e-9, 1e-6, 1e-3, 0.05, 0.3, 0.4999, 0.5001, 1.0, 3.0, 20.0, 300.0}) {
      const double alpha = x / T;
      const Discrete ref = van_loan(alpha, T);
      const Eigen::Matrix3d F = SingerModel::axis_transition(alpha, T);
      const Eigen::Matrix3d Q = SingerModel::noise_per_psd(alpha, T);
      INFO("T = " << T << " alpha T = " << x);
      CHECK(max_rel_entry(F, ref.F) < 1e-11);
      CHECK(max_rel_entry(Q, ref.Q) < 1e-8);
      CHECK((Q - Q.transpose()).norm() == 0.0);
      CHECK(Eigen::LLT<Eigen::Matrix3d>(Q).info() == Eigen::Success);
    }
}

TEST_CASE("Singer series and closed form meet at the switch point") {
  const double T = 2.0, limit = SingerModel::kSeriesLimit;
  const Eigen::Matrix3d below = SingerModel::noise_per_psd(limit * (1 - 1e-12) / T, T);
  const Eigen::Matrix3d above = SingerModel::noise_per_psd(limit / T, T);
  CHECK(max_rel_entry(below, above) < 1e-11);
  CHECK(max_rel_entry(SingerModel::axis_transition(limit * (1 - 1e-12) / T, T),
                      SingerModel::axis_transition(limit / T, T)) < 1e-11);
}

// alpha -> 0 with 2 alpha sigma^2 = q fixed gives the Wiener-process-acceleration CA model
TEST_CASE("Singer with small alpha tends to the CA model") {
  const double T = 0.5, q = 3.0, alpha = 1e-7;
  SingerModel m;
  m.alpha = alpha;
  m.sigma = std::sqrt(q / (2 * alpha));
  const Eigen::Matrix3d Qca = ConstantAcceleration::axis_noise_continuous(T, q);
  // Leading correction is O(alpha T) relative.
  CHECK(max_rel_entry(m.axis_noise(T), Qca) < 10 * alpha * T);
  CHECK(max_rel_entry(m.axis_transition(T), ConstantAcceleration::axis_transition(T)) < 10 * alpha * T);
}

// alpha -> infinity with 2 sigma^2 / alpha = q fixed gives the CV model in position and velocity
TEST_CASE("Singer with large alpha tends to the CV model") {
  const double T = 1.0, q = 2.0;
  for (double alpha : {1e3, 1e4}) {
    SingerModel m;
    m.alpha = alpha;
    m.sigma = std::sqrt(q * alpha / 2);
    const Eigen::Matrix3d Q = m.axis_noise(T);
    const Eigen::Matrix2d Qcv = ConstantVelocity::axis_noise_continuous(T, q);
    // Relative corrections are O(1 / (alpha T)).
    const Eigen::Matrix2d diff = Q.topLeftCorner<2, 2>() - Qcv;
    CHECK(diff.cwiseQuotient(Qcv).cwiseAbs().maxCoeff() < 5.0 / (alpha * T));
    CHECK(Q(2, 2) == Approx(m.sigma * m.sigma).epsilon(1e-9));  // acceleration decorrelates: stationary variance
  }
}
