// Purpose: sim.scenario — a multi-target truth and detection simulator: scripted and Poisson-born nearly-constant-velocity targets, a Cartesian position sensor with P_D, and Poisson clutter, one Scan per step.
#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/run_result_codec.hpp>

#include "simulation/detection_order.hpp"
#include "simulation/poisson.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace trackflow {
namespace {

using simulation::poisson;

constexpr double kInf = std::numeric_limits<double>::infinity();
// Step times are start + k T; a scripted birth or death this close to a step counts as at it.
constexpr double kTimeTolerance = 1e-9;  // s
// Planar without a z range: clutter z is spread over ± this many sigma_z around z = 0.
constexpr double kPlanarZSigmas = 3.0;

// What each detection measures: the ENU position, or its x and y (a planar position sensor).
enum class Measured { Xyz, Xy };

struct Box {
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
  double volume() const { return (hi - lo).prod(); }
};

struct ScriptedTarget {
  Vec3 position, velocity;  // at birth_time
  double birth = 0.0, death = kInf;
  // Its detections' true noise is noise_factor σ, while their covariance states σ (a target the
  // sensor measures worse than it reports: glint, a tumbling body); 1: as stated.
  double noise_factor = 1.0;
};

struct Target {
  std::uint32_t id = 0;
  bool scripted = false;
  std::size_t script = 0;  // index into the scripted list when scripted
  Vec3 position = Vec3::Zero(), velocity = Vec3::Zero(), acceleration = Vec3::Zero();
};

struct ScenarioRunResult final : RunResult {
  std::uint64_t steps = 0, born = 0, alive_steps = 0, detections = 0, clutter = 0, missed = 0;
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.steps, r.born, r.alive_steps, r.detections, r.clutter, r.missed);
  }
};

struct Settings {
  double period = 1.0, start = 0.0;
  long long steps = 0;
  std::vector<ScriptedTarget> scripted;
  double birth_rate = 0.0, survival = 1.0;
  long long initial_targets = 0;
  Box birth_region;
  Vec3 birth_v_mean = Vec3::Zero(), birth_v_sigma = Vec3::Zero();
  double q = 0.0;
  bool planar = false;
  int measured = 3;  // position values per detection: 3 (x, y, z) or 2 (planar x, y)
  SensorFrame sensor;
  double pd = 1.0;
  Vec3 sigma = Vec3::Ones();
  Box region;
  double clutter_mean = 0.0;
};

Box read_box(const Params& p, const char* lo_name, const char* hi_name, bool planar, double planar_z, bool strict) {
  const auto& lo = p.reals(lo_name);
  const auto& hi = p.reals(hi_name);
  for (const char* name : {lo_name, hi_name}) {
    const std::size_t n = p.reals(name).size();
    if (planar ? (n != 2 && n != 3) : n != 3)
      throw p.error(name, planar ? "needs 2 values [x, y] (or 3 with a z range) with 'planar: true'"
                                 : "needs 3 values [x, y, z]");
  }
  if (lo.size() != hi.size())
    throw p.error(hi_name, std::string("has ") + std::to_string(hi.size()) + " values but '" + lo_name + "' has " +
                               std::to_string(lo.size()));
  Box b;
  for (std::size_t i = 0; i < 3; ++i) {
    if (i < lo.size()) {
      b.lo[i] = lo[i];
      b.hi[i] = hi[i];
    } else {
      b.lo[i] = -planar_z;
      b.hi[i] = planar_z;
    }
    const bool bad = strict ? !(b.lo[i] < b.hi[i]) : !(b.lo[i] <= b.hi[i]);
    if (i < lo.size() && bad)
      throw p.error(hi_name, std::string("must be ") + (strict ? "above" : "at least") + " '" + lo_name + "' on axis " +
                                 "xyz"[i] + " (" + std::to_string(b.lo[i]) + " m vs " + std::to_string(b.hi[i]) + " m)");
  }
  return b;
}

