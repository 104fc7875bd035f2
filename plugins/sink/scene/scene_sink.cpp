// Purpose: sink.scene — records one run's truths by target, tracks by id and status, and scan detections (clutter or target-originated) in ENU, capped in size, for the report's multi-target picture.
#include "recording/port_streams.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/scan.hpp>
#include <trackflow/tracks.hpp>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace trackflow {
namespace {

// One recorded position. `id`: the target (truth), the track id (tracks), the origin's target id
// or -1 for clutter and -2 for unknown (detections). `tag`: the TrackStatus (tracks), the scan's
// index in the run (detections), 0 (truth).
struct Point {
  double time;
  double id;
  double tag;
  double p[3];
};

using Stream = recording::Stream<Point>;

struct SceneRunResult final : RunResult {
  std::vector<Stream> streams;       // by input port x kind, as laid out by PortStreams
  std::uint64_t clutter_stride = 1;  // clutter kept of every k-th scan only
  std::uint64_t not_recorded = 0;    // points past max_points once no clutter was left to thin
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.streams, r.clutter_stride, r.not_recorded);
  }
};

constexpr ItemKind kKinds[] = {ItemKind::Truth, ItemKind::Scan, ItemKind::Tracks};
constexpr double kClutter = -1.0, kUnknownOrigin = -2.0;

