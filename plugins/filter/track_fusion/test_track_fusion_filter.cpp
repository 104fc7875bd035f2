// Purpose: tests of filter.track_fusion as a node: information fusion of two local tracks equals the hand-computed sum of their information, CI publishes a fused estimate, a mismatched state size is refused, the shared motion block's checks, the inputs' transition model taken or a different one refused.
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

// The motion block is the SDK's transition-model block (transition_model.hpp), as every filter
// declares it: the same checks of its combination, each naming its parameter.
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

namespace {

InputInfo filter_input(const std::string& id, const TransitionModel& t) {
  InputInfo in{id, "filter.ekf", mask(ItemKind::Estimate), {}};
  in.transition = t;
  return in;
}

TransitionModel constant_acceleration(double q_jerk) {
  TransitionModel t;
  t.motion = TransitionModel::Motion::ConstantAcceleration;
  t.intensity = q_jerk;
  return t;
}

std::string refusal(Component& n, const std::vector<InputInfo>& inputs) {
  try {
    n.set_inputs(inputs);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// Without motion parameters the node predicts with its inputs' model: a 9-state CA model from
// the inputs makes it take 9-state estimates and refuse 6-state ones.
TEST_CASE("track_fusion: takes the inputs' transition model") {
  test::Collector out;
  auto n = test::make("filter.track_fusion", "{method: information}");
  n->set_inputs({filter_input("a", constant_acceleration(2.0)), filter_input("b", constant_acceleration(2.0))});
  out.attach_to(*n);
  testing::start_run(*n);
  Estimate e = cv_estimate(0.0, 0.0, 1.0);
  CHECK_THROWS_AS(n->on_estimate(e, 0), DataError);
  e.state = StateVec::Zero(9);
  e.covariance = StateCov::Identity(9, 9);
  n->on_estimate(e, 0);
  REQUIRE(out.estimates.size() == 1);
  CHECK(out.estimates[0].initialised);
  CHECK(out.estimates[0].state.size() == 9);
}

// Inputs that predict differently, or a node model other than its inputs', are refused before
// the run, naming both; with no model anywhere the node asks for one.
TEST_CASE("track_fusion: refuses models that differ") {
  auto inherit = test::make("filter.track_fusion", "{}");
  const std::string two = refusal(*inherit, {filter_input("a", constant_acceleration(1.0)), filter_input("b", constant_acceleration(3.0))});
  CHECK(two.find("input 'b'") != std::string::npos);
  CHECK(two.find("q_jerk 3 m2/s5") != std::string::npos);
  CHECK(two.find("input 'a' with constant_acceleration, q_jerk 1 m2/s5") != std::string::npos);

  auto given = test::make("filter.track_fusion", "{q: 5 m2/s3}");
  const std::string own = refusal(*given, {filter_input("a", constant_acceleration(1.0))});
  CHECK(own.find("this node's parameters give constant_velocity, q 5 m2/s3") != std::string::npos);
  CHECK(own.find("leave the motion parameters out") != std::string::npos);

  auto none = test::make("filter.track_fusion", "{}");
  const std::string missing = refusal(*none, {{"a", "filter.x", mask(ItemKind::Estimate), {}}});
  CHECK(missing.find("no input names its transition model") != std::string::npos);

  auto same = test::make("filter.track_fusion", "{motion: constant_acceleration, q_jerk: 1 m2/s5}");
  CHECK(refusal(*same, {filter_input("a", constant_acceleration(1.0)), filter_input("b", constant_acceleration(1.0))}).empty());
}