Settings read_settings(const Params& p) {
  Settings s;
  if (p.given("rate") && p.given("period")) throw p.error("period", "give either 'rate' or 'period', not both");
  s.period = p.given("rate") ? 1.0 / p.real("rate") : p.real("period");
  s.start = p.real("start_time");
  const double duration = p.real("duration");
  const double span = duration / s.period;
  if (span > 1e9) throw p.error("duration", "gives more than 1e9 steps at this period; lower it");
  s.steps = static_cast<long long>(std::floor(span + kTimeTolerance / s.period)) + 1;
  s.planar = p.boolean("planar");

  static const std::vector<Params> kNone;
  for (const Params& r : p.has("targets") ? p.records("targets") : kNone) {
    ScriptedTarget t;
    t.position = r.vec3("initial_position");
    t.velocity = r.vec3("initial_velocity");
    t.birth = r.real("birth_time");
    t.death = r.has("death_time") ? r.real("death_time") : kInf;
    t.noise_factor = r.real("noise_factor");
    if (!(t.death > t.birth))
      throw r.error("death_time", "must be after birth_time (" + std::to_string(t.birth) + " s)");
    if (s.planar && (t.position.z() != 0.0 || t.velocity.z() != 0.0))
      throw r.error(t.position.z() != 0.0 ? "initial_position" : "initial_velocity",
                    "must have z = 0 with 'planar: true'");
    s.scripted.push_back(t);
  }

  s.birth_rate = p.real("birth_rate");
  s.initial_targets = p.integer("initial_targets");
  s.survival = p.real("survival_probability");
  s.birth_v_mean = p.vec3("birth_velocity_mean");
  s.birth_v_sigma = p.vec3("birth_velocity_sigma");
  if (s.planar) {
    s.birth_v_mean.z() = 0.0;
    s.birth_v_sigma.z() = 0.0;
  }
  if (p.given("survival_probability") && s.birth_rate == 0.0 && s.initial_targets == 0)
    throw p.error("survival_probability", "applies to Poisson-born targets only: give birth_rate or initial_targets");
  s.q = p.real("process_noise_q");

  const double sigma = p.real("measurement_sigma");
  const double sigma_z = p.has("measurement_sigma_z") ? p.real("measurement_sigma_z") : sigma;
  s.sigma = Vec3(sigma, sigma, sigma_z);
  s.pd = p.real("detection_probability");

  s.region = read_box(p, "region_lo", "region_hi", s.planar, kPlanarZSigmas * sigma_z, true);
  const bool random_births = s.birth_rate > 0.0 || s.initial_targets > 0;
  if (p.given("birth_region_lo") != p.given("birth_region_hi"))
    throw p.error(p.given("birth_region_lo") ? "birth_region_lo" : "birth_region_hi",
                  "give both birth_region_lo and birth_region_hi (or neither: the surveillance region)");
  if (p.given("birth_region_lo")) {
    if (!random_births) throw p.error("birth_region_lo", "applies to Poisson-born targets only: give birth_rate or initial_targets");
    s.birth_region = read_box(p, "birth_region_lo", "birth_region_hi", s.planar, 0.0, false);
  } else {
    s.birth_region = s.region;
  }
  if (s.planar) s.birth_region.lo.z() = s.birth_region.hi.z() = 0.0;

  if (p.given("clutter_rate") && p.given("clutter_density"))
    throw p.error("clutter_density", "give either 'clutter_rate' (per scan) or 'clutter_density' (per m3), not both");
  s.clutter_mean = p.given("clutter_density") ? p.real("clutter_density") * s.region.volume() : p.real("clutter_rate");
  if (s.clutter_mean > 1e7) throw p.error(p.given("clutter_density") ? "clutter_density" : "clutter_rate",
                                           "gives more than 1e7 clutter detections per scan; lower it");

  s.sensor.sensor = static_cast<std::uint32_t>(p.integer("sensor"));
  s.sensor.frame = Frame::Cartesian;
  if (p.choice<Measured>("detections") == Measured::Xy) {
    if (!s.planar) throw p.error("detections", "xy (planar x-y detections) needs 'planar: true'");
    if (p.given("measurement_sigma_z")) throw p.error("measurement_sigma_z", "has no use with 'detections: xy' (z is not measured)");
    if (p.given("clutter_density"))
      throw p.error("clutter_density", "is per m3; with 'detections: xy' give clutter_rate (per scan over the x-y region)");
    s.measured = 2;
    s.sensor.frame = Frame::Planar;
  }
  s.sensor.sensor_position = p.vec3("sensor_position");
  return s;
}

