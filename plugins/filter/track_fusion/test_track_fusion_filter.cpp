// Purpose: tests of filter.track_fusion as a node: information fusion of two local tracks equals the hand-computed sum of their information, CI publishes a fused estimate, a mismatched state size is refused, the shared motion block's checks.
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <trackflow/error.hpp>

#include <Eigen/Dense>

using namespace trackflow;

namespace {

// A constant-velocity estimate (state [x vx y vy z vz]) at time t with diagonal covariance.
Estimate cv_estimate(double t, double pos, double var) {
  Estimate e;
  e.time = t;
  e.initialised = true;
  e.updated = true;
  e.state = StateVec::Zero(6);
  e.state(0) = pos;
  e.covariance = StateCov::Identity(6, 6) * var;
  return e;
}

std::shared_ptr<Component> node(const std::string& yaml, test::Collector& out) {
  auto n = test::make("filter.track_fusion", yaml);
  n->set_inputs({{"a", "filter.ekf", mask(ItemKind::Estimate), {}}, {"b", "filter.ekf", mask(ItemKind::Estimate), {}}});
  out.attach_to(*n);
  testing::start_run(*n);
  return n;
}

}  // namespace

// Both local tracks start at t = 0 (no local prior): the fused information is the sum,
// x = (1/1 * 0 + 1/4 * 10) / (1 + 1/4) = 2, P = 0.8. The first estimate alone is published first.
TEST_CASE("track_fusion: node IMF adds first estimates") {
  test::Collector out;
  auto n = node("{method: information, q: 0 m2/s3}", out);
  n->on_estimate(cv_estimate(0.0, 0.0, 1.0), 0);
  n->on_estimate(cv_estimate(0.0, 10.0, 4.0), 1);
  REQUIRE(out.estimates.size() == 2);
  CHECK(out.estimates[0].enu(0) == Approx(0.0).margin(1e-12));
  CHECK(out.estimates[1].enu(0) == Approx(2.0).epsilon(1e-12));
  CHECK(out.estimates[1].enu_covariance(0, 0) == Approx(0.8).epsilon(1e-12));
  // A second update of input a at t = 1 that added nothing (same covariance as its prediction
  // with q = 0 and zero velocity) leaves the fused track as it was.
  Estimate again = cv_estimate(1.0, 0.0, 1.0);
  again.covariance(0, 0) = 1.0 + 1.0;  // P(1|0) = F P F' with T = 1: var x + var vx
  again.covariance(0, 1) = again.covariance(1, 0) = 1.0;
  again.covariance(2, 2) = again.covariance(4, 4) = 2.0;
  again.covariance(2, 3) = again.covariance(3, 2) = again.covariance(4, 5) = again.covariance(5, 4) = 1.0;
  n->on_estimate(again, 0);
  REQUIRE(out.estimates.size() == 3);
  CHECK(out.estimates[2].enu(0) == Approx(2.0).epsilon(1e-9));
  CHECK(out.estimates[2].enu_covariance(0, 0) == Approx(0.8 + 0.8).epsilon(1e-9));  // predicted: var x + var vx
}

// CI of the same two estimates with the trace criterion: all axes alike, w = 0.5 or an end; the
// fused variance is never below the better input's times the weight and the position lies
// between the inputs.
TEST_CASE("track_fusion: node CI lies between its inputs") {
  test::Collector out;
  auto n = node("{q: 0 m2/s3}", out);
  n->on_estimate(cv_estimate(0.0, 0.0, 1.0), 0);
  n->on_estimate(cv_estimate(0.0, 10.0, 4.0), 1);
  REQUIRE(out.estimates.size() == 2);
  const Estimate& f = out.estimates[1];
  CHECK(f.initialised);
  CHECK(f.enu(0) >= 0.0);
  CHECK(f.enu(0) < 10.0);
  CHECK(f.enu_covariance(0, 0) <= 1.0 + 1e-12);
}

TEST_CASE("track_fusion: node refuses another state size") {
  test::Collector out;
  auto n = node("{motion: constant_acceleration}", out);
  CHECK_THROWS_AS(n->on_estimate(cv_estimate(0.0, 0.0, 1.0), 0), DataError);
}

// The motion block is the Cartesian filters' own (lib/estimation): the same checks of its
// combination, each naming its parameter.
TEST_CASE("track_fusion: shared motion block checks") {
  const auto refused = [](const std::string& yaml, const std::string& param) {
    try {
      test::make("filter.track_fusion", yaml);
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      return what.find(param) != std::string::npos;
    }
    return false;
  };
  CHECK(refused("{motion: constant_velocity, q_jerk: 1 m2/s5}", "q_jerk"));
  CHECK(refused("{motion: singer, singer_alpha: 1 1/s}", "singer_sigma"));
  CHECK(refused("{q: 1 m2/s3, sigma_accel: 1 m/s2}", "sigma_accel"));
  CHECK_NOTHROW(test::make("filter.track_fusion", "{motion: singer, singer_alpha: 1 1/s, singer_sigma: 5 m/s2}"));
}
