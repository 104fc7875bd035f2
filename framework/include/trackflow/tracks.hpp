// Purpose: TrackSet — what a tracker knows at one time: tracks with stable ids, a status, an Estimate and a score.
#pragma once

#include <trackflow/items.hpp>

#include <cstdint>
#include <limits>
#include <span>

namespace trackflow {

// tentative: initiated, not yet confirmed; confirmed: reported; coasting: confirmed but missed in
// the latest look; deleted: published once, in the set of the time it was dropped, then never again.
enum class TrackStatus : std::uint8_t { Tentative, Confirmed, Coasting, Deleted };
const char* to_string(TrackStatus s);

struct TrackEstimate {
  std::uint64_t id = 0;  // unique within a run, never reused
  TrackStatus status = TrackStatus::Tentative;
  // The track score: tracker.multi's log-likelihood ratio of target against false alarms
  // (tracker.hpp, track_score); NaN when the tracker keeps none.
  double score = 0.0;
  // The probability that the track is a target (JIPDA); NaN when the tracker keeps none.
  double existence = std::numeric_limits<double>::quiet_NaN();
  int hits = 0;    // detections used so far
  int misses = 0;  // consecutive looks without one
  Estimate estimate;
};

// ItemKind::Tracks. The tracks are owned by the emitting node and valid only during the delivery.
struct TrackSet {
  double time = 0.0;
  std::span<const TrackEstimate> tracks;
};

}  // namespace trackflow