class ScenarioSource final : public Generator, public FieldListCodec<ScenarioRunResult> {
 public:
  explicit ScenarioSource(Settings s) : s_(std::move(s)) {
    // Exact CV discretisation per axis, Q = q [[T³/3, T²/2], [T²/2, T]] (motion.hpp), and its
    // Cholesky factor, once: each step draws w = L n, n ~ N(0, I₂).
    if (s_.q > 0.0) {
      const auto Q = ConstantVelocity::axis_noise_continuous(s_.period, s_.q);
      chol_ = Q.llt().matrixL();
    }
    const double steady = static_cast<double>(s_.initial_targets) +
                          (s_.survival < 1.0 ? s_.birth_rate / (1.0 - s_.survival) : s_.birth_rate * s_.steps);
    const std::size_t population = s_.scripted.size() + static_cast<std::size_t>(std::min(4.0 * steady + 16.0, 1e6));
    living_.reserve(population);
    const double clutter = s_.clutter_mean + 6.0 * std::sqrt(s_.clutter_mean) + 8.0;
    detections_.reserve(population + static_cast<std::size_t>(clutter));
    scan_.sensor = s_.sensor;
    scan_.region.known = true;
    scan_.region.dim = s_.measured;
    for (int i = 0; i < 3; ++i) {
      scan_.region.lo[i] = s_.region.lo[i];
      scan_.region.hi[i] = s_.region.hi[i];
    }
    if (s_.measured == 2) scan_.region.lo[2] = scan_.region.hi[2] = 0.0;
    scan_.clutter_density = s_.clutter_mean / scan_.region.volume();
    scan_.detection_probability = s_.pd;
  }

  void start_run(const RunContext& ctx) override {
    rng_.reseed(ctx.seed);
    run_ = ScenarioRunResult{};
    living_.clear();
    detections_.clear();
    next_step_ = 0;
    next_id_ = static_cast<std::uint32_t>(s_.scripted.size());
    scripted_born_.assign(s_.scripted.size(), false);
  }

  double next_time() const override { return next_step_ < s_.steps ? step_time(next_step_) : kInf; }

  void emit_next() override {
    const double t = step_time(next_step_);
    if (next_step_ == 0) {
      births(t);
      for (long long i = 0; i < s_.initial_targets; ++i) born_random();
    } else {
      deaths(t);
      for (Target& x : living_) propagate(x);
      births(t);
      for (std::uint64_t n = poisson(rng_, s_.birth_rate); n > 0; --n) born_random();
    }
    ++next_step_;
    ++run_.steps;
    run_.alive_steps += living_.size();

    truth_.time = t;
    for (const Target& x : living_) {
      truth_.target = x.id;
      truth_.position = x.position;
      truth_.velocity = x.velocity;
      truth_.acceleration = x.acceleration;
      out.emit(truth_);
    }
    sense(t);
  }

  std::unique_ptr<RunResult> end_run() override { return std::make_unique<ScenarioRunResult>(run_); }
  void merge(RunResult& r) override {
    const auto& c = static_cast<ScenarioRunResult&>(r);
    ++runs_;
    total_.steps += c.steps;
    total_.born += c.born;
    total_.alive_steps += c.alive_steps;
    total_.detections += c.detections;
    total_.clutter += c.clutter;
    total_.missed += c.missed;
  }
  void finish(Summary& s, const FinishContext&) override {
    if (runs_ == 0) return;
    const double n = static_cast<double>(runs_);
    s.metric("targets_born", static_cast<double>(total_.born) / n);
    s.metric("mean_targets_alive",
             total_.steps ? static_cast<double>(total_.alive_steps) / static_cast<double>(total_.steps) : 0.0);
    s.metric("target_detections", static_cast<double>(total_.detections) / n);
    s.metric("clutter_detections", static_cast<double>(total_.clutter) / n);
    s.metric("missed_detections", static_cast<double>(total_.missed) / n);
    s.metric("scans", static_cast<double>(total_.steps) / n);
    s.notes.push_back("per run averages over " + std::to_string(runs_) + " run(s); mean_targets_alive is per scan");
  }

