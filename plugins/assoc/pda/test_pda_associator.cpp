// Purpose: tests of assoc.pda: its probabilities are the PDA's closed form (Bar-Shalom & Tse) per track, inside the chi-square gate, and survive likelihoods far below the double range; through tracker.multi two targets in clutter keep their tracks with combined updates; estimators and adapters that cannot take a combined update are refused before the run.
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <trackflow/chi_square.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/tracker.hpp>
#include <trackflow/tracks.hpp>

#include <cmath>
#include <numbers>
#include <vector>

using namespace trackflow;

namespace {

double gaussian(const Vec3& nu, const MeasCov& S) {
  const Eigen::Matrix3d s = S.topLeftCorner<3, 3>();
  return std::exp(-0.5 * nu.dot(s.inverse() * nu)) / std::sqrt(std::pow(2 * std::numbers::pi, 3) * s.determinant());
}

struct SetCollector : Component {
  std::vector<std::vector<TrackEstimate>> sets;
  Link link{this, 0, 0xFF};
  void on_tracks(const TrackSet& s, int) override { sets.emplace_back(s.tracks.begin(), s.tracks.end()); }
};

}  // namespace

TEST_CASE("the PDA's closed form per track inside the gate") {
  auto a = test::make_part<Associator>("assoc.pda", "{ gate_probability: 0.99 }");
  REQUIRE(a->probabilistic());
  Rng rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<PredictedMeasurement> pred(3);
    std::vector<TrackView> tracks(3);
    for (int i = 0; i < 3; ++i) {
      pred[i].z = Vec3(30 * i + 5 * rng.normal(), 5 * rng.normal(), 0.0);
      pred[i].S = MeasCov::Zero(3, 3);
      for (int k = 0; k < 3; ++k) pred[i].S(k, k) = std::pow(2 + 4 * rng.uniform(), 2);
      set_log_det(pred[i]);
      tracks[i].id = static_cast<std::uint64_t>(i + 1);
      tracks[i].predicted = &pred[i];
    }
    std::vector<Detection> det(8);
    for (Detection& d : det) {
      d.value = Vec3(90 * rng.uniform() - 10, 30 * rng.uniform() - 15, 6 * rng.uniform() - 3);
      d.covariance = MeasCov::Identity(3, 3);
    }
    Scan scan;
    scan.sensor.frame = Frame::Cartesian;
    scan.detections = det;
    scan.detection_probability = 0.8;
    scan.clutter_density = 1e-5;
    AssociationProbabilities out;
    out.clear(3);
    a->associate_probabilities(tracks, scan, out);
    const double gamma = chi_square_quantile(3, 0.99), w0 = 1 - 0.8 * 0.99;
    for (int i = 0; i < 3; ++i) {
      std::vector<double> l(det.size(), 0.0);
      double sum = w0;
      for (size_t j = 0; j < det.size(); ++j) {
        const Vec3 nu = det[j].value.head<3>() - pred[i].z.head<3>();
        const Eigen::Matrix3d s = pred[i].S.topLeftCorner<3, 3>();
        if (nu.dot(s.inverse() * nu) > gamma) continue;
        l[j] = 0.8 * gaussian(nu, pred[i].S) / 1e-5;
        sum += l[j];
      }
      std::vector<double> got(det.size(), 0.0);
      for (const auto& e : out.of(i)) got[static_cast<size_t>(e.detection)] = e.probability;
      for (size_t j = 0; j < det.size(); ++j) CHECK(got[j] == Approx(l[j] / sum).epsilon(1e-10).margin(1e-15));
      CHECK(out.none(i) == Approx(w0 / sum).epsilon(1e-10));
    }
  }
}

TEST_CASE("likelihoods below the double range") {
  // S = 1e206 I: N(nu; 0, S) ~ 1e-310, a denormal with a few digits left; over lambda = 1e-305
  // the ratio is ~6e-6. Formed in the log domain, the probabilities keep their full precision.
  auto a = test::make_part<Associator>("assoc.pda", "{ gate_probability: 0.99, detection_probability: 0.9 }");
  PredictedMeasurement p;
  p.z = Vec3::Zero();
  p.S = MeasCov::Identity(3, 3) * 1e206;
  set_log_det(p);
  TrackView v;
  v.predicted = &p;
  std::vector<Detection> det(2);
  det[0].value = Vec3(1, 0, 0);
  det[1].value = Vec3(-1, 0, 0);
  for (Detection& d : det) d.covariance = MeasCov::Identity(3, 3);
  Scan scan;
  scan.sensor.frame = Frame::Cartesian;
  scan.detections = det;
  scan.clutter_density = 1e-305;
  AssociationProbabilities out;
  out.clear(1);
  a->associate_probabilities(std::span<const TrackView>(&v, 1), scan, out);
  REQUIRE(out.of(0).size() == 2);
  const double log_l = std::log(0.9) + 305 * std::log(10.0) - 0.5 * (3 * std::log(2 * std::numbers::pi) + 618 * std::log(10.0));
  const double l = std::exp(log_l), w0 = 1 - 0.9 * 0.99;
  CHECK(l > 1e-7);
  CHECK(out.of(0)[0].probability == Approx(l / (w0 + 2 * l)).epsilon(1e-9));
  CHECK(out.of(0)[1].probability == Approx(l / (w0 + 2 * l)).epsilon(1e-9));
  CHECK(out.none(0) == Approx(w0 / (w0 + 2 * l)).epsilon(1e-9));
}

