// Purpose: SDK and plugin ABI version numbers checked when a plugin is loaded.
#pragma once

namespace trackflow {

// Bump kAbiVersion whenever a type that crosses the plugin boundary changes layout or
// a virtual function is added, removed or reordered. The loader refuses mismatches.
inline constexpr int kAbiVersion = 9;  // 9: ParamSpec::plausible_max_abs, implausible_hint; Params::warn (issue 26)
// 8: probabilistic association — Associator::probabilistic, associate_probabilities, AssociationProbabilities; Estimator::takes_weighted_updates, update_weighted, copy_from; TrackView, TrackStart, TrackEstimate::existence (issue 22)
// 7: Frame::Polar and Frame::Planar (2-D measurements); MeasurementSpec::frames is a mask (issue 21)
// 6: Component::on_time_complete, produced_kinds, ComponentDecl::groups_by_time; TrackView::score, peak_score; TrackStart::score (issue 21)
// 5: Measurement = SensorFrame + Detection; Scan and TrackSet items (on_scan, on_tracks); InputInfo::state, time_ordered; ComponentDecl::time_ordered (issue 20)
inline constexpr const char* kSdkVersion = "0.9.0";

}  // namespace trackflow
