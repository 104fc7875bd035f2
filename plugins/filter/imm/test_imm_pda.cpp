// Purpose: tests of filter.imm under probabilistic data association (IMM-PDA, imm_pda.hpp), both forms: two identical modes are the single-mode PDA of filter.ekf, the mode probabilities are w_j0 + sum_k w_jk, component EKF modes equal the record form, and under tracker.multi with assoc.pda a manoeuvring target in clutter keeps its track.
#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/tracker.hpp>
#include <trackflow/tracks.hpp>

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

// What an estimator reports: its innovation onto e, its annotations (the mode probabilities).
struct Track final : TrackContext {
  void warn(const std::string& w) override { warnings.push_back(w); }
  void count(int) override {}
  void annotate(int i, double v) override {
    if (i >= static_cast<int>(annotations.size())) annotations.resize(static_cast<size_t>(i) + 1);
    annotations[static_cast<size_t>(i)] = v;
  }
  Estimate e;
  std::vector<std::string> warnings;
  std::vector<double> annotations;
};

// 200 m/s along x from (-5000, 20000, 3000) m, 30 m/s2 along x from t = 20 s to t = 30 s.
Vec3 truth(double t) {
  const Vec3 p0(-5000.0, 20000.0, 3000.0), v0(200.0, 0.0, 0.0), a(30.0, 0.0, 0.0);
  if (t < 20.0) return p0 + v0 * t;
  const double s = std::min(t, 30.0) - 20.0;
  const Vec3 p = p0 + v0 * t + 0.5 * a * s * s;
  return t <= 30.0 ? p : Vec3(p + a * s * (t - 30.0));
}

// A radar at the origin: [r, az (north-clockwise), el], sigma 10 m, 1 mrad, 1 mrad.
const Vec3 kSigma(10.0, 1e-3, 1e-3);

Measurement spherical(const Vec3& p, double t, Rng* rng) {
  Measurement m;
  m.time = t;
  m.frame = Frame::Spherical;
  const double r = p.norm();
  Vec3 z(r, std::atan2(p.x(), p.y()), std::asin(p.z() / r));
  if (rng)
    for (int a = 0; a < 3; ++a) z(a) += kSigma(a) * rng->normal();
  z(1) = wrap_angle(z(1));
  m.value = z;
  m.covariance = Vec3(kSigma.array().square()).asDiagonal();
  return m;
}

// Three candidates around the target's measurement: it, and two a few sigma off.
std::vector<Measurement> candidates(const Measurement& m) {
  std::vector<Measurement> c(3, m);
  c[1].value += Vec3(3.0 * kSigma(0), -2.0 * kSigma(1), 1.0 * kSigma(2));
  c[2].value += Vec3(-2.0 * kSigma(0), 2.5 * kSigma(1), -1.5 * kSigma(2));
  return c;
}

void bind(Estimator& e, Track& t) {
  e.bind(t);
  t.estimate = &t.e;
}

// Runs hard updates with the target's measurements from t0 (step T) until `until`, initiating first.
void run_hard(Estimator& e, Track& t, Rng& rng, double t0, double until, double T) {
  bool formed = e.reset();
  double last = t0;
  for (double time = t0; time < until - 1e-9; time += T) {
    const Measurement m = spherical(truth(time), time, &rng);
    t.time = time;
    e.measurement_noise() = m.covariance;
    if (!formed) {
      formed = e.initiate(m, 3);
      last = time;
      continue;
    }
    e.predict(time - last);
    last = time;
    REQUIRE(e.update(m, 3));
  }
  REQUIRE(formed);
}

const std::string kTwoCvRecords =
    "{ modes: [{ name: a, motion: constant_velocity, q: 1 m2/s3 }, { name: b, motion: constant_velocity, q: 1 m2/s3 }], "
    "transition: [0.9, 0.1, 0.2, 0.8], initial_probabilities: [0.3, 0.7] }";
const std::string kTwoCvComponents =
    "{ modes: [{ type: filter.ekf, motion: constant_velocity, q: 1 m2/s3 }, { type: filter.ekf, motion: "
    "constant_velocity, q: 1 m2/s3 }], transition: [0.9, 0.1, 0.2, 0.8], initial_probabilities: [0.3, 0.7] }";
const std::string kCvCaRecords =
    "{ modes: [{ motion: constant_velocity, q: 1 m2/s3 }, { motion: constant_acceleration, q_jerk: 100 m2/s5 }], "
    "transition: [0.8, 0.2, 0.3, 0.7] }";
