// Purpose: TrackAdapters — a tracker's per-track adapters: made and checked like `attach_to:` adapters (host::FilterControl), restarted per track, called around each of the track's updates.
#include <trackflow/error.hpp>
#include <trackflow/host/filter_control.hpp>
#include <trackflow/track_adapters.hpp>

#include <cmath>
#include <limits>
#include <utility>

namespace trackflow {

using host::FilterControl;

std::unique_ptr<Adapter> create_adapter(const NestedComponent& entry) {
  std::unique_ptr<Component> made = entry.component_factory ? entry.component_factory(entry.params) : nullptr;
  auto* adapter = dynamic_cast<Adapter*>(made.get());
  if (!adapter)
    throw ConfigError("type '" + entry.type + "' is not an adapter, so it cannot run here", entry.type_where,
                      entry.params.node());
  made.release();
  return std::unique_ptr<Adapter>(adapter);
}

TrackAdapters::TrackAdapters(const std::vector<NestedComponent>& adapters, Estimator& estimator, std::string who)
    : estimator_(&estimator), who_(std::move(who)) {
  for (const NestedComponent& entry : adapters) {
    std::unique_ptr<Adapter> a = create_adapter(entry);
    // The same check and the same slots as an `attach_to:` adapter on a filter node (graph.cpp),
    // with the entry's `type:` line in place of the `attach_to:` line.
    if (std::string why = noise_mismatch(a->needs(), noise(), has_covariance_access()); !why.empty())
      throw ConfigError("cannot run adapter " + entry.type + " on the tracks of " + who_ + ": " + why,
                        entry.type_where, entry.params.node());
    if (!FilterControl::attach(*this, *a, static_cast<int>(a->annotation_names().size())))
      throw ConfigError("too many adapters or annotations on each track of " + who_ + " (at most " +
                            std::to_string(Filter::kMaxAdapters) + " adapters and " + std::to_string(kMaxAnnotations) +
                            " annotations per track)",
                        entry.type_where, entry.params.node());
    adapters_.push_back(std::move(a));
    frames_.push_back(entry.accepts_frames);
    types_.push_back(entry.type);
  }
  // The estimator's noise now is the configured one; start_track puts it back for every track.
  FilterControl::save_configured_noise(*this);
  const int n = estimator_->layout().dim;
  scratch_.state = StateVec::Zero(n);
  scratch_.covariance = StateCov::Zero(n, n);
}

TrackAdapters::~TrackAdapters() = default;

std::vector<std::string> TrackAdapters::annotation_names_of(const std::vector<NestedComponent>& adapters) {
  std::vector<std::string> names;
  for (const NestedComponent& entry : adapters)
    for (const std::string& name : create_adapter(entry)->annotation_names()) names.push_back(entry.type + "." + name);
  return names;
}

void TrackAdapters::start_track(const RunContext& ctx) {
  FilterControl::reset_adapted_state(*this);
  restart_requested_ = false;
  for (const auto& a : adapters_) a->start_run(ctx);
}

void TrackAdapters::before_update(const Measurement& m, int dim) {
  // A frame an adapter does not declare (a 2-D plot reaching an adapter of three channels) would be
  // passed over by it without a word: refused instead, as graph.cpp refuses it on a filter node.
  for (std::size_t i = 0; i < adapters_.size(); ++i)
    if (m.valid && !(frames_[i] & mask(m.frame)))
      throw DataError(who_ + ": adapter " + types_[i] + " takes " + frame_names(frames_[i]) + " measurements, but the " +
                      "detection at t=" + std::to_string(m.time) + " s is " + to_string(m.frame));
  for (const auto& a : adapters_) a->before_update(m, *this);
  const MeasCov& R = estimator_->measurement_noise();
  if (m.valid && (R.rows() < dim || R.cols() < dim))
    throw DataError(who_ + ": an adapter left a " + std::to_string(R.rows()) + "x" + std::to_string(R.cols()) +
                    " R for a " + std::to_string(dim) + "-element measurement");
}

void TrackAdapters::after_update(const Measurement& m, Estimate& e) {
  stamp(e);
  for (const auto& a : adapters_) a->after_update(m, e, *this);
}

void TrackAdapters::stamp(Estimate& e) const { FilterControl::stamp_annotations(*this, e); }

void TrackAdapters::read_covariance(StateCov& P) const {
  scratch_.state.resize(estimator_->layout().dim);  // fixed capacity: no heap
  estimator_->fill(scratch_);
  P = scratch_.covariance;
}

void TrackAdapters::scale_covariance(double factor) {
  if (factor > 0.0 && factor < std::numeric_limits<double>::infinity()) estimator_->scale_covariance(factor);
}

}  // namespace trackflow
