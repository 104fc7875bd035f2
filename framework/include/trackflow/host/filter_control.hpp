// Purpose: the engine's side of a Filter and its Adapters — attach, annotation slots, configured noise saved once and put back every run, published-estimate counts — kept out of the SDK a plugin sees.
#pragma once

#include <trackflow/component.hpp>

#include <cstdint>

namespace trackflow::host {

class FilterControl {
 public:
  // Estimates `f` has published since the last call (the engine's measurements_processed).
  static std::uint64_t take_processed(Filter& f) {
    const std::uint64_t n = f.processed_;
    f.processed_ = 0;
    return n;
  }
  // Reserves the filter's own annotation slots (before any attach); false when there is no room.
  static bool reserve_own_annotations(Filter& f, int count) {
    if (f.adapter_count_ > 0 || count < 0 || f.annotation_count_ + count > kMaxAnnotations) return false;
    f.annotation_count_ += count;
    f.own_annotation_count_ += count;
    return true;
  }
  // Attaches `a` with `annotations` values; false when there is no room.
  static bool attach(Filter& f, Adapter& a, int annotations) {
    if (f.adapter_count_ >= Filter::kMaxAdapters || f.annotation_count_ + annotations > kMaxAnnotations) return false;
    a.first_annotation_ = f.annotation_count_;
    f.annotation_count_ += annotations;
    f.adapters_[f.adapter_count_++] = &a;
    return true;
  }
  // The annotation values `f` stamps on its next estimate (what Filter::publish does), for a
  // Filter that is no node and publishes nothing itself (TrackAdapters, a tracker's track).
  static void stamp_annotations(const Filter& f, Estimate& e) {
    e.annotation_count = f.annotation_count_;
    for (int i = 0; i < f.annotation_count_; ++i) e.annotations[i] = f.annotation_values_[i];
  }
  // Remembers the process noise as configured (once, before any run) ...
  static void save_configured_noise(Filter& f) {
    const ProcessNoiseHandle q = f.noise().process;
    f.configured_count_ = q ? (q.count < Filter::kMaxNoiseValues ? q.count : Filter::kMaxNoiseValues) : 0;
    for (int i = 0; i < f.configured_count_; ++i) f.configured_[i] = q.values[i];
  }
  // ... and puts it back, with no annotation values, at the start of every run, so what an
  // adapter tuned in one run never leaks into the next (whichever thread runs it).
  static void reset_adapted_state(Filter& f) {
    const ProcessNoiseHandle q = f.noise().process;
    for (int i = 0; i < f.configured_count_ && q && i < q.count; ++i) q.values[i] = f.configured_[i];
    for (double& v : f.annotation_values_) v = Filter::kNoAnnotation;
  }
};

}  // namespace trackflow::host