const std::string kCvCaComponents =
    "{ modes: [{ type: filter.ekf, motion: constant_velocity, q: 1 m2/s3 }, { type: filter.ukf, motion: "
    "constant_acceleration, q_jerk: 100 m2/s5 }], transition: [0.8, 0.2, 0.3, 0.7] }";

}  // namespace

// Two identical modes: every candidate is equally likely under both, so w_jk = beta_k c_j and each
// mode runs the single-model PDA with the same weights; the combination of two equal Gaussians is
// that Gaussian. The IMM-PDA must then be filter.ekf's combined update, step by step.
TEST_CASE("IMM-PDA with two identical modes is the single-mode PDA") {
  for (const std::string& params : {kTwoCvRecords, kTwoCvComponents}) {
    INFO(params);
    auto imm = test::fixture().make_estimator("filter.imm", params);
    auto ekf = test::fixture().make_estimator("filter.ekf", "{ motion: constant_velocity, q: 1 m2/s3 }");
    REQUIRE(imm->takes_weighted_updates());
    Track ti, te;
    bind(*imm, ti);
    bind(*ekf, te);
    Rng rng(21);
    imm->reset();
    ekf->reset();
    double last = 0.0;
    int compared = 0;
    bool formed = false;
    for (int k = 0; k < 60; ++k) {
      const double t = 0.5 * k;
      const Measurement m = spherical(truth(t), t, &rng);
      ti.time = te.time = t;
      imm->measurement_noise() = ekf->measurement_noise() = m.covariance;
      if (!formed) {
        const bool a = imm->initiate(m, 3), b = ekf->initiate(m, 3);
        REQUIRE(a == b);
        formed = a;
        last = t;
        continue;
      }
      imm->predict(t - last);
      ekf->predict(t - last);
      last = t;
      const std::vector<Measurement> c = candidates(m);
      const std::vector<double> p = k % 2 ? std::vector<double>{0.55, 0.25, 0.1} : std::vector<double>{0.2, 0.1, 0.05};
      const double none = k % 2 ? 0.1 : 0.65;
      REQUIRE(imm->update_weighted(c, p, none, 3));
      REQUIRE(ekf->update_weighted(c, p, none, 3));
      Estimate a, b;
      imm->fill(a);
      ekf->fill(b);
      REQUIRE(a.state.size() == 6);
      REQUIRE(b.state.size() == 6);
      for (int i = 0; i < 6; ++i) {
        CHECK(a.state(i) == Approx(b.state(i)).epsilon(1e-9).margin(1e-9));
        for (int j = 0; j < 6; ++j) CHECK(a.covariance(i, j) == Approx(b.covariance(i, j)).epsilon(1e-9).margin(1e-9));
      }
      CHECK(ti.e.nis == Approx(te.e.nis).epsilon(1e-9));
      for (int i = 0; i < 3; ++i) CHECK(ti.e.innovation(i) == Approx(te.e.innovation(i)).epsilon(1e-9).margin(1e-12));
      // The modes' probabilities follow the Markov chain alone: mu = Pi' mu_prev (no likelihood
      // tells them apart). From [0.3, 0.7]: the stationary [2/3, 1/3] is approached.
      REQUIRE(ti.annotations.size() == 2);
      CHECK(ti.annotations[0] + ti.annotations[1] == Approx(1.0).epsilon(1e-14));
      ++compared;
    }
    CHECK(compared > 50);
    CHECK(ti.annotations[0] == Approx(2.0 / 3.0).epsilon(1e-6));
  }
}

