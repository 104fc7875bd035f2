// Purpose: the multiplication counts of docs/performance.md, instrumented with a counting scalar and checked against the analytic counts of each phase.
#include "operation_counts.hpp"

#include <catch2/catch.hpp>

using namespace trackflow;
using namespace trackflow::gain_transform;

// the counting scalar counts what it should and computes what double computes
TEST_CASE("counting scalar counts and computes like double") {
  const OperationCount c = count_operations([] {
    const Counted a = 3.0, b = 4.0;
    const Counted r = sqrt(a * a + b * b) / (a - b);
    CHECK(static_cast<double>(r) == -5.0);
  });
  CHECK(c.mul == 2);
  CHECK(c.add == 2);
  CHECK(c.div == 1);
  CHECK(c.func == 1);
  // How Eigen 3.4 multiplies, for any scalar type: products with all sizes <= 8 are coefficient-
  // based, m n k multiplications. With a size above 8, if rows + cols + depth < 20 it is still
  // coefficient-based after combining the operands' scalar factors (1 more); otherwise it takes
  // its GEMM path, which also scales each of the m n results by alpha (= 1 here) and forms alpha
  // itself (2): m n k + m n + 2.
  const Eigen::Matrix<Counted, 9, 9> A = Eigen::Matrix<double, 9, 9>::Identity().cast<Counted>();
  const Eigen::Matrix<Counted, 9, 3> B = Eigen::Matrix<double, 9, 3>::Ones().cast<Counted>();
  Eigen::Matrix<Counted, 9, 3> C;
  const OperationCount small = count_operations([&] { C.topRows<3>() = A.topLeftCorner<3, 9>() * B; });
  CHECK(small.mul == 3 * 9 * 3 + 1);
  const OperationCount gemm = count_operations([&] { C = A * B; });
  CHECK(static_cast<double>(C(4, 2)) == 1.0);
  CHECK(gemm.mul == 9 * 9 * 3 + 9 * 3 + 2);
}

// gain-transform step: the counts stated in gain_transform_core.hpp
TEST_CASE("gain-transform step has the stated counts") {
  const StepCounts c = count_gain_transform_step();
  CHECK(c.covariance_prediction.mul == 1 + 3 * 22);  // sigma^2, then 16 + 6 per LOS axis
  CHECK(c.linearisation.mul == 8 + 14);              // frame (los_frame.hpp), measurement_variances
  CHECK(c.linearisation.div == 2 + 2);
  CHECK(c.linearisation.func == 4);                  // 2 hypot, 2 atan2: h(x) comes with the frame
  CHECK(c.gain_and_covariance_update.mul == 90 + 60);  // reframe, decoupled_gain
  CHECK(c.gain_and_covariance_update.div == 3);
  CHECK(c.state.mul == 12 + 32);                     // x = F x, correct_state
  CHECK(c.state.div == 3);
  CHECK(c.publication.mul == 153);
  CHECK(c.gain_computation().mul == 67 + 22 + 150);
}

// filter.ekf step (replica of its arithmetic): dense fixed-size products
TEST_CASE("filter.ekf step replica: dense products") {
  const StepCounts c = count_filter_ekf_step();
  CHECK(c.covariance_prediction.mul == 9 * 54 + 3 * 10 + 81);
  CHECK(c.linearisation.mul == 5 + 28);  // Jacobian, angle curvature
  // K: P H' (243), H (P H') (81), the Cholesky factor of S (4) and 9 triangular solve pairs (108);
  // Joseph form: K H (243), (I-KH) P (729), (.)(I-KH)' (729), K R (81), (K R) K' (243), (P1+P1')/2 (81).
  // Eigen's GEMM path adds m n + 2 to P H' (29) and to the four 9-row products of width 9 (83 each).
  const long long algorithmic = 243 + 81 + 4 + 108 + (243 + 729 + 729 + 81 + 243 + 81);
  const long long gemm_scaling = 29 + 4 * 83;
  CHECK(c.gain_and_covariance_update.mul >= algorithmic + gemm_scaling);
  CHECK(c.gain_and_covariance_update.mul <= algorithmic + gemm_scaling + 2);
  CHECK(c.state.mul >= 27 + 27 + 3);  // x = F x per axis, K nu, nu' S^-1 nu
  const StepCounts g = count_gain_transform_step();
  CHECK(g.gain_computation().mul < 0.1 * c.gain_computation().mul);
}

// lean EKF step: structured prediction and H-sparse symmetric update
TEST_CASE("lean EKF step: structured and sparse") {
  const StepCounts c = count_lean_ekf_step();
  CHECK(c.covariance_prediction.mul == 1 + 138);  // sigma^2, then lean_predict_covariance
  CHECK(c.linearisation.mul == 8);
  CHECK(c.gain_and_covariance_update.mul == 6 + 81 + 18 + 21 + 81 + 135);
  CHECK(c.gain_and_covariance_update.div == 3);
  CHECK(c.state.mul == 12 + 27);
  const StepCounts g = count_gain_transform_step();
  // The gain transform's saving against an EKF that already exploits H's and F's structure.
  CHECK(g.gain_computation().mul < 0.6 * c.gain_computation().mul);
}