 private:
  double step_time(long long k) const { return s_.start + static_cast<double>(k) * s_.period; }

  // Random-born targets survive each step with survival_probability; scripted ones live from
  // birth_time up to (not including) death_time. Order (ids ascending) is kept.
  void deaths(double t) {
    const double ps = s_.survival;
    auto dead = [&](const Target& x) {
      if (x.scripted) return s_.scripted[x.script].death <= t + kTimeTolerance;
      return ps < 1.0 && !(rng_.uniform() < ps);
    };
    living_.erase(std::remove_if(living_.begin(), living_.end(), dead), living_.end());
  }

  // Over one period, per axis [p, v] <- [[1, T], [0, 1]] [p, v] + L n (planar: no z noise).
  void propagate(Target& x) {
    const double T = s_.period;
    x.position += T * x.velocity;
    x.acceleration.setZero();
    if (s_.q > 0.0) {
      const int axes = s_.planar ? 2 : 3;
      for (int i = 0; i < axes; ++i) {
        const double n1 = rng_.normal(), n2 = rng_.normal();
        const double wv = chol_(1, 0) * n1 + chol_(1, 1) * n2;
        x.position[i] += chol_(0, 0) * n1;
        x.velocity[i] += wv;
        x.acceleration[i] = wv / T;  // the mean white acceleration over the step
      }
    }
  }

  // Scripted targets whose birth_time has come: inserted at their id's place, at the position
  // their straight line reaches at t (birth_time between two steps).
  void births(double t) {
    for (std::size_t i = 0; i < s_.scripted.size(); ++i) {
      const ScriptedTarget& st = s_.scripted[i];
      if (scripted_born_[i] || st.birth > t + kTimeTolerance) continue;
      scripted_born_[i] = true;
      if (st.death <= t + kTimeTolerance) continue;  // lived between two steps only
      Target x;
      x.id = static_cast<std::uint32_t>(i);
      x.scripted = true;
      x.script = i;
      const double dt = std::max(0.0, t - st.birth);
      x.position = st.position + dt * st.velocity;
      x.velocity = st.velocity;
      auto at = std::lower_bound(living_.begin(), living_.end(), x.id,
                                 [](const Target& a, std::uint32_t id) { return a.id < id; });
      living_.insert(at, x);
      ++run_.born;
    }
  }

  // A Poisson-born target: position uniform in the birth region, velocity N(mean, sigma²) per axis.
  void born_random() {
    Target x;
    x.id = next_id_++;
    for (int i = 0; i < 3; ++i) {
      const double lo = s_.birth_region.lo[i], hi = s_.birth_region.hi[i];
      x.position[i] = lo + (hi - lo) * rng_.uniform();
    }
    for (int i = 0; i < 3; ++i) x.velocity[i] = s_.birth_v_sigma[i] > 0.0 ? rng_.normal(s_.birth_v_mean[i], s_.birth_v_sigma[i])
                                                                            : s_.birth_v_mean[i];
    living_.push_back(x);
    ++run_.born;
  }

  void sense(double t) {
    detections_.clear();
    const int k_values = s_.measured;  // position values per detection: 3, or 2 (planar x, y)
    Detection d;
    d.value.resize(k_values);
    d.covariance.setZero(k_values, k_values);
    for (int i = 0; i < k_values; ++i) d.covariance(i, i) = s_.sigma[i] * s_.sigma[i];
    for (const Target& x : living_) {
      if (!(rng_.uniform() < s_.pd)) {
        ++run_.missed;
        continue;
      }
      // k = 1 (every random-born target, a scripted one by default): k σ is σ exactly.
      const double k = x.scripted ? s_.scripted[x.script].noise_factor : 1.0;
      for (int i = 0; i < k_values; ++i) d.value[i] = x.position[i] + k * s_.sigma[i] * rng_.normal();
      d.origin = x.id;
      detections_.push_back(d);
      ++run_.detections;
    }
    d.origin = kOriginClutter;
    for (std::uint64_t n = poisson(rng_, s_.clutter_mean); n > 0; --n) {
      for (int i = 0; i < k_values; ++i) d.value[i] = s_.region.lo[i] + (s_.region.hi[i] - s_.region.lo[i]) * rng_.uniform();
      detections_.push_back(d);
      ++run_.clutter;
    }
    // Sorted by x, then y, then z, so the order gives nothing of the origin away.
    simulation::sort_detections(detections_);
    scan_.time = t;
    scan_.detections = std::span<const Detection>(detections_.data(), detections_.size());
    out.emit(scan_);
  }

