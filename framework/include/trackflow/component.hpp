// Purpose: the interfaces a plugin implements: Component (truth, measurement, estimate, scan and track-set inputs), Generator (root source), Filter, Adapter, and the filter–adapter contract.
#pragma once

#include <trackflow/items.hpp>
#include <trackflow/scan.hpp>
#include <trackflow/tracks.hpp>
#include <trackflow/noise.hpp>
#include <trackflow/series.hpp>
#include <trackflow/transition_model.hpp>

#include <boost/config.hpp>

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace trackflow {

class Component;
namespace host {
class FilterControl;  // the engine's side of Filter and Adapter (host/filter_control.hpp, not in the SDK)
}

namespace detail {
// The component this thread is executing: set around every delivery (Outputs::emit, adapter
// hooks) and by the engine around its own calls, so that when a plugin throws or crashes the
// host can name the node. Two stores per delivery; initial-exec TLS (libtrackflow is always
// loaded with the program), so no call.
extern BOOST_SYMBOL_VISIBLE thread_local constinit Component* executing
#if defined(__GNUC__)
    __attribute__((tls_model("initial-exec")))
#endif
    ;
}  // namespace detail

// The folder (--out) the ensemble this thread works for writes into, for a sink that streams
// its file while runs are merged (merge() has no FinishContext); empty outside the engine.
BOOST_SYMBOL_VISIBLE const std::string& output_directory();

// One downstream connection: deliver to `target` on its input port `port`.
struct Link {
  Component* target = nullptr;
  int port = 0;
  ItemMask accepts = 0xFF;  // kinds this link delivers (what the target declared it accepts)
};

// Counted skips and warnings of one run, merged in run order by the engine.
struct Diagnostics {
  struct Entry {
    std::string node;
    std::string message;
  };
  std::vector<Entry> skips;
  std::vector<Entry> warnings;
  void skip(const std::string& node, std::string message) { skips.push_back({node, std::move(message)}); }
  void warn(const std::string& node, std::string message) { warnings.push_back({node, std::move(message)}); }
};

// What a component learns at the start of each Monte Carlo run.
struct RunContext {
  std::uint64_t run = 0;        // 0-based run index
  std::uint64_t seed = 0;       // derived from (pipeline seed, run, node id)
  Diagnostics* diagnostics = nullptr;
};

// Per-run result a component hands to the engine (metrics sinks, CSV writers).
struct BOOST_SYMBOL_VISIBLE RunResult {
  virtual ~RunResult() = default;
};

struct Metric {
  std::string name;
  double value = 0.0;
  std::string unit;
  bool has_band = false;  // a two-sided acceptance band, e.g. chi-square bounds of ANEES
  double band_lo = 0.0, band_hi = 0.0, confidence = 0.0;
};

// What one node contributes to the end-of-pipeline summary and to --metrics-json.
struct Summary {
  std::vector<Metric> metrics;
  std::vector<std::string> notes;
  std::vector<std::string> files;
  std::vector<Series> series;  // per-step tables for `run --series` and `trackflow report` (appended: old plugins never touch it)
  void metric(std::string name, double v, std::string unit = {}) {
    metrics.push_back({std::move(name), v, std::move(unit)});
  }
  void metric_band(std::string name, double v, double lo, double hi, double confidence) {
    metrics.push_back({std::move(name), v, {}, true, lo, hi, confidence});
  }
  const Metric* find(const std::string& name) const {
    for (const auto& m : metrics)
      if (m.name == name) return &m;
    return nullptr;
  }
};

// One input of a node as wired in the pipeline (port = position in `inputs:`).
struct InputInfo {
  std::string node;   // upstream node id
  std::string type;   // upstream component type
  ItemMask kinds = 0; // item kinds this input delivers
  // A filter's input: the names of Estimate::annotations, "<adapter id>.<name>", in order.
  std::vector<std::string> annotations;
  // A filter's input: the names and units of Estimate::state (look components up with
  // state.index_of("b")); empty for other inputs. Points into the upstream plugin, which stays
  // loaded while this node exists.
  StateLayout state;
  // Whether this input's items arrive in non-decreasing time within a run (every source upstream
  // declares ComponentDecl::time_ordered), so a sink may score an item as soon as its truth is known.
  bool time_ordered = false;
  // A filter's input: the transition model it predicts with (Filter::transition_model), when it
  // has one of transition_model.hpp's; a fusion node predicts the inputs' estimates with it.
  std::optional<TransitionModel> transition;
};

struct FinishContext {
  std::string node;
  std::string output_dir;   // --out, created on demand by the component that writes
  std::uint64_t runs = 1;
};

// Fan-out list of a node, filled by the engine. emit() is inline: one indirect call per consumer.
class Outputs {
 public:
  void connect(const Link* links, int count) {
    links_ = links;
    count_ = count;
  }
  inline void emit(const Truth& t) const;
  inline void emit(const Measurement& m) const;
  inline void emit(const Estimate& e) const;
  inline void emit(const Scan& s) const;
  inline void emit(const TrackSet& t) const;
  int count() const { return count_; }

 private:
  template <ItemKind K, class Item, class Handler>
  void deliver(const Item& item, Handler handler) const;
  const Link* links_ = nullptr;
  int count_ = 0;
};

// Base of every pipeline node. The engine builds one instance per worker thread (plus one
// that aggregates), calls start_run() before each run, delivers items, then end_run().
class BOOST_SYMBOL_VISIBLE Component {
 public:
  virtual ~Component() = default;
  // Called once after construction with this node's inputs; may throw ConfigError (e.g. a
  // sink that takes at most one estimate stream).
  virtual void set_inputs(const std::vector<InputInfo>&) {}
  // The measurement frames this instance emits, when its parameters narrow what its type
  // declares (a recorded log of Cartesian positions); checked against its consumers.
  virtual FrameMask produced_frames() const { return kAnyFrame; }
  // The item kinds this instance emits, when its parameters narrow what its type declares (a log
  // of detections emits scans, one of measurements measurements); its wires are checked against it.
  virtual ItemMask produced_kinds() const { return static_cast<ItemMask>(~ItemMask{0}); }
  virtual void start_run(const RunContext&) {}
  // Items arriving on input `port` (the position of the source in the node's `inputs:`).
  virtual void on_truth(const Truth&, int port);
  virtual void on_measurement(const Measurement&, int port);
  virtual void on_estimate(const Estimate&, int port);
  virtual void on_scan(const Scan&, int port);
  virtual void on_tracks(const TrackSet&, int port);
  // Called on a node whose type sets ComponentDecl::groups_by_time, once everything of time
  // `time` has been delivered: every source has emitted all it has up to `time` and its next
  // item, if any, is later (also after a run's last item). A node that gathers what arrives at one
  // instant (a scan radar making one look of every target) emits it here. Nodes are called
  // upstream first, so what one emits here reaches a downstream one before that one's own call.
  virtual void on_time_complete(double /*time*/) {}
  // Called after the last item of a run; the result (may be null) goes to merge() of the
  // aggregating instance, in run order, so reductions are identical whatever the thread count.
  virtual std::unique_ptr<RunResult> end_run() { return nullptr; }
  virtual void merge(RunResult&) {}
  // Called once on the aggregating instance after all runs.
  virtual void finish(Summary&, const FinishContext&) {}

  Outputs out;
};

// A node with no inputs that produces items itself (simulated trajectory, recorded log).
class BOOST_SYMBOL_VISIBLE Generator : public Component {
 public:
  // Time of the next item, or +infinity when the run's data are exhausted.
  virtual double next_time() const = 0;
  // Emits the item(s) at next_time() through `out`.
  virtual void emit_next() = 0;
};

class Filter;

// Attached to a filter in YAML (`attach_to: <filter id>`); retunes its noise, rescales its state
// covariance or annotates its estimates between steps. What it touches is declared by needs()
// and checked against the filter's noise() before anything runs.
class BOOST_SYMBOL_VISIBLE Adapter : public Component {
 public:
  // What this adapter reads and writes (may depend on its parameters).
  virtual NoiseNeeds needs() const { return {}; }
  // Names of the values this adapter publishes on every estimate of its filter (see annotate);
  // sinks see them as "<adapter id>.<name>".
  virtual std::vector<std::string> annotation_names() const { return {}; }
  // Called before the filter uses `m` (R already holds the measurement's own covariance), and
  // after it has produced `e` from it.
  virtual void before_update(const Measurement& m, Filter& f);
  virtual void after_update(const Measurement& m, const Estimate& e, Filter& f);

 protected:
  // Sets annotation `i` (index into annotation_names()) on the filter's next estimates; it
  // stays until changed. NaN: no value.
  inline void annotate(Filter& f, int i, double value) const;

 private:
  friend class host::FilterControl;
  int first_annotation_ = 0;  // where this adapter's annotations start in its filter's list
};

class BOOST_SYMBOL_VISIBLE Filter : public Component {
 public:
  static constexpr int kMaxAdapters = 4;
  // The noise adapters may read and overwrite, with what each number is (noise.hpp).
  virtual NoiseHandles noise() { return {}; }
  virtual StateLayout state_layout() const { return {}; }
  // The kinematic model the filter predicts with, as configured (adapters may retune its noise
  // per track); nullptr when its state is not one of transition_model.hpp's models.
  virtual const TransitionModel* transition_model() const { return nullptr; }
  // Names of values the filter itself publishes on every estimate (e.g. an IMM's mode
  // probabilities); they come first in the estimate's annotations, before its adapters', and
  // sinks see them as "<filter id>.<name>". Set with annotate_own().
  virtual std::vector<std::string> annotation_names() const { return {}; }

  // State covariance for adapters (fading memory, inflation, re-initialisation). A filter that
  // returns true from has_covariance_access implements the three below.
  virtual bool has_covariance_access() const { return false; }
  // The current covariance of the state (state_layout order); empty before initialisation.
  virtual void read_covariance(StateCov& P) const { P.resize(0, 0); }
  // P <- factor P (factor > 0), whatever the filter's internal representation of P.
  virtual void scale_covariance(double /*factor*/) {}
  // Forgets the track: the next measurements initialise it again.
  virtual void restart_track() {}

 protected:
  static constexpr double kNoAnnotation = std::numeric_limits<double>::quiet_NaN();
  void before_update(const Measurement& m) {
    for (int i = 0; i < adapter_count_; ++i) {
      detail::executing = adapters_[i];
      adapters_[i]->before_update(m, *this);
    }
    detail::executing = this;
  }
  // Sets the filter's own annotation `i` (index into annotation_names()) on its next estimates.
  void annotate_own(int i, double value) {
    if (i >= 0 && i < own_annotation_count_) annotation_values_[i] = value;
  }
  // Whether anything sees the estimates: a consumer downstream or an adapter's after_update.
  bool observed() const { return adapter_count_ > 0 || out.count() > 0; }
  // Stamps the adapters' annotations on `e`, lets adapters see the result, then sends it on.
  void publish(const Measurement& m, Estimate& e) {
    e.annotation_count = annotation_count_;
    for (int i = 0; i < annotation_count_; ++i) e.annotations[i] = annotation_values_[i];
    ++processed_;
    for (int i = 0; i < adapter_count_; ++i) {
      detail::executing = adapters_[i];
      adapters_[i]->after_update(m, e, *this);
    }
    detail::executing = this;
    out.emit(e);
  }

 private:
  // The engine's side of a filter (attaching adapters, their annotation slots, the configured
  // noise put back at every run, the count of published estimates) is host::FilterControl's,
  // not part of what a plugin calls.
  friend class host::FilterControl;
  friend class Adapter;
  void set_annotation(int slot, double value) {
    if (slot >= 0 && slot < annotation_count_) annotation_values_[slot] = value;
  }

  static constexpr int kMaxNoiseValues = 8;
  Adapter* adapters_[kMaxAdapters] = {};
  int adapter_count_ = 0;
  int annotation_count_ = 0;
  int own_annotation_count_ = 0;
  double annotation_values_[kMaxAnnotations] = {kNoAnnotation, kNoAnnotation, kNoAnnotation, kNoAnnotation,
                                                kNoAnnotation, kNoAnnotation, kNoAnnotation, kNoAnnotation};
  double configured_[kMaxNoiseValues] = {};
  int configured_count_ = 0;
  std::uint64_t processed_ = 0;
};

inline void Adapter::annotate(Filter& f, int i, double value) const { f.set_annotation(first_annotation_ + i, value); }

// Each delivery marks its target as executing; if the target throws, the mark stays on the
// innermost node, which is the one the host names.
template <ItemKind K, class Item, class Handler>
inline void Outputs::deliver(const Item& item, Handler handler) const {
  Component* const self = detail::executing;
  for (int i = 0; i < count_; ++i)
    if (links_[i].accepts & mask(K)) {
      detail::executing = links_[i].target;
      (links_[i].target->*handler)(item, links_[i].port);
    }
  detail::executing = self;
}
inline void Outputs::emit(const Truth& t) const { deliver<ItemKind::Truth>(t, &Component::on_truth); }
inline void Outputs::emit(const Measurement& m) const { deliver<ItemKind::Measurement>(m, &Component::on_measurement); }
inline void Outputs::emit(const Estimate& e) const { deliver<ItemKind::Estimate>(e, &Component::on_estimate); }
inline void Outputs::emit(const Scan& s) const { deliver<ItemKind::Scan>(s, &Component::on_scan); }
inline void Outputs::emit(const TrackSet& t) const { deliver<ItemKind::Tracks>(t, &Component::on_tracks); }

}  // namespace trackflow
