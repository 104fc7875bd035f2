// Purpose: sink.track — records the truth, measurements (in ENU) and estimates of one chosen run, for the report's track plots.
#include "recording/port_streams.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace trackflow {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What is kept of one item: enough for a ground track, an altitude plot and error bars.
struct Point {
  double time;
  double target;
  double p[3];
  double v[3];
  double sigma[3];
};

using Stream = recording::Stream<Point>;
constexpr ItemKind kKinds[] = {ItemKind::Truth, ItemKind::Measurement, ItemKind::Estimate};

struct TrackRunResult final : RunResult {
  std::vector<Stream> streams;  // by input port x kind, as laid out in set_inputs
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.streams);
  }
};

// Records only run `run`; every other run costs one comparison per item. Buffers are sized at
// the start of the recorded run, so recording does not allocate per item for runs of up to
// kReserve items per stream.
class TrackSink final : public Component, public FieldListCodec<TrackRunResult> {
 public:
  explicit TrackSink(const Params& p) : run_(static_cast<std::uint64_t>(p.integer("run"))) {}

  void set_inputs(const std::vector<InputInfo>& inputs) override { streams_.lay_out(inputs, kKinds); }

  void start_run(const RunContext& ctx) override {
    active_ = ctx.run == run_;
    if (!active_) return;
    for (auto& s : streams_.streams()) {
      s.points.clear();
      s.points.reserve(kReserve);
    }
  }

  void on_truth(const Truth& t, int port) override {
    if (Stream* s = stream(port, ItemKind::Truth))
      s->points.push_back({t.time, static_cast<double>(t.target), {t.position.x(), t.position.y(), t.position.z()},
                           {t.velocity.x(), t.velocity.y(), t.velocity.z()}, {kNaN, kNaN, kNaN}});
  }

  void on_measurement(const Measurement& m, int port) override {
    Stream* s = stream(port, ItemKind::Measurement);
    const int k = m.position_dim();
    if (!s || !m.valid || m.value.size() < k) return;
    const Vec3 p = measured_position(m);
    Vec3 sigma = Vec3::Constant(kNaN);
    if ((m.frame == Frame::Cartesian || m.frame == Frame::Planar) && m.covariance.rows() >= k && m.covariance.cols() >= k)
      for (int i = 0; i < k; ++i) sigma(i) = m.covariance(i, i) >= 0.0 ? std::sqrt(m.covariance(i, i)) : kNaN;
    s->points.push_back({m.time, kNaN, {p.x(), p.y(), p.z()}, {kNaN, kNaN, kNaN}, {sigma.x(), sigma.y(), sigma.z()}});
  }

  // Uninitialised estimates carry a zero state: they would draw a line to the origin.
  void on_estimate(const Estimate& e, int port) override {
    Stream* s = stream(port, ItemKind::Estimate);
    if (!s || !e.initialised) return;
    Point& q = s->points.emplace_back();
    q.time = e.time;
    q.target = static_cast<double>(e.target);
    for (int i = 0; i < 3; ++i) {
      q.p[i] = e.enu(i);
      q.v[i] = e.enu(3 + i);
      const double var = e.enu_covariance(i, i);
      q.sigma[i] = var >= 0.0 ? std::sqrt(var) : kNaN;
    }
  }

  std::unique_ptr<RunResult> end_run() override {
    if (!active_) return nullptr;
    active_ = false;
    auto r = std::make_unique<TrackRunResult>();
    r->streams = streams_.streams();
    return r;
  }

  void merge(RunResult& result) override {
    recorded_ = static_cast<TrackRunResult&>(result).streams;
    have_ = true;
  }

  void finish(Summary& summary, const FinishContext& ctx) override {
    if (!have_) {
      summary.notes.push_back("run " + std::to_string(run_) + " was not run (only " + std::to_string(ctx.runs) +
                              "): no track recorded");
      return;
    }
    for (size_t i = 0; i < recorded_.size(); ++i) {
      const Stream& st = recorded_[i];
      Series s;
      s.name = streams_.names()[i];
      s.description = std::string(to_string(st.kind)) + "s of run " + std::to_string(run_) + " in the ENU frame";
      s.add_column("time", "s");
      s.add_column("target");
      for (const char* a : {"x", "y", "z"}) s.add_column(a, "m");
      for (const char* a : {"vx", "vy", "vz"}) s.add_column(a, "m/s");
      for (const char* a : {"sigma_x", "sigma_y", "sigma_z"}) s.add_column(a, "m");
      s.values.reserve(st.points.size() * s.columns.size());
      for (const Point& p : st.points) {
        s.values.push_back(p.time);
        s.values.push_back(p.target);
        s.values.insert(s.values.end(), std::begin(p.p), std::end(p.p));
        s.values.insert(s.values.end(), std::begin(p.v), std::end(p.v));
        s.values.insert(s.values.end(), std::begin(p.sigma), std::end(p.sigma));
      }
      summary.series.push_back(std::move(s));
    }
    summary.metric("run", static_cast<double>(run_));
  }

 private:
  static constexpr size_t kReserve = 8192;
  static std::size_t slot(ItemKind k) { return k == ItemKind::Truth ? 0 : k == ItemKind::Measurement ? 1 : 2; }
  Stream* stream(int port, ItemKind k) { return active_ ? streams_.find(port, slot(k)) : nullptr; }

  const std::uint64_t run_;
  recording::PortStreams<Point> streams_;
  bool active_ = false;
  // Aggregating instance.
  std::vector<Stream> recorded_;
  bool have_ = false;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.track";
  d.kind = ComponentKind::Sink;
  d.summary = "Records the truth, measurements and estimates of one run for plots (`trackflow report` adds one)";
  d.doc =
      "Inputs: any nodes, e.g. inputs: [truth, cm, kf]. For run `run` only, it keeps per input and item kind the "
      "time, target, ENU position and velocity, and the position sigmas (estimates: sqrt of the ENU covariance "
      "diagonal; Cartesian measurements: of their covariance); spherical measurements are converted to ENU at the "
      "sensor's position. Uninitialised estimates and invalid measurements are left out. It publishes one series per "
      "stream, named <kind>:<node> (`trackflow run --series` writes them as CSV); `trackflow report` adds this sink by "
      "itself to draw the track of --track-run.";
  d.params = {
      ParamSpec::integer("run", "the 0-based run to record").def("0").at_least(0),
  };
  d.accepts = ItemKind::Estimate | ItemKind::Truth | mask(ItemKind::Measurement);
  d.min_inputs = 1;
  d.max_inputs = -1;
  d.produces = 0;
  d.create = [](const Params& p) { return std::make_unique<TrackSink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.track", trackflow::register_components)
