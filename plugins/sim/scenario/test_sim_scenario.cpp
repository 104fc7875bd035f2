// Purpose: tests of sim.scenario: item order, ids, detection probability, a scripted target's noise_factor, clutter, births and survival, determinism, parameter refusals.
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <trackflow/error.hpp>

#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

struct Event {
  bool scan = false;
  double time = 0.0;
  std::uint32_t target = 0;  // truth
  Vec3 position = Vec3::Zero();
  std::vector<Detection> detections;  // scan
  double clutter_density = 0.0, pd = 0.0;
  SurveillanceRegion region;
  Frame frame = Frame::Cartesian;
};

class Recorder final : public Component {
 public:
  void on_truth(const Truth& t, int) override {
    Event e;
    e.time = t.time;
    e.target = t.target;
    e.position = t.position;
    events.push_back(e);
  }
  void on_scan(const Scan& s, int) override {
    Event e;
    e.scan = true;
    e.time = s.time;
    e.detections.assign(s.detections.begin(), s.detections.end());
    e.clutter_density = s.clutter_density;
    e.pd = s.detection_probability;
    e.region = s.region;
    e.frame = s.sensor.frame;
    events.push_back(e);
  }
  std::vector<Event> events;
};

std::vector<Event> simulate(const std::string& yaml, std::uint64_t seed = 1) {
  auto gen = test::make("sim.scenario", yaml);
  Recorder rec;
  Link link{&rec, 0, 0xFF};
  gen->out.connect(&link, 1);
  test::drain(*gen, seed);
  return rec.events;
}

std::string refusal(const std::string& yaml) {
  try {
    (void)test::make("sim.scenario", yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return {};
}

const char* kTwo = R"(
  period: 1 s
  duration: 20 s
  region_lo: [-1000 m, -1000 m, -100 m]
  region_hi: [1000 m, 1000 m, 100 m]
  measurement_sigma: 2 m
  targets:
    - {initial_position: [-500, 0, 0], initial_velocity: [50, 0, 0]}
    - {initial_position: [0, -500, 0], initial_velocity: [0, 50, 0], birth_time: 3 s, death_time: 15 s}
)";

}  // namespace

// every truth of a time comes before the one scan of that time; truths in id order
TEST_CASE("truths precede their scan") {
  const auto ev = simulate(std::string(kTwo) + "  clutter_rate: 5\n  detection_probability: 0.8\n");
  REQUIRE(!ev.empty());
  double last_scan = -1e9;
  std::vector<std::uint32_t> ids;
  int scans = 0;
  for (const Event& e : ev) {
    if (e.scan) {
      ++scans;
      CHECK(e.time > last_scan);
      last_scan = e.time;
      ids.clear();
    } else {
      CHECK(e.time > last_scan);  // a truth of a later time than the previous scan
      if (!ids.empty()) CHECK(e.target > ids.back());
      ids.push_back(e.target);
    }
  }
  CHECK(scans == 21);
  CHECK(ev.back().scan);
}

// scripted ids 0..n-1 are stable; target 1 lives from 3 s to 14 s
TEST_CASE("ids unique and stable") {
  const auto ev = simulate(kTwo);
  std::map<std::uint32_t, std::vector<double>> times;
  for (const Event& e : ev)
    if (!e.scan) times[e.target].push_back(e.time);
  REQUIRE(times.size() == 2);
  CHECK(times[0].size() == 21);
  REQUIRE(times[1].size() == 12);
  CHECK(times[1].front() == Approx(3.0));
  CHECK(times[1].back() == Approx(14.0));
  for (const Event& e : ev)
    if (!e.scan && e.target == 0) CHECK(e.position.x() == Approx(-500 + 50 * e.time));
}

