// Purpose: the true ENU state at an estimate's time: a sample within tolerance, else linear interpolation.
#pragma once

#include <trackflow/items.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace trackflow::metrics {

inline bool truth_before(const Truth& a, const Truth& b) {
  return a.target < b.target || (a.target == b.target && a.time < b.time);
}

// Keeps samples ordered by (target, time). They normally arrive in that order, so this is an
// append; the insert path only runs for interleaved targets or out-of-order sources.
inline void insert_truth(std::vector<Truth>& samples, const Truth& t) {
  if (samples.empty() || !truth_before(t, samples.back())) {
    samples.push_back(t);
    return;
  }
  samples.insert(std::upper_bound(samples.begin(), samples.end(), t, truth_before), t);
}

// The samples an item of `target` is compared with. With a single truth target the ids are
// ignored, because filters need not number their track the way the simulator numbers its target.
struct TruthSpan {
  const Truth* begin = nullptr;
  const Truth* end = nullptr;
};
inline TruthSpan truth_for(const std::vector<Truth>& samples, std::uint32_t target) {
  if (samples.empty()) return {};
  const Truth* b = samples.data();
  const Truth* e = b + samples.size();
  if (samples.front().target == samples.back().target) return {b, e};
  auto lo = std::lower_bound(b, e, target, [](const Truth& t, std::uint32_t id) { return t.target < id; });
  auto hi = std::upper_bound(lo, e, target, [](std::uint32_t id, const Truth& t) { return id < t.target; });
  return {lo, hi};
}
inline bool single_target(const std::vector<Truth>& samples) {
  return samples.empty() || samples.front().target == samples.back().target;
}

// truth_at's answer once `it`, the first sample at or after t - tolerance, is known (a caller
// that has already found it need not search again).
inline bool truth_from(TruthSpan span, const Truth* it, double t, double tolerance, Vec6& state) {
  if (it != span.end && it->time <= t + tolerance) {
    const Truth* best = it;
    for (const Truth* p = it + 1; p != span.end && p->time <= t + tolerance; ++p)
      if (std::abs(p->time - t) < std::abs(best->time - t)) best = p;
    state << best->position, best->velocity;
    return true;
  }
  if (it == span.begin || it == span.end) return false;
  const Truth& a = *(it - 1);
  const Truth& b = *it;
  const double w = (t - a.time) / (b.time - a.time);
  state << a.position + w * (b.position - a.position), a.velocity + w * (b.velocity - a.velocity);
  return true;
}

// [position; velocity] at time t: the closest sample within `tolerance`, else linear
// interpolation between the two samples that bracket t. False outside the span of the samples.
//
// `from` (optional) is for a caller that looks up nondecreasing times in samples known to be in
// time order (no NaN time): the previous lookup's position, from which the first sample at or
// after t - tolerance is found by a forward walk -- the sample the binary search finds, in one
// or two steps at a fixed rate. A lookup earlier than the last falls back to the binary search.
inline bool truth_at(TruthSpan span, double t, double tolerance, Vec6& state, const Truth** from = nullptr) {
  if (span.begin == span.end) return false;
  const double lo = t - tolerance;
  const Truth* it;
  if (from && *from && *from >= span.begin && *from <= span.end && (*from == span.begin || (*from - 1)->time < lo)) {
    it = *from;
    while (it != span.end && it->time < lo) ++it;
  } else {
    it = std::lower_bound(span.begin, span.end, lo, [](const Truth& s, double time) { return s.time < time; });
  }
  if (from) *from = it;
  return truth_from(span, it, t, tolerance, state);
}

}  // namespace trackflow::metrics