TEST_CASE("tracker.multi: two targets in clutter keep their tracks") {
  auto n = test::make("tracker.multi",
                      "{ estimator: { type: filter.kalman, q: 0.1 m2/s3 }, associator: { type: assoc.pda }, "
                      "initiator: { type: init.m_of_n, m: 3, n: 4, max_speed: 50 m/s }, "
                      "deleter: { type: delete.misses, max_misses: 3 } }");
  SetCollector out;
  n->out.connect(&out.link, 1);
  test::start_run(*n);
  Rng rng(5);
  std::vector<Detection> det;
  for (int k = 0; k < 25; ++k) {
    const double t = k;
    det.clear();
    const Vec3 p1(0.0, -100.0 + 10.0 * t, 0.0), p2(200.0, 100.0 - 10.0 * t, 0.0);
    for (const auto& [p, origin] : {std::pair{p1, 1u}, std::pair{p2, 2u}}) {
      Detection d;
      d.value = p + 2.0 * Vec3(rng.normal(), rng.normal(), rng.normal());
      d.covariance = MeasCov::Identity(3, 3) * 4.0;
      d.origin = origin;
      det.push_back(d);
    }
    for (int c = 0; c < 5; ++c) {
      Detection d;
      d.value = Vec3(1000 * rng.uniform() - 500, 1000 * rng.uniform() - 500, 1000 * rng.uniform() - 500);
      d.covariance = MeasCov::Identity(3, 3) * 4.0;
      d.origin = kOriginClutter;
      det.push_back(d);
    }
    Scan s;
    s.time = t;
    s.sensor.frame = Frame::Cartesian;
    s.detections = det;
    s.detection_probability = 0.99;
    s.clutter_density = 5e-9;
    n->on_scan(s, 0);
  }
  REQUIRE(out.sets.size() == 25);
  for (size_t k = 5; k < out.sets.size(); ++k) {
    int confirmed = 0;
    for (const TrackEstimate& tr : out.sets[k]) {
      if (tr.status != TrackStatus::Confirmed && tr.status != TrackStatus::Coasting) continue;
      ++confirmed;
      const double t = static_cast<double>(k);
      const Vec3 p = tr.estimate.target == 1 ? Vec3(0.0, -100.0 + 10.0 * t, 0.0) : Vec3(200.0, 100.0 - 10.0 * t, 0.0);
      CHECK((tr.estimate.enu.head<3>() - p).norm() < 8.0);
      CHECK(tr.estimate.updated);  // a combined update every look
    }
    CHECK(confirmed == 2);
  }
}

TEST_CASE("estimators and adapters without combined updates refused") {
  try {
    test::make("tracker.multi",
               "{ estimator: { type: filter.decoupled },\n"
               "  associator: { type: assoc.pda }, initiator: { type: init.m_of_n, max_speed: 1 m/s },\n"
               "  deleter: { type: delete.misses } }");
    FAIL("filter.decoupled under assoc.pda was accepted");
  } catch (const ConfigError& e) {
    INFO(e.what());
    CHECK(std::string(e.what()).find("update_weighted") != std::string::npos);
    CHECK(e.where().line == 1);
  }
  try {
    test::make("tracker.multi",
               "{ estimator: { type: filter.kalman },\n"
               "  adapters: [ { type: adapt.innovation_r } ],\n"
               "  associator: { type: assoc.pda }, initiator: { type: init.m_of_n, max_speed: 1 m/s },\n"
               "  deleter: { type: delete.misses } }");
    FAIL("adapters under assoc.pda were accepted");
  } catch (const ConfigError& e) {
    INFO(e.what());
    CHECK(std::string(e.what()).find("adapters") != std::string::npos);
    CHECK(e.where().line == 2);
  }
}