// Records only run `run`; every other run costs one comparison per item. At most max_points
// points: past that, the clutter is thinned to the scans whose index is a multiple of a doubling
// stride (the same for every scan stream), and what still does not fit is counted, not kept.
class SceneSink final : public Component, public FieldListCodec<SceneRunResult> {
 public:
  explicit SceneSink(const Params& p)
      : run_(static_cast<std::uint64_t>(p.integer("run"))), max_points_(static_cast<std::size_t>(p.integer("max_points"))) {}

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    streams_.lay_out(inputs, kKinds);
    scans_.assign(streams_.streams().size(), 0);
  }

  void start_run(const RunContext& ctx) override {
    active_ = ctx.run == run_;
    if (!active_) return;
    for (auto& s : streams_.streams()) s.points.clear();
    std::fill(scans_.begin(), scans_.end(), 0);
    rec_.clutter_stride = 1;
    rec_.not_recorded = 0;
    total_ = thinnable_ = 0;
  }

  void on_truth(const Truth& t, int port) override {
    if (Stream* s = stream(port, 0)) keep(*s, {t.time, double(t.target), 0.0, {t.position.x(), t.position.y(), t.position.z()}});
  }

  void on_scan(const Scan& scan, int port) override {
    Stream* s = stream(port, 1);
    if (!s || !scan.valid) return;
    const std::uint64_t index = scans_[static_cast<size_t>(s - streams_.streams().data())]++;
    Measurement m;
    for (const Detection& d : scan.detections) {
      const bool clutter = d.origin == kOriginClutter;
      if (clutter && index % rec_.clutter_stride != 0) continue;
      if (d.value.size() < position_values(scan.sensor.frame)) continue;
      to_measurement(scan, d, m);
      const Vec3 p = measured_position(m);
      const double origin = clutter ? kClutter : d.origin == kOriginUnknown ? kUnknownOrigin : double(d.origin);
      keep(*s, {scan.time, origin, double(index), {p.x(), p.y(), p.z()}});
    }
  }

  // Uninitialised tracks carry a zero state (a line to the origin), deleted ones are no estimate.
  void on_tracks(const TrackSet& set, int port) override {
    Stream* s = stream(port, 2);
    if (!s) return;
    for (const TrackEstimate& te : set.tracks) {
      if (!te.estimate.initialised || te.status == TrackStatus::Deleted) continue;
      const auto& e = te.estimate.enu;
      keep(*s, {set.time, double(te.id), double(static_cast<int>(te.status)), {e(0), e(1), e(2)}});
    }
  }

  std::unique_ptr<RunResult> end_run() override {
    if (!active_) return nullptr;
    active_ = false;
    auto r = std::make_unique<SceneRunResult>(rec_);
    r->streams = streams_.streams();
    return r;
  }

  void merge(RunResult& result) override {
    recorded_ = static_cast<SceneRunResult&>(result);
    have_ = true;
  }

  void finish(Summary& summary, const FinishContext& ctx) override {
    if (!have_) {
      summary.notes.push_back("run " + std::to_string(run_) + " was not run (only " + std::to_string(ctx.runs) +
                              "): no scene recorded");
      return;
    }
    static const char* kTag[] = {"", "scan", "status"};
    for (size_t i = 0; i < recorded_.streams.size(); ++i) {
      const Stream& st = recorded_.streams[i];
      const int k = st.kind == ItemKind::Truth ? 0 : st.kind == ItemKind::Scan ? 1 : 2;
      Series s;
      s.name = streams_.names()[i];
      s.description = std::string(k == 0   ? "truths by target"
                                  : k == 1 ? "scan detections (origin: target id, -1 clutter, -2 unknown)"
                                           : "tracks by id (status: 0 tentative, 1 confirmed, 2 coasting)") +
                      " of run " + std::to_string(run_) + " in the ENU frame";
      s.add_column("time", "s");
      s.add_column(k == 0 ? "target" : k == 1 ? "origin" : "track");
      if (k) s.add_column(kTag[k]);
      for (const char* a : {"x", "y", "z"}) s.add_column(a, "m");
      s.values.reserve(st.points.size() * s.columns.size());
      for (const Point& p : st.points) {
        s.values.push_back(p.time);
        s.values.push_back(p.id);
        if (k) s.values.push_back(p.tag);
        s.values.insert(s.values.end(), std::begin(p.p), std::end(p.p));
      }
      summary.series.push_back(std::move(s));
    }
    summary.metric("run", static_cast<double>(run_));
    summary.metric("clutter_scan_stride", static_cast<double>(recorded_.clutter_stride));
    summary.metric("points_not_recorded", static_cast<double>(recorded_.not_recorded));
    if (recorded_.clutter_stride > 1)
      summary.notes.push_back("clutter of every " + std::to_string(recorded_.clutter_stride) +
                              "th scan only (max_points " + std::to_string(max_points_) + ")");
    if (recorded_.not_recorded)
      summary.notes.push_back(std::to_string(recorded_.not_recorded) + " points past max_points " +
                              std::to_string(max_points_) + " not recorded (no clutter left to thin)");
  }

 private:
  Stream* stream(int port, std::size_t slot) { return active_ ? streams_.find(port, slot) : nullptr; }

  void keep(Stream& s, const Point& p) {
    while (total_ >= max_points_ && thinnable_ > 0) thin_clutter();
    // Clutter of a scan the stride (just doubled) leaves out is thinned, as the note says.
    if (p.id == kClutter && static_cast<std::uint64_t>(p.tag) % rec_.clutter_stride != 0) return;
    if (total_ >= max_points_) {
      ++rec_.not_recorded;
      return;
    }
    s.points.push_back(p);
    ++total_;
    if (p.id == kClutter && p.tag != 0.0) ++thinnable_;
  }

  // Doubles the clutter stride and drops the clutter of the scans it now leaves out. Scan 0's
  // clutter stays at any stride, so only the clutter of later scans (thinnable_ of it, counted as
  // kept, so that a full recorder costs no pass over its points per item) can be thinned.
  void thin_clutter() {
    rec_.clutter_stride *= 2;
    total_ = thinnable_ = 0;
    for (auto& s : streams_.streams()) {
      if (s.kind == ItemKind::Scan)
        std::erase_if(s.points, [&](const Point& p) {
          return p.id == kClutter && static_cast<std::uint64_t>(p.tag) % rec_.clutter_stride != 0;
        });
      total_ += s.points.size();
      for (const Point& p : s.points) thinnable_ += p.id == kClutter && p.tag != 0.0 ? 1 : 0;
    }
  }

  const std::uint64_t run_;
  const std::size_t max_points_;
  recording::PortStreams<Point> streams_;
  std::vector<std::uint64_t> scans_;  // per stream: valid scans seen in the run
  SceneRunResult rec_;                // the run's stride and count (its streams: streams_)
  std::size_t total_ = 0;      // points kept
  std::size_t thinnable_ = 0;  // of them, clutter of scans after the first
  bool active_ = false;
  // Aggregating instance.
  SceneRunResult recorded_;
  bool have_ = false;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.scene";
  d.kind = ComponentKind::Sink;
  d.summary = "Records one run's truths, tracks and scan detections for the report's picture (`trackflow report` adds one)";
  d.doc =
      "Inputs: a multi-target scenario's truth and scans and the trackers' track sets, e.g. inputs: [scenario, "
      "tracker]. For run `run` only, it keeps the ENU positions of every truth (by target), every initialised "
      "track that is not deleted (by track id, with its status) and every detection of the valid scans (its "
      "origin: the target id, or clutter), spherical detections converted at the sensor's position. At most "
      "max_points points: past that the clutter is thinned to every k-th scan (k doubling; the metric "
      "clutter_scan_stride and a note say k), and points that still do not fit are counted "
      "(points_not_recorded), never dropped unsaid. It publishes one series per input and kind, named "
      "<kind>:<node>; `trackflow report` adds this sink by itself to a pipeline with a tracker and draws the "
      "scene of --track-run in the x-y plane.";
  d.params = {
      ParamSpec::integer("run", "the 0-based run to record").def("0").at_least(0),
      ParamSpec::integer("max_points", "most positions kept (truths, tracks and detections together)")
          .def("200000")
          .at_least(100),
  };
  d.accepts = ItemKind::Truth | ItemKind::Scan | mask(ItemKind::Tracks);
  d.min_inputs = 1;
  d.max_inputs = -1;
  d.produces = 0;
  d.create = [](const Params& p) { return std::make_unique<SceneSink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.scene", trackflow::register_components)
