// Purpose: delete.score — a confirmed track is deleted when its log-likelihood-ratio score has fallen score_drop below its peak, or (optionally) when its position uncertainty has grown past max_position_sd.
#include <trackflow/error.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace trackflow {
namespace {

// Blackman & Popoli 1999, §6.2: a track is deleted when its score L has dropped a threshold below
// its maximum, peak - L >= score_drop (the score of a true track rises on average, so a steady
// fall means the target is gone). Covariance growth: a coasting track whose position standard
// deviation sqrt(lambda_max(P_pos)), the largest eigenvalue of the ENU position block of its
// covariance, exceeds max_position_sd no longer says where the target is.
class ScoreDeleter final : public Deleter {
 public:
  ScoreDeleter(double score_drop, double max_position_sd, std::string node)
      : score_drop_(score_drop), max_sd_(max_position_sd), node_(std::move(node)) {}

  bool drop(const TrackView& t) const override {
    if (std::isnan(t.score))
      throw DataError("delete.score (node '" + node_ + "'): track " + std::to_string(t.id) +
                      " has no score: a scan stated no detection probability or no clutter density, which the "
                      "track score needs (sim.scenario states both); use delete.misses");
    if (t.peak_score - t.score >= score_drop_) return true;
    return std::isfinite(max_sd_) && t.estimator && position_sd(*t.estimator) > max_sd_;
  }

 private:
  // The estimator's published covariance (fill: the ENU block for any state layout). `scratch_`
  // is per part, and a tracker (with its parts) is used by one thread at a time.
  double position_sd(const Estimator& e) const {
    e.fill(scratch_);
    const Mat3 P = scratch_.enu_covariance.topLeftCorner<3, 3>();
    const double largest = Eigen::SelfAdjointEigenSolver<Mat3>(P, Eigen::EigenvaluesOnly).eigenvalues()(2);
    return std::sqrt(std::max(largest, 0.0));
  }

  double score_drop_, max_sd_;
  std::string node_;
  mutable Estimate scratch_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  return std::make_unique<ScoreDeleter>(p.real("score_drop"),
                                        p.real_or("max_position_sd", std::numeric_limits<double>::infinity()), p.node());
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "delete.score";
  d.kind = ComponentKind::Deleter;
  d.summary = "Deletes a confirmed track when its score fell score_drop below its peak, or its position standard "
              "deviation exceeds max_position_sd";
  d.doc =
      "The track score L is the log-likelihood ratio the tracker keeps (tracker.multi: per look ln(P_D/beta_FA) + "
      "ln N(nu; 0, S) for a detection used, ln(1 - P_D) for a miss; a scan without P_D or clutter density is "
      "refused). The track is deleted when peak - L >= score_drop, peak the largest L so far (Blackman & Popoli "
      "1999, sec. 6.2): with P_D = 0.9 a miss costs ln 10 = 2.3, so the default 6.5 deletes after three "
      "consecutive misses of a track at its peak. With max_position_sd, also when sqrt of the largest eigenvalue "
      "of the ENU position covariance exceeds it (covariance-growth deletion of a coasting track). A scan with "
      "valid: false is no look. See docs/multi-target.md.";
  d.params = {
      ParamSpec::real("score_drop", Dimension{}, "fall of the score below its peak that deletes a track")
          .def("6.5")
          .positive(),
      ParamSpec::real("max_position_sd", dim::length,
                      "delete a track whose position standard deviation (largest axis) exceeds this")
          .positive(),
  };
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("delete.score", trackflow::register_components)