// P_D = 1, no clutter: one detection per living target, with its id as origin, near its truth
TEST_CASE("P_D 1 detects every target once") {
  const auto ev = simulate(kTwo);
  std::map<std::uint32_t, Vec3> truth;
  for (const Event& e : ev) {
    if (!e.scan) {
      truth[e.target] = e.position;
      continue;
    }
    REQUIRE(e.detections.size() == truth.size());
    std::set<std::uint32_t> seen;
    for (const Detection& d : e.detections) {
      REQUIRE(truth.count(d.origin));
      seen.insert(d.origin);
      CHECK((d.value.head<3>() - truth[d.origin]).norm() < 2.0 * 6);
      CHECK(d.covariance(0, 0) == Approx(4.0));
    }
    CHECK(seen.size() == truth.size());
    CHECK(e.pd == 1.0);
    CHECK(e.clutter_density == 0.0);
    truth.clear();
  }
}

// noise_factor 3 on target 1: its detections scatter with 3 sigma while their covariance still
// states sigma; target 0 (default 1) keeps sigma. Sample RMS per axis over 2 x 201 x 3 draws each.
TEST_CASE("noise_factor scales a target's true noise only") {
  const auto ev = simulate(R"(
  period: 1 s
  duration: 200 s
  region_lo: [-1000 m, -1000 m, -100 m]
  region_hi: [1000 m, 1000 m, 100 m]
  measurement_sigma: 2 m
  targets:
    - {initial_position: [-500, 0, 0], initial_velocity: [1, 0, 0]}
    - {initial_position: [0, -500, 0], initial_velocity: [0, 1, 0], noise_factor: 3}
)");
  std::map<std::uint32_t, Vec3> truth;
  double sum2[2] = {0, 0};
  int n[2] = {0, 0};
  for (const Event& e : ev) {
    if (!e.scan) {
      truth[e.target] = e.position;
      continue;
    }
    for (const Detection& d : e.detections) {
      REQUIRE(d.origin < 2);
      CHECK(d.covariance(0, 0) == 4.0);  // stated sigma 2 m whatever the factor
      sum2[d.origin] += (d.value.head<3>() - truth[d.origin]).squaredNorm();
      n[d.origin] += 3;
    }
  }
  REQUIRE(n[0] == 603);
  REQUIRE(n[1] == 603);
  // The RMS of 603 normal draws is within about 3 % (1 sigma) of the true sigma: 15 % bands.
  CHECK(std::sqrt(sum2[0] / n[0]) == Approx(2.0).epsilon(0.15));
  CHECK(std::sqrt(sum2[1] / n[1]) == Approx(6.0).epsilon(0.15));
}

// P_D = 0.5 over 20 targets x 201 scans: detected fraction within 4 binomial sigmas of 0.5
TEST_CASE("P_D 0.5 binomial band") {
  const auto ev = simulate(R"(
    duration: 200 s
    region_lo: [0, 0, 0]
    region_hi: [100, 100, 100]
    initial_targets: 20
    detection_probability: 0.5
  )");
  double n = 0, k = 0;
  std::size_t alive = 0;
  for (const Event& e : ev) {
    if (!e.scan) {
      ++alive;
      continue;
    }
    n += static_cast<double>(alive);
    k += static_cast<double>(e.detections.size());
    alive = 0;
  }
  REQUIRE(n == 20 * 201);
  const double sd = std::sqrt(n * 0.25);
  CHECK(std::fabs(k - 0.5 * n) < 4 * sd);
}

// clutter only: Poisson mean within 4 sigma of the mean, every point inside the region, both
// below 30 (multiplication) and above (rejection)
TEST_CASE("clutter Poisson band and region") {
  for (double rate : {3.0, 80.0}) {
    const auto ev = simulate("duration: 499 s\nregion_lo: [0, -50, 10]\nregion_hi: [200, 50, 20]\nclutter_rate: " +
                             std::to_string(rate) + "\n");
    double total = 0, scans = 0, sq = 0;
    for (const Event& e : ev) {
      REQUIRE(e.scan);
      ++scans;
      total += static_cast<double>(e.detections.size());
      sq += static_cast<double>(e.detections.size() * e.detections.size());
      CHECK(e.clutter_density == Approx(rate / (200.0 * 100 * 10)));
      for (const Detection& d : e.detections) {
        CHECK(d.origin == kOriginClutter);
        CHECK((d.value[0] >= 0 && d.value[0] <= 200 && d.value[1] >= -50 && d.value[1] <= 50 && d.value[2] >= 10 &&
               d.value[2] <= 20));
      }
      for (std::size_t i = 1; i < e.detections.size(); ++i) CHECK(e.detections[i - 1].value[0] <= e.detections[i].value[0]);
    }
    REQUIRE(scans == 500);
    const double mean = total / scans;
    CHECK(std::fabs(mean - rate) < 4 * std::sqrt(rate / scans));
    const double var = sq / scans - mean * mean;
    CHECK(var == Approx(rate).epsilon(0.25));
  }
}

