// Purpose: test-only plugins that misbehave the way a buggy plugin can (test.misbehave: throws, crashes, aborts, exits at a chosen item, alone or on several threads at once; test.nan_estimates: publishes NaN; test.nan_filter: a single-track filter whose estimator's state turns NaN), for tests/hostile.
#include <trackflow/single_track_filter.hpp>
#include <trackflow/plugin.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <thread>

namespace {

using namespace trackflow;

enum class What { None, ThrowStd, ThrowInt, ThrowData, ThrowConfig, Segfault, StackOverflow, Abort, Exit0, QuickExit0 };

// Deep recursion that no compiler can turn into a loop: every frame is used after the call.
int recurse(int n) {
  volatile char frame[4096];
  frame[0] = static_cast<char>(n);
  return recurse(n + 1) + frame[0];
}

// Holds each caller until `n` callers arrived (or 5 s passed): runs on different threads then
// misbehave at the same moment (two crashes at once, for the crash handler).
void meet(long long n) {
  static std::atomic<long long> arrived{0};
  const long long mine = ++arrived;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (arrived.load() < n && mine <= n && std::chrono::steady_clock::now() < until) std::this_thread::yield();
}

// Passes measurements on; at measurement `at` of run `run` it does `what`.
class Misbehave final : public Component {
 public:
  explicit Misbehave(const Params& p)
      : what_(p.choice<What>("what")),
        at_(p.integer("at")),
        every_run_(p.integer("run") < 0),
        run_wanted_(static_cast<std::uint64_t>(p.integer("run"))),
        together_(p.integer("together")) {}

  void start_run(const RunContext& ctx) override {
    run_ = ctx.run;
    count_ = 0;
  }

  void on_measurement(const Measurement& m, int) override {
    if ((every_run_ || run_ == run_wanted_) && count_++ == at_) {
      if (together_ > 1) meet(together_);
      misbehave();
    }
    out.emit(m);
  }

 private:
  void misbehave() const {
    switch (what_) {
      case What::None: return;
      case What::ThrowStd: throw std::out_of_range("index 7 out of range (deliberate)");
      case What::ThrowInt: throw 42;
      case What::ThrowData: throw DataError("a deliberate data error");
      case What::ThrowConfig: throw ConfigError("a deliberate configuration error");
      case What::Segfault: {
        // Not null: a null store is caught by UBSan before it faults; page 0 faults in any build.
        static volatile std::uintptr_t address = 16;
        *reinterpret_cast<volatile int*>(address) = 1;
        return;
      }
      case What::StackOverflow: (void)recurse(0); return;
      case What::Abort: std::abort();
      case What::Exit0: std::exit(0);
      case What::QuickExit0: std::quick_exit(0);
    }
  }

  const What what_;
  const long long at_;
  const bool every_run_;
  const std::uint64_t run_wanted_;
  const long long together_;
  std::uint64_t run_ = 0;
  long long count_ = 0;
};

// A filter outside the front end that publishes the measured position as its state, NaN from
// measurement `at` on: what reaches a sink when a plugin lets a NaN through.
class NanEstimates final : public Filter {
 public:
  explicit NanEstimates(const Params& p) : at_(p.integer("at")) {}
  void start_run(const RunContext&) override { count_ = 0; }
  void on_measurement(const Measurement& m, int) override {
    Estimate e;
    e.time = m.time;
    e.initialised = true;
    e.updated = false;
    e.state = StateVec::Zero(6);
    e.covariance = StateCov::Identity(6, 6);
    e.enu.setZero();
    e.enu.head<3>() = m.value.head<3>();
    e.enu_covariance = Mat6::Identity();
    if (count_++ >= at_) e.enu(0) = std::numeric_limits<double>::quiet_NaN();
    publish(m, e);
  }

