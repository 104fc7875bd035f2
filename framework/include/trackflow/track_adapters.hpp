// Purpose: TrackAdapters — one track's own instances of a tracker's adapters, run over that track's estimator with the hooks, noise, covariance access and annotations they have on a single-track filter node.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/estimator.hpp>
#include <trackflow/params.hpp>

#include <boost/config.hpp>

#include <memory>
#include <string>
#include <vector>

namespace trackflow {

// A new instance of the adapter a nested `{type: adapt..., ...}` entry names (its type's
// ComponentDecl::create, NestedComponent::component_factory). Throws ConfigError at the entry's
// `type:` value when the type is not an adapter.
BOOST_SYMBOL_VISIBLE std::unique_ptr<Adapter> create_adapter(const NestedComponent& entry);

// A tracker that takes adapters (a component-list parameter of kind Adapter, e.g. tracker.multi's
// `adapters:`) keeps one TrackAdapters with each track slot, made when the slot is made and kept
// with it: slots are reused by later tracks and runs, so nothing is allocated per scan once the
// track population is steady. It is the Filter its adapters see: noise() is the track's
// estimator's (Estimator::noise), scale_covariance rescales that estimator's P, annotate() goes
// onto the track's estimates. start_track() puts the estimator's process noise back as configured
// and restarts every adapter (Component::start_run), so what one track's adapters learned never
// reaches the next track of the slot, nor another track, nor another run.
//
// The tracker calls, per measurement the track's estimator uses (initiating ones included), with
// the estimator's R already holding the detection's covariance:
//   before_update(m, dim)   the adapters may replace R and the process noise;
//   (the estimator initiates or updates)
//   after_update(m, e)      e: the track's estimate from it (filled); stamps the adapters' values on
//                           e, then lets the adapters see e — Filter::publish's order.
// The hooks run with the tracker as the executing node (component.hpp, detail::executing), so an
// adapter that throws is reported as the tracker's error.
class BOOST_SYMBOL_VISIBLE TrackAdapters final : public Filter {
 public:
  // One new instance of each entry of `adapters` over `estimator`, which must outlive this object
  // and hold the configured noise (the tracker's prototype or a fresh clone of it). Throws
  // ConfigError at an entry's `type:` value when the estimator does not offer what that adapter
  // needs (noise_mismatch, as for `attach_to:`) or when the adapters do not fit on one track
  // (Filter::kMaxAdapters, kMaxAnnotations). `who` names the tracker in messages.
  TrackAdapters(const std::vector<NestedComponent>& adapters, Estimator& estimator, std::string who);
  ~TrackAdapters() override;
  TrackAdapters(const TrackAdapters&) = delete;
  TrackAdapters& operator=(const TrackAdapters&) = delete;

  // The values a track's estimates carry with these entries, "<adapter type>.<name>" in order
  // (entries in the order given); the host gives them to the tracker's consumers as
  // InputInfo::annotations, prefixed with the tracker's id.
  static std::vector<std::string> annotation_names_of(const std::vector<NestedComponent>& adapters);

  // A new track in this slot, before its first measurement: process noise as configured, no
  // annotation values, every adapter's start_run(ctx), no restart requested.
  void start_track(const RunContext& ctx);
  // Throws DataError when m's frame is one an adapter does not declare (ComponentDecl::accepts_frames)
  // or when an adapter left an R smaller than dim x dim.
  void before_update(const Measurement& m, int dim);
  void after_update(const Measurement& m, Estimate& e);
  // The adapters' current values onto e (annotation_count included): a track's estimate between updates.
  void stamp(Estimate& e) const;
  // Whether an adapter asked to forget the track (restart_track) since start_track.
  bool restart_requested() const { return restart_requested_; }

  NoiseHandles noise() override { return estimator_->noise(); }
  StateLayout state_layout() const override { return estimator_->layout(); }
  const TransitionModel* transition_model() const override { return estimator_->transition_model(); }
  bool has_covariance_access() const override { return true; }
  void read_covariance(StateCov& P) const override;
  // P <- factor P in the estimator's own representation (factor finite and > 0; others ignored).
  void scale_covariance(double factor) override;
  // A tracker does not re-initialise a track in place: it records the request, and the tracker
  // deletes the track (its detections may start a new one).
  void restart_track() override { restart_requested_ = true; }

 private:
  Estimator* estimator_;
  std::string who_;
  std::vector<std::unique_ptr<Adapter>> adapters_;
  std::vector<FrameMask> frames_;   // each adapter's declared measurement frames
  std::vector<std::string> types_;  // and its type, for messages
  mutable Estimate scratch_;        // read_covariance's
  bool restart_requested_ = false;
};

}  // namespace trackflow