  Settings s_;
  Eigen::Matrix2d chol_ = Eigen::Matrix2d::Zero();
  Rng rng_;
  std::vector<Target> living_;
  std::vector<bool> scripted_born_;
  std::vector<Detection> detections_;
  long long next_step_ = 0;
  std::uint32_t next_id_ = 0;
  Truth truth_;
  Scan scan_;
  ScenarioRunResult run_, total_;
  std::uint64_t runs_ = 0;
};

std::vector<ParamSpec> target_fields() {
  return {
      ParamSpec::real_list("initial_position", dim::length, "ENU position at birth_time [x, y, z]", 3).req(),
      ParamSpec::real_list("initial_velocity", dim::velocity, "ENU velocity [vx, vy, vz]", 3).def("[0, 0, 0]"),
      ParamSpec::real("birth_time", dim::time, "first time it exists (from the first step at or after it)").def("0 s"),
      ParamSpec::real("death_time", dim::time, "time it stops existing: its last step is the one before (default: never)"),
      ParamSpec::real("noise_factor", dim::none,
                      "its detections' true noise is noise_factor x the stated sigma (their covariance still states "
                      "sigma): a target measured worse than the sensor reports")
          .def("1")
          .positive(),
  };
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sim.scenario";
  d.kind = ComponentKind::Source;
  d.summary = "Multi-target scenario: scripted and Poisson-born nearly-constant-velocity targets seen by a Cartesian "
              "position sensor with detection probability and Poisson clutter; per step one Truth per living target, "
              "then one Scan";
  d.doc =
      "Steps at t_k = start_time + k T (T = period, or 1/rate) up to and including start_time + duration. At each "
      "step, in this order: random-born targets that fail the survival test (probability survival_probability) and "
      "scripted ones whose death_time has come disappear; the survivors move by the nearly-constant-velocity model, "
      "per axis [p, v] <- [[1, T], [0, 1]] [p, v] + w, w ~ N(0, q [[T³/3, T²/2], [T²/2, T]]) with q = "
      "process_noise_q (the exact discretisation of continuous white acceleration, Bar-Shalom et al. 2001 eq "
      "6.2.2-12, as motion.hpp's ConstantVelocity::axis_noise_continuous; q = 0: straight lines); scripted targets "
      "whose birth_time has come appear (on their straight line from initial_position at birth_time); then a "
      "Poisson(birth_rate) number of new targets, each uniform in the birth region (birth_region_lo/hi, default the "
      "surveillance region) with velocity N(birth_velocity_mean, diag(birth_velocity_sigma²)); initial_targets "
      "such targets exist at the first step. Scripted targets take ids 0..n-1 in list order, random-born ones n, "
      "n+1, ... in birth order; ids are never reused in a run. The node then emits one Truth per living target in "
      "id order (its acceleration: the mean white acceleration of the step, zero without noise), then one Scan of "
      "the same time: each living target is detected with probability detection_probability, value = position + "
      "N(0, k² diag(σ², σ², σ_z²)) (σ = measurement_sigma, σ_z = measurement_sigma_z, default σ; k = the scripted "
      "target's noise_factor, default 1, 1 for random-born ones), covariance diag(σ², σ², σ_z²) whatever k, origin "
      "= its id; plus a Poisson number of clutter detections of mean clutter_rate (or "
      "clutter_density × region volume), uniform over the surveillance region [region_lo, region_hi], origin "
      "clutter. Detections are sorted by x, then y, then z. The Scan is Cartesian (value = ENU position), its sensor "
      "at sensor_position, its region the surveillance box (known, dim 3), its clutter_density the expected clutter "
      "over the region's volume and its detection_probability P_D. planar: true keeps every target in z = 0 (z "
      "velocity 0, no z noise); detections stay 3-D, z measured with σ_z, and region_lo/hi may then have 2 values, "
      "the z range being ±3 σ_z. detections: xy (with planar: true) makes them planar instead: value [x, y], "
      "covariance diag(σ², σ²), a Planar scan whose region is the x-y rectangle (dim 2; clutter_rate spread over it). "
      "All draws come from this node's run seed, in a fixed order (survival tests, motion "
      "noise per target and axis, random births, then per target a detection test and its noise, clutter count and "
      "positions), so results are identical for any --threads.";
  d.params = {
      ParamSpec::real("period", dim::time, "time between steps (default 1 s; or rate)").def("1 s").positive(),
      ParamSpec::real("rate", dim::frequency, "instead of period: steps per second").positive(),
      ParamSpec::real("start_time", dim::time, "time of the first step").def("0 s"),
      ParamSpec::real("duration", dim::time, "time from the first step to the last (included)").req().at_least(0),
      ParamSpec::records("targets", target_fields(), "scripted targets (crossing, parallel, ...), ids 0..n-1 in order"),
      ParamSpec::real("birth_rate", dim::none, "expected Poisson births per step after the first").def("0").at_least(0),
      ParamSpec::integer("initial_targets", "random-born targets at the first step").def("0").at_least(0).at_most(1e6),
      ParamSpec::real("survival_probability", dim::none, "per step, of each random-born target").def("1").at_least(0).at_most(1),
      ParamSpec::real_list("birth_region_lo", dim::length, "lower corner of the birth region (default: region_lo)"),
      ParamSpec::real_list("birth_region_hi", dim::length, "upper corner of the birth region (default: region_hi)"),
      ParamSpec::real_list("birth_velocity_mean", dim::velocity, "mean velocity of random-born targets", 3).def("[0, 0, 0]"),
      ParamSpec::real_list("birth_velocity_sigma", dim::velocity, "standard deviation per axis of their velocity", 3)
          .def("[0, 0, 0]")
          .at_least(0),
      ParamSpec::real("process_noise_q", dim::accel_psd, "white acceleration spectral density per axis (0: straight lines)")
          .def("0 m2/s3")
          .at_least(0),
      ParamSpec::boolean("planar", "targets stay in z = 0 (z velocity 0, no z noise)").def("false"),
      ParamSpec::choice<Measured>("detections", {{Measured::Xyz, "xyz"}, {Measured::Xy, "xy"}},
                                  "what a detection measures: x, y, z (Cartesian scans) or, with planar: true, x and y "
                                  "(Planar scans of a planar position sensor)")
          .def("xyz"),
      ParamSpec::integer("sensor", "sensor id written into each Scan").def("0").at_least(0).at_most(4294967295.0),
      ParamSpec::real_list("sensor_position", dim::length, "sensor position in the ENU frame", 3).def("[0, 0, 0]"),
      ParamSpec::real("detection_probability", dim::none, "P_D of each living target per scan").def("1").at_least(0).at_most(1),
      ParamSpec::real("measurement_sigma", dim::length, "position noise standard deviation per axis").def("1 m").positive(),
      ParamSpec::real("measurement_sigma_z", dim::length, "z noise standard deviation (default measurement_sigma)").positive(),
      ParamSpec::real_list("region_lo", dim::length, "surveillance region lower corner [x, y, z] (planar: [x, y] allowed)").req(),
      ParamSpec::real_list("region_hi", dim::length, "surveillance region upper corner").req(),
      ParamSpec::real("clutter_rate", dim::none, "expected clutter detections per scan (or clutter_density)").def("0").at_least(0),
      ParamSpec::real("clutter_density", dim::length.pow(-3), "instead of clutter_rate: expected clutter per m3 of the region")
          .at_least(0),
  };
  d.accepts = 0;
  d.min_inputs = 0;
  d.max_inputs = 0;
  d.produces = ItemKind::Truth | ItemKind::Scan;
  d.produces_frames = mask(Frame::Cartesian) | mask(Frame::Planar);
  d.time_ordered = true;
  d.create = [](const Params& p) { return std::make_unique<ScenarioSource>(read_settings(p)); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sim.scenario", trackflow::register_components)