 private:
  const long long at_;
  long long count_ = 0;
};

// An estimator behind the SDK's single-track node whose state becomes NaN at the update at time
// `at`: the node must refuse that step instead of publishing it.
class NanEstimator final : public Estimator {
 public:
  explicit NanEstimator(const Params& p)
      : Estimator(MeasurementSpec{mask(Frame::Cartesian), RangeRateUse::Ignore, {}}), at_(p.real("at")) {}
  NoiseHandles noise() override { return {}; }
  StateLayout layout() const override {
    static constexpr StateComponent kLayout[] = {{"x", "m"}, {"y", "m"}, {"z", "m"},
                                                 {"a", "m"}, {"b", "m"}, {"c", "m"}};
    return {kLayout, 6};
  }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<NanEstimator>(*this); }

 private:
  bool reset() override { return false; }
  bool initiate(const Measurement& m, int) override {
    x_ = m.value.head<3>();
    return true;
  }
  void predict(double) override {}
  bool predict_measurement(const SensorFrame&, const MeasCov&, PredictedMeasurement&) const override { return false; }
  bool update(const Measurement& m, int) override {
    x_ = m.value.head<3>();
    if (std::abs(m.time - at_) < 1e-9) x_(1) = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  void fill(Estimate& e) const override {
    e.state.setZero();
    e.state.head<3>() = x_;
    e.covariance.setIdentity();
    e.enu.setZero();
    e.enu.head<3>() = x_;
    e.enu_covariance.setIdentity();
  }
  void scale_covariance(double) override {}

  const double at_;
  Vec3 x_ = Vec3::Zero();
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "test.misbehave";
  d.kind = ComponentKind::Converter;
  d.summary = "Test only: passes measurements on and misbehaves (throws, crashes, aborts) at a chosen one";
  d.params = {
      ParamSpec::choice<What>("what",
                              {{What::None, "none"},
                               {What::ThrowStd, "throw_std"},
                               {What::ThrowInt, "throw_int"},
                               {What::ThrowData, "throw_data"},
                               {What::ThrowConfig, "throw_config"},
                               {What::Segfault, "segfault"},
                               {What::StackOverflow, "stack_overflow"},
                               {What::Abort, "abort"},
                               {What::Exit0, "exit0"},
                               {What::QuickExit0, "quick_exit0"}},
                              "what to do")
          .def("none"),
      ParamSpec::integer("at", "0-based index of the measurement of the run at which to misbehave").def("3"),
      ParamSpec::integer("run", "the run in which to misbehave (-1: every run)").def("0"),
      ParamSpec::integer("together", "when above 1: wait until this many runs reached `at` (on other threads), then all misbehave at once").def("0"),
  };
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Measurement);
  d.create = [](const Params& p) -> std::unique_ptr<Component> { return std::make_unique<Misbehave>(p); };
  r.add(d);

  ComponentDecl n;
  n.type = "test.nan_estimates";
  n.kind = ComponentKind::Filter;
  n.summary = "Test only: publishes the measured position as its estimate, NaN from measurement `at` on";
  n.params = {ParamSpec::integer("at", "0-based index of the first NaN estimate").def("2")};
  n.accepts = mask(ItemKind::Measurement);
  n.accepts_frames = mask(Frame::Cartesian);
  n.produces = mask(ItemKind::Estimate);
  n.create = [](const Params& p) -> std::unique_ptr<Component> { return std::make_unique<NanEstimates>(p); };
  r.add(n);

  ComponentDecl f;
  f.type = "test.nan_filter";
  f.kind = ComponentKind::Filter;
  f.summary = "Test only: a front-end filter whose state turns NaN at the update at time `at`";
  f.params = {ParamSpec::real("at", dim::time, "time of the update that produces NaN").def("0.5 s")};
  f.accepts = mask(ItemKind::Measurement);
  f.accepts_frames = mask(Frame::Cartesian);
  f.produces = mask(ItemKind::Estimate);
  f.create = [](const Params& p) -> std::unique_ptr<Component> {
    return make_single_track_filter("test.nan_filter", p.node(), NanEstimator(p));
  };
  r.add(f);
}

}  // namespace

TRACKFLOW_PLUGIN("test.misbehave", register_components)