// clutter_density x volume gives the rate
TEST_CASE("clutter density sets the rate") {
  const auto ev = simulate("duration: 299 s\nregion_lo: [0, 0, 0]\nregion_hi: [100, 100, 10]\nclutter_density: 1e-4\n");
  double total = 0;
  for (const Event& e : ev) total += static_cast<double>(e.detections.size());
  CHECK(std::fabs(total / 300 - 10.0) < 4 * std::sqrt(10.0 / 300));
}

// Poisson births with survival: birth count mean within band; each target's lifetime is
// geometric with mean 1 / (1 - ps)
TEST_CASE("births and survival") {
  const auto ev = simulate(R"(
    duration: 999 s
    region_lo: [0, 0, 0]
    region_hi: [1000, 1000, 0.001]
    birth_region_lo: [100, 100, 0]
    birth_region_hi: [200, 200, 0]
    birth_rate: 0.5
    survival_probability: 0.8
    birth_velocity_sigma: [1, 1, 0]
  )");
  std::map<std::uint32_t, int> steps;
  std::map<std::uint32_t, Vec3> first;
  for (const Event& e : ev)
    if (!e.scan) {
      if (!steps.count(e.target)) first[e.target] = e.position;
      ++steps[e.target];
    }
  const double born = static_cast<double>(steps.size());
  CHECK(std::fabs(born - 0.5 * 999) < 4 * std::sqrt(0.5 * 999));
  // ids 0..born-1, none reused
  CHECK(steps.rbegin()->first == steps.size() - 1);
  for (const auto& [id, p] : first) CHECK((p.x() >= 100 && p.x() <= 200 && p.y() >= 100 && p.y() <= 200));
  double life = 0;
  for (const auto& [id, n] : steps) life += n;
  const double mean = life / born;  // geometric: mean 1/(1-ps) = 5, sd sqrt(ps)/(1-ps) = 4.47
  CHECK(std::fabs(mean - 5.0) < 4 * 4.47 / std::sqrt(born) + 0.1);
}

// planar keeps z = 0 with process noise on
TEST_CASE("planar stays in z 0") {
  const auto ev = simulate(R"(
    duration: 50 s
    planar: true
    region_lo: [0, 0]
    region_hi: [1000, 1000]
    initial_targets: 5
    birth_velocity_sigma: [5, 5, 5]
    process_noise_q: 1 m2/s3
    measurement_sigma_z: 0.5 m
  )");
  for (const Event& e : ev) {
    if (!e.scan) CHECK(e.position.z() == 0.0);
    else {
      CHECK(e.region.lo[2] == Approx(-1.5));
      CHECK(e.region.hi[2] == Approx(1.5));
    }
  }
}

// the same seed reproduces every item; another seed does not
TEST_CASE("seed determinism") {
  const std::string y = R"(
    duration: 30 s
    region_lo: [0, 0, 0]
    region_hi: [1000, 1000, 100]
    initial_targets: 5
    birth_rate: 0.3
    survival_probability: 0.95
    process_noise_q: 0.5 m2/s3
    detection_probability: 0.9
    clutter_rate: 10
  )";
  auto flat = [](const std::vector<Event>& ev) {
    std::vector<double> v;
    for (const Event& e : ev) {
      v.push_back(e.time);
      v.push_back(e.target);
      for (int i = 0; i < 3; ++i) v.push_back(e.position[i]);
      for (const Detection& d : e.detections) {
        v.push_back(d.origin);
        for (int i = 0; i < 3; ++i) v.push_back(d.value[i]);
      }
    }
    return v;
  };
  const auto a = flat(simulate(y, 7)), b = flat(simulate(y, 7)), c = flat(simulate(y, 8));
  CHECK(a == b);
  CHECK(a != c);
}