// mu_j = w_j0 + sum_k w_jk = beta_0 c_j + sum_k beta_k q_jk, with c = Pi' mu_prev and q_jk the
// IMM's own posterior mode probabilities for candidate k alone (c_j g_jk / sum_i c_i g_ik: a
// clone updated with z_k). The case is one where using the last mu for c, or equal weights per
// candidate, would be visibly wrong.
TEST_CASE("IMM-PDA mode probabilities: beta_0 c_j + sum_k beta_k q_jk") {
  const double pi[2][2] = {{0.8, 0.2}, {0.3, 0.7}};
  for (const std::string& params : {kCvCaRecords, kCvCaComponents}) {
    INFO(params);
    auto imm = test::fixture().make_estimator("filter.imm", params);
    Track t;
    bind(*imm, t);
    Rng rng(4);
    run_hard(*imm, t, rng, 10.0, 22.0, 0.5);  // into the manoeuvre: the modes disagree
    REQUIRE(t.annotations.size() == 2);
    const std::vector<double> mu_prev = t.annotations;
    const double time = 22.0;
    t.time = time;
    imm->predict(0.5);
    double c[2];
    for (int j = 0; j < 2; ++j) c[j] = pi[0][j] * mu_prev[0] + pi[1][j] * mu_prev[1];
    const Measurement m = spherical(truth(time), time, &rng);
    const std::vector<Measurement> cand = candidates(m);
    const std::vector<double> beta = {0.5, 0.25, 0.1};
    const double beta0 = 0.15;
    // q_jk from clones, one candidate each.
    std::vector<std::vector<double>> q;
    for (const Measurement& z : cand) {
      auto one = imm->clone();
      Track tk;
      tk.time = time;
      bind(*one, tk);
      one->measurement_noise() = z.covariance;
      REQUIRE(one->update(z, 3));
      REQUIRE(tk.annotations.size() == 2);
      q.push_back(tk.annotations);
    }
    // The limit of a vanishing candidate: the predicted mode probabilities c themselves.
    {
      auto limit = imm->clone();
      Track tl;
      tl.time = time;
      bind(*limit, tl);
      REQUIRE(limit->update_weighted(std::vector<Measurement>{cand[0]}, std::vector<double>{1e-200}, 1.0, 3));
      for (int j = 0; j < 2; ++j) CHECK(tl.annotations[static_cast<size_t>(j)] == Approx(c[j]).epsilon(1e-12));
    }
    imm->measurement_noise() = m.covariance;
    REQUIRE(imm->update_weighted(cand, beta, beta0, 3));
    double sum = 0.0;
    for (int j = 0; j < 2; ++j) {
      double expected = beta0 * c[j];
      for (size_t k = 0; k < cand.size(); ++k) expected += beta[k] * q[k][static_cast<size_t>(j)];
      CHECK(t.annotations[static_cast<size_t>(j)] == Approx(expected).epsilon(1e-10));
      sum += t.annotations[static_cast<size_t>(j)];
      // The case discriminates: c is not the last mu, and the candidates' q differ.
      CHECK(std::fabs(beta0 * (c[j] - mu_prev[static_cast<size_t>(j)])) > 1e-3);
      CHECK(std::fabs(q[0][static_cast<size_t>(j)] - q[1][static_cast<size_t>(j)]) > 1e-3);
    }
    CHECK(sum == Approx(1.0).epsilon(1e-14));
  }
}

// The two forms run the same IMM-PDA: EKF modes given as components equal the record form's
// (the component form's likelihoods come from each mode's predict_measurement, the record form's
// from its EKF update: the same z^ and S to rounding).
TEST_CASE("IMM-PDA: component EKF modes equal the record form") {
  const std::string transition = ", transition: [0.8, 0.2, 0.3, 0.7] }";
  auto rec = test::fixture().make_estimator(
      "filter.imm", "{ modes: [{ motion: constant_velocity, q: 1 m2/s3 }, { motion: constant_acceleration, q_jerk: 100 m2/s5 }]" +
                        transition);
  auto cmp = test::fixture().make_estimator("filter.imm",
                                            "{ modes: [{ type: filter.ekf, motion: constant_velocity, q: 1 m2/s3 }, { type: "
                                            "filter.ekf, motion: constant_acceleration, q_jerk: 100 m2/s5 }]" + transition);
  Track tr, tc;
  bind(*rec, tr);
  bind(*cmp, tc);
  Rng rng(8);
  rec->reset();
  cmp->reset();
  bool formed = false;
  double last = 0.0;
  int compared = 0;
  double most_ca = 0.0;
  for (int k = 0; k < 70; ++k) {
    const double t = 0.5 * k;
    const Measurement m = spherical(truth(t), t, &rng);
    tr.time = tc.time = t;
    rec->measurement_noise() = cmp->measurement_noise() = m.covariance;
    if (!formed) {
      const bool a = rec->initiate(m, 3), b = cmp->initiate(m, 3);
      REQUIRE(a == b);
      formed = a;
      last = t;
      continue;
    }
    rec->predict(t - last);
    cmp->predict(t - last);
    last = t;
    const std::vector<Measurement> c = candidates(m);
    const std::vector<double> p = {0.5, 0.2, 0.1};
    REQUIRE(rec->update_weighted(c, p, 0.2, 3));
    REQUIRE(cmp->update_weighted(c, p, 0.2, 3));
    Estimate x, y;
    rec->fill(x);
    cmp->fill(y);
    REQUIRE(x.state.size() == 9);
    REQUIRE(y.state.size() == 9);
    for (int i = 0; i < 9; ++i) {
      CHECK(y.state(i) == Approx(x.state(i)).epsilon(1e-9).margin(1e-9));
      for (int j = 0; j < 9; ++j) CHECK(y.covariance(i, j) == Approx(x.covariance(i, j)).epsilon(1e-9).margin(1e-9));
    }
    CHECK(tc.annotations[1] == Approx(tr.annotations[1]).margin(1e-10));
    CHECK(tc.e.nis == Approx(tr.e.nis).epsilon(1e-9));
    most_ca = std::max(most_ca, tr.annotations[1]);
    ++compared;
  }
  CHECK(compared > 60);
  CHECK(most_ca > 0.5);  // in the manoeuvre the CA mode leads: the modes differ
}

