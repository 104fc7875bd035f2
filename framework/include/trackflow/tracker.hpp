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
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
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
  // The probability that the track is a target (JIPDA's existence, Musicki & Evans 2004), as the
  // associator last gave it; NaN when the tracker keeps none (hard association, assoc.pda/jpda
  // without survival_probability). init.existence and delete.existence read it.
  double existence = std::numeric_limits<double>::quiet_NaN();
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
  // Whether the part reads TrackView::existence (init.existence, delete.existence): the tracker
  // then refuses, before the run, an associator that keeps none.
  virtual bool reads_existence() const { return false; }
};

// The answer of a probabilistic associator (PDA, JPDA): for each track, the detections that may be
// its own with their probabilities beta_ij, and the probability beta_i0 that none is (Bar-Shalom,
// Willett & Tian 2011, "Tracking and Data Fusion", sec. 3.4 and 7.x: the association
// probabilities). Entries are added track by track in the tracks' order; storage is kept between
// scans, so a steady scan allocates nothing.
class AssociationProbabilities {
 public:
  struct Entry {
    int detection = 0;
    double probability = 0.0;
  };
  // A new scan with `tracks` tracks, every track's none-probability 1 (no entries).
  void clear(int tracks) {
    entries_.clear();
    first_.assign(static_cast<std::size_t>(tracks) + 1, 0);
    none_.assign(static_cast<std::size_t>(tracks), 1.0);
    existence_.assign(static_cast<std::size_t>(tracks), std::numeric_limits<double>::quiet_NaN());
    last_ = 0;
    initiation_threshold = 0.0;
    exact_clusters = approximate_clusters = unconverged_clusters = 0;
  }
  // Track `track`'s entries: tracks in ascending order, each track's entries together.
  void add(int track, int detection, double probability) {
    if (track < last_ || track >= tracks())
      throw std::logic_error("AssociationProbabilities::add: tracks out of order or out of range");
    while (last_ < track) first_[static_cast<std::size_t>(++last_)] = static_cast<int>(entries_.size());
    entries_.push_back({detection, probability});
  }
  void set_none(int track, double probability) { none_.at(static_cast<std::size_t>(track)) = probability; }
  // An associator that keeps existence (JIPDA) gives each track's posterior existence
  // probability; its entries and none() are then conditioned on the track existing.
  void set_existence(int track, double probability) { existence_.at(static_cast<std::size_t>(track)) = probability; }
  double existence(int track) const { return existence_[static_cast<std::size_t>(track)]; }

  int tracks() const { return static_cast<int>(none_.size()); }
  std::span<const Entry> of(int track) const {
    const int size = static_cast<int>(entries_.size());
    const int b = track <= last_ ? first_[static_cast<std::size_t>(track)] : size;
    const int e = track < last_ ? first_[static_cast<std::size_t>(track) + 1] : size;
    return std::span<const Entry>(entries_).subspan(static_cast<std::size_t>(b), static_cast<std::size_t>(e - b));
  }
  double none(int track) const { return none_[static_cast<std::size_t>(track)]; }

  // A detection whose probability of being some track's (the sum over tracks) is at most this goes
  // to the initiator; the others are the tracks'. 0 (the default): a detection in any track's gate
  // starts no track (MATLAB's trackerJPDA InitializationThreshold, default 0).
  double initiation_threshold = 0.0;
  // How the probabilities were computed this look (JPDA: clusters of competing tracks by exact
  // enumeration, by an approximation such as loopy belief propagation, and approximations that
  // stopped before converging); the tracker sums them into its summary.
  int exact_clusters = 0, approximate_clusters = 0, unconverged_clusters = 0;

 private:
  std::vector<Entry> entries_;
  std::vector<int> first_;  // track t < last_: entries [first_[t], first_[t + 1]); last_: [first_[last_], end)
  std::vector<double> none_, existence_;
  int last_ = 0;
};

// Data association: which detection of the scan each track takes — one (associate), or, for a
// probabilistic associator, each candidate with its probability (associate_probabilities).
class BOOST_SYMBOL_VISIBLE Associator : public TrackerPart {
 public:
  // detection_of_track[i] (sized as tracks) receives the index in scan.detections given to
  // tracks[i], or -1; a detection goes to at most one track. The tracks come in a fixed order
  // (by id), so the answer is the same for any thread count.
  virtual void associate(std::span<const TrackView> tracks, const Scan& scan, std::span<int> detection_of_track) = 0;
  // A probabilistic associator (assoc.pda, assoc.jpda) returns true and implements
  // associate_probabilities; the tracker then calls it instead of associate() and updates each
  // track with all its candidates at once (Estimator::update_weighted). `out` arrives cleared for
  // tracks.size() tracks; each track's probabilities, with none(i), sum to 1. It is called for
  // every look, also one without detections (existence decays through it).
  virtual bool probabilistic() const { return false; }
  // Whether it gives each track's existence (AssociationProbabilities::set_existence: JIPDA).
  virtual bool keeps_existence() const { return false; }
  virtual void associate_probabilities(std::span<const TrackView> /*tracks*/, const Scan& /*scan*/,
                                       AssociationProbabilities& /*out*/) {
    throw std::logic_error("this associator gives no association probabilities");
  }
};

// A new track's first detections: `first` from an earlier scan (time first_time), `second` the
// index of a detection in the current scan; the tracker initiates a fresh estimator with both.
// `score`: the track score L after the two (0: they are the reference the later looks add to).
// velocity_sigma > 0: a one-point start — the detection `second` alone, at rest with velocity
// standard deviation velocity_sigma per axis (Estimator::initiate_one_point; `first` is not used).
// existence: the new track's existence probability (init.existence; NaN: none kept).
struct TrackStart {
  Measurement first;
  int second = -1;
  double score = 0.0;
  double velocity_sigma = 0.0;
  double existence = std::numeric_limits<double>::quiet_NaN();
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