// inconsistent parameters are refused naming the parameter
TEST_CASE("refusals name their parameter") {
  const std::string base = "duration: 10 s\nregion_lo: [0, 0, 0]\nregion_hi: [10, 10, 10]\n";
  CHECK_THAT(refusal(base + "clutter_rate: 1\nclutter_density: 1e-3\n"), Catch::Contains("clutter_density"));
  CHECK_THAT(refusal("duration: 10 s\nregion_lo: [0, 0, 10]\nregion_hi: [10, 10, 10]\n"), Catch::Contains("region_hi"));
  CHECK_THAT(refusal(base + "detection_probability: 1.5\n"), Catch::Contains("detection_probability"));
  CHECK_THAT(refusal(base + "rate: 2 Hz\nperiod: 1 s\n"), Catch::Contains("period"));
  CHECK_THAT(refusal("duration: 10 s\nregion_lo: [0, 0]\nregion_hi: [10, 10]\n"), Catch::Contains("region_lo"));
  CHECK_THAT(refusal(base + "survival_probability: 0.9\n"), Catch::Contains("survival_probability"));
  CHECK_THAT(refusal(base + "targets: [{initial_position: [0, 0, 0], birth_time: 5 s, death_time: 2 s}]\n"),
             Catch::Contains("death_time"));
  CHECK_THAT(refusal(base + "planar: true\ntargets: [{initial_position: [0, 0, 5]}]\n"), Catch::Contains("initial_position"));
  CHECK_THAT(refusal(base + "clutter_density: 1 m\n"), Catch::Contains("clutter_density"));
  CHECK(refusal(base).empty());
}

// detections: xy makes a planar position sensor: 2-value detections with a 2x2 covariance, clutter
// over the x-y rectangle (region dim 2, density per m2), and refusals for what has no meaning there.
TEST_CASE("planar x-y detections of a planar sensor") {
  const auto ev = simulate(R"(
    duration: 200 s
    planar: true
    detections: xy
    region_lo: [0, 0]
    region_hi: [1000 m, 500 m]
    initial_targets: 3
    birth_velocity_sigma: [1, 1, 0]
    measurement_sigma: 2 m
    clutter_rate: 4
  )");
  int scans = 0, clutter = 0, hits = 0;
  for (const Event& e : ev) {
    if (!e.scan) continue;
    ++scans;
    CHECK(e.frame == Frame::Planar);
    CHECK(e.region.dim == 2);
    CHECK(e.region.volume() == Approx(1000.0 * 500.0));
    CHECK(e.clutter_density == Approx(4.0 / (1000.0 * 500.0)));
    for (const Detection& d : e.detections) {
      REQUIRE(d.value.size() == 2);
      REQUIRE(d.covariance.rows() == 2);
      CHECK(d.covariance(0, 0) == Approx(4.0));
      if (d.origin == kOriginClutter) {
        ++clutter;
        CHECK(d.value[0] >= 0.0);
        CHECK(d.value[0] <= 1000.0);
        CHECK(d.value[1] <= 500.0);
      } else {
        ++hits;
      }
    }
  }
  CHECK(scans == 201);
  CHECK(hits == 3 * 201);
  CHECK(static_cast<double>(clutter) / scans == Approx(4.0).margin(4.0 * std::sqrt(4.0 / scans)));
  CHECK_THAT(refusal("duration: 10 s\ndetections: xy\nregion_lo: [0, 0, 0]\nregion_hi: [1, 1, 1]\n"),
             Catch::Contains("detections") && Catch::Contains("planar: true"));
  CHECK_THAT(refusal("duration: 10 s\nplanar: true\ndetections: xy\nregion_lo: [0, 0]\nregion_hi: [1, 1]\n"
                     "clutter_density: 1e-6 1/m3\n"),
             Catch::Contains("clutter_rate"));
}