namespace {

struct SetCollector : Component {
  std::vector<std::vector<TrackEstimate>> sets;
  Link link{this, 0, 0xFF};
  void on_tracks(const TrackSet& s, int) override { sets.emplace_back(s.tracks.begin(), s.tracks.end()); }
};

}  // namespace

// tracker.multi with filter.imm (an EKF CV and a UKF CA mode, or the record form's EKF modes) and
// assoc.pda: spherical scans every 0.5 s of the target above (level, then 30 m/s2 for 10 s, then
// level at 500 m/s), P_D 0.9, 60 clutter plots per scan in a 1 km x 0.05 rad x 0.05 rad box around
// it (24 plots per m rad2; the box moves with the target, so clutter tracks are confirmed too and
// stay near it). The track nearest the target at the end was confirmed within 6 s and followed it
// throughout: measured rms 26.7 m (24.7 m in the manoeuvre), worst 94 m, both forms.
TEST_CASE("IMM-PDA under tracker.multi keeps a manoeuvring target") {
  const std::string transition = "transition: [0.95, 0.05, 0.05, 0.95]";
  for (const std::string& estimator :
       {"{ type: filter.imm, modes: [{ type: filter.ekf, motion: constant_velocity, q: 1 m2/s3 }, { type: filter.ukf, "
        "motion: constant_acceleration, q_jerk: 100 m2/s5 }], " + transition + " }",
        "{ type: filter.imm, modes: [{ motion: constant_velocity, q: 1 m2/s3 }, { motion: constant_acceleration, q_jerk: "
        "100 m2/s5 }], " + transition + " }"}) {
    INFO(estimator);
    auto n = test::make("tracker.multi", "{ estimator: " + estimator +
                                             ", associator: { type: assoc.pda }, "
                                             "initiator: { type: init.m_of_n, m: 3, n: 4, max_speed: 400 m/s }, "
                                             "deleter: { type: delete.misses, max_misses: 3 } }");
    SetCollector out;
    n->out.connect(&out.link, 1);
    test::start_run(*n);
    Rng rng(9);
    const double T = 0.5, box_r = 1000.0, box_angle = 0.05;
    const int clutter = 60;
    std::vector<Detection> det;
    std::vector<Vec3> truths;
    for (int k = 0; k < 80; ++k) {
      const double t = T * k;
      const Vec3 p = truth(t);
      truths.push_back(p);
      det.clear();
      const Measurement target = spherical(p, t, &rng);
      if (k < 2 || rng.uniform() < 0.9) {  // the first two always: a track to keep
        Detection d = target;
        d.origin = 1;
        det.push_back(d);
      }
      const Measurement centre = spherical(p, t, nullptr);
      for (int c = 0; c < clutter; ++c) {
        Detection d;
        d.value = Vec3(centre.value(0) + box_r * (rng.uniform() - 0.5), wrap_angle(centre.value(1) + box_angle * (rng.uniform() - 0.5)),
                       centre.value(2) + box_angle * (rng.uniform() - 0.5));
        d.covariance = target.covariance;
        d.origin = kOriginClutter;
        det.push_back(d);
      }
      Scan s;
      s.time = t;
      s.sensor.frame = Frame::Spherical;
      s.detections = det;
      s.detection_probability = 0.9;
      s.clutter_density = clutter / (box_r * box_angle * box_angle);
      n->on_scan(s, 0);
    }
    REQUIRE(out.sets.size() == 80);
    double se = 0.0, worst = 0.0, se_turn = 0.0;
    int n_err = 0, n_turn = 0, updated = 0;
    // The target's track: the confirmed track nearest the target at the last scan (whatever
    // detections started it), followed back to its confirmation.
    auto confirmed = [](const TrackEstimate& tr) {
      return tr.status == TrackStatus::Confirmed || tr.status == TrackStatus::Coasting;
    };
    std::uint64_t kept = 0;
    double nearest = 1e300;
    for (const TrackEstimate& tr : out.sets.back())
      if (confirmed(tr) && (tr.estimate.enu.head<3>() - truths.back()).norm() < nearest) {
        nearest = (tr.estimate.enu.head<3>() - truths.back()).norm();
        kept = tr.id;
      }
    REQUIRE(kept != 0);
    auto target_track = [&](size_t k) -> const TrackEstimate* {
      for (const TrackEstimate& tr : out.sets[k])
        if (tr.id == kept && confirmed(tr)) return &tr;
      return nullptr;
    };

    size_t first = 0;
    while (first < out.sets.size() && !target_track(first)) ++first;
    CHECK(first <= 12);  // confirmed within 6 s
    for (size_t k = first; k < out.sets.size(); ++k) {
      const TrackEstimate* mine = target_track(k);
      INFO("scan " << k);
      REQUIRE(mine);  // confirmed (or coasting) from its confirmation to the end: never lost
      const double err = (mine->estimate.enu.head<3>() - truths[k]).norm();
      se += err * err;
      worst = std::max(worst, err);
      ++n_err;
      const double t = T * static_cast<double>(k);
      if (t >= 20.0 && t <= 30.0) {
        se_turn += err * err;
        ++n_turn;
      }
      updated += mine->estimate.updated;  // a combined update: some candidate in its gate
    }
    const double rms = std::sqrt(se / n_err);
    const double rms_turn = std::sqrt(se_turn / n_turn);
    INFO("position error: rms " << rms << " m, in the manoeuvre " << rms_turn << " m, worst " << worst << " m; updated in " << updated << " of " << n_err << " scans");
    // One measurement's cross-range error at ~20 km is ~20 m per angle.
    CHECK(rms < 45.0);
    CHECK(rms_turn < 60.0);
    CHECK(worst < 150.0);
    CHECK(updated > 0.8 * n_err);
  }
}

