// Purpose: the parts a multi-target tracker is composed of — Associator, Initiator, Deleter — and what they see of a track (TrackView); each part is a plugin type the tracker's YAML names.
#pragma once

#include <trackflow/error.hpp>
#include <trackflow/estimator.hpp>
#include <trackflow/params.hpp>
#include <trackflow/scan.hpp>
#include <trackflow/tracks.hpp>

#include <boost/config.hpp>

#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace trackflow {

// What the parts see of one live track at a scan, after its prediction to the scan's time.
struct TrackView {
  std::uint64_t id = 0;
  TrackStatus status = TrackStatus::Tentative;
  int hits = 0;            // detections used so far (the initiating ones included)
  int misses = 0;          // consecutive looks without one
  int looks = 0;           // scans since the track started (the initiating ones included)
  std::uint64_t history = 0;  // one bit per look, newest in bit 0: 1 = a detection was used
  const Estimator* estimator = nullptr;
  // z^, S and log det S for this scan's sensor; nullptr when the track cannot predict the
  // measurement (S not positive definite): no detection may then be given to it.
  const PredictedMeasurement* predicted = nullptr;
  // The track score L: the log-likelihood ratio of "a target" against "false alarms" of the
  // detections the track used and the looks it missed (track_score below), and its largest value
  // so far. It starts at TrackStart::score; NaN when a scan did not state P_D or its clutter density.
  double score = 0.0;
  double peak_score = 0.0;
};

// The track score's increment per look (Blackman & Popoli 1999, "Design and Analysis of Modern
// Tracking Systems", §6.2, the track score; Blackman 2004, IEEE AES Magazine 19(1) pp. 5-18), kept
// by the tracker, read by the parts (init.score, delete.score) — one formula for all of them.
namespace track_score {
// A look with detection z used: dL = ln(P_D / beta_FA) - (dim ln 2 pi + ln|S| + d^2) / 2, with
// beta_FA the false-alarm density of the measurement space, S the innovation covariance and
// d^2 = nu' S^-1 nu; the second term is ln N(nu; 0, S), the detection's likelihood under the track.
inline double hit(double detection_probability, double clutter_density, double nis, double log_det_S, int dim) {
  constexpr double kLog2Pi = 1.8378770664093454836;  // ln 2 pi
  return std::log(detection_probability) - std::log(clutter_density) - 0.5 * (dim * kLog2Pi + log_det_S + nis);
}
// A look without one: dL = ln(1 - P_D P_G) (P_G: the probability that the target's detection
// falls in the gate; 1 when the tracker knows no gate).
inline double miss(double detection_probability, double gate_probability = 1.0) {
  return std::log1p(-detection_probability * gate_probability);
}
}  // namespace track_score

// The base of every part (ComponentDecl::create_part gives one). Visible, so that a tracker can
// tell the part another plugin made (make_part's dynamic_cast across shared objects).
class BOOST_SYMBOL_VISIBLE TrackerPart {
 public:
  virtual ~TrackerPart() = default;
};

// Data association: which detection of the scan each track takes.
class BOOST_SYMBOL_VISIBLE Associator : public TrackerPart {
 public:
  // detection_of_track[i] (sized as tracks) receives the index in scan.detections given to
  // tracks[i], or -1; a detection goes to at most one track. The tracks come in a fixed order
  // (by id), so the answer is the same for any thread count.
  virtual void associate(std::span<const TrackView> tracks, const Scan& scan, std::span<int> detection_of_track) = 0;
};

// A new track's first detections: `first` from an earlier scan (time first_time), `second` the
// index of a detection in the current scan; the tracker initiates a fresh estimator with both.
// `score`: the track score L after the two (0: they are the reference the later looks add to).
// velocity_sigma > 0: a one-point start — the detection `second` alone, at rest with velocity
// standard deviation velocity_sigma per axis (Estimator::initiate_one_point; `first` is not used).
struct TrackStart {
  Measurement first;
  int second = -1;
  double score = 0.0;
  double velocity_sigma = 0.0;
};

// Track initiation and confirmation.
class BOOST_SYMBOL_VISIBLE Initiator : public TrackerPart {
 public:
  // Called once per scan with the detections no track took (indices into scan.detections, in
  // order). Appends the tracks to start to `starts` (reserved by the tracker; may be left empty)
  // and keeps what it needs of the rest for later scans.
  virtual void initiate(const Scan& scan, std::span<const int> unassigned, std::vector<TrackStart>& starts) = 0;
  // Tentative -> confirmed.
  virtual bool confirmed(const TrackView& track) const = 0;
  // A tentative track that will not be confirmed any more: deleted.
  virtual bool failed(const TrackView& track) const = 0;
  // Whether it makes one-point starts (TrackStart::velocity_sigma > 0): the tracker then refuses,
  // before the run, an estimator that cannot start from one point.
  virtual bool one_point_starts() const { return false; }
  // A new run: forget the detections kept from the previous one.
  virtual void reset() = 0;
};

// Deletion of confirmed (and coasting) tracks.
class BOOST_SYMBOL_VISIBLE Deleter : public TrackerPart {
 public:
  virtual bool drop(const TrackView& track) const = 0;
};

// The part a nested `{type: ...}` parameter names, created by its plugin (the host sets the
// factory at validation). Throws ConfigError at the `type:` value when that type is not a `Part`.
template <class Part>
std::unique_ptr<Part> make_part(const NestedComponent& c, const char* what) {
  if (!c.part_factory)
    throw ConfigError(c.type + " is not a tracker part (" + what + ")", c.type_where, c.params.node());
  std::unique_ptr<TrackerPart> p = c.part_factory(c.params);
  if (auto* typed = dynamic_cast<Part*>(p.get())) {
    p.release();
    return std::unique_ptr<Part>(typed);
  }
  throw ConfigError(c.type + " is not " + what, c.type_where, c.params.node());
}

}  // namespace trackflow