// Through a coast (predictions without updates) the mode probabilities follow the Markov chain
// (issue 25): two identical CV modes, Pi = [[0.9, 0.1], [0.1, 0.9]], mu0 = [1, 0] after the start,
// give p_a = 0.5 + 0.5 * 0.8^k after k predictions — the mode probabilities published with each
// predicted estimate, and the ones the next update starts from.
TEST_CASE("a coast moves the mode probabilities along the chain") {
  const std::string records =
      "{ modes: [{ name: a, motion: constant_velocity, q: 1 m2/s3 }, { name: b, motion: constant_velocity, q: 1 m2/s3 }], "
      "transition: [0.9, 0.1, 0.1, 0.9], initial_probabilities: [1, 0] }";
  const std::string components =
      "{ modes: [{ type: filter.ekf, motion: constant_velocity, q: 1 m2/s3 }, { type: filter.ekf, motion: "
      "constant_velocity, q: 1 m2/s3 }], transition: [0.9, 0.1, 0.1, 0.9], initial_probabilities: [1, 0] }";
  for (const std::string& params : {records, components}) {
    INFO(params);
    auto imm = test::fixture().make_estimator("filter.imm", params);
    Track t;
    bind(*imm, t);
    Rng rng(2);
    REQUIRE_FALSE(imm->reset());
    for (int k = 0; k < 2; ++k) {  // the two-point start: mu stays mu0 = [1, 0]
      const Measurement m = spherical(truth(k), k, &rng);
      t.time = k;
      imm->measurement_noise() = m.covariance;
      (void)imm->initiate(m, 3);
    }
    REQUIRE(t.annotations.size() == 2);
    CHECK(t.annotations[0] == Approx(1.0));
    for (int k = 1; k <= 10; ++k) {
      t.time = 1 + k;
      imm->predict(1.0);
      INFO("k = " << k);
      CHECK(t.annotations[0] == Approx(0.5 + 0.5 * std::pow(0.8, k)).epsilon(1e-12));
      CHECK(t.annotations[0] + t.annotations[1] == Approx(1.0).epsilon(1e-14));
    }
    // Then an update starts from the chain's c: two identical modes have equal likelihoods, so the
    // posterior is the prediction's c = Pi' mu = [0.5 + 0.5 * 0.8^11, ...].
    const Measurement m = spherical(truth(12), 12, &rng);
    t.time = 12;
    imm->predict(1.0);
    imm->measurement_noise() = m.covariance;
    REQUIRE(imm->update(m, 3));
    CHECK(t.annotations[0] == Approx(0.5 + 0.5 * std::pow(0.8, 11)).epsilon(1e-9));
  }
}
