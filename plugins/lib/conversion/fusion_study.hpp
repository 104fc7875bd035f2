// Purpose: what a filter makes of the conversions: NEES of n fused conversions of a static target, for convert-consistency.
#pragma once

#include "consistency_study.hpp"

namespace trackflow::conversion {

// For the fusion study: A and B plus the middle ground r σ²/σ_r = 2 (issue 3's long-range pipeline).
inline std::vector<StudyGeometry> fusion_geometries() {
  auto g = standard_geometries();
  StudyGeometry c = g.at(0);
  c.name = "C: r 50 km, σ_angle 20 mrad, σ_r 10 m";
  c.range = 50e3;
  c.sigma_azimuth = c.sigma_elevation = 20e-3;
  return {g.at(0), c, g.at(1)};
}

// What a filter makes of the conversions: `fused` converted measurements of the same static
// target combined by information weighting, x = (Σ R⁻¹)⁻¹ Σ R⁻¹ z — a Kalman filter with no
// process noise. A covariance that depends on the measurement error (every statistical
// conversion's does) biases this weighted mean even when the plain mean is unbiased, so the
// single-measurement NEES does not tell the whole story.
class FusionAccumulator final : public Component {
 public:
  explicit FusionAccumulator(Vec3 truth) : truth_(std::move(truth)) {}
  void on_measurement(const Measurement& m, int) override {
    const Mat3 R = m.covariance.topLeftCorner<3, 3>();
    const Eigen::LLT<Mat3> llt(R);
    if (llt.info() != Eigen::Success) {
      ++not_pd_;
      return;
    }
    const Mat3 R_inv = llt.solve(Mat3::Identity());
    information_ += R_inv;
    information_state_ += R_inv * m.value.head<3>();
  }
  void end_trial() {
    const Eigen::LLT<Mat3> llt(information_);
    if (llt.info() == Eigen::Success) {
      const Vec3 e = llt.solve(information_state_) - truth_;
      nees_sum_ += e.dot(information_ * e);
      ++trials_;
    } else {
      ++not_pd_;
    }
    information_.setZero();
    information_state_.setZero();
  }
  double nees_per_dim() const { return trials_ > 0 ? nees_sum_ / static_cast<double>(trials_) / 3.0 : 0.0; }
  std::uint64_t not_positive_definite() const { return not_pd_; }

 private:
  Vec3 truth_;
  Mat3 information_ = Mat3::Zero();
  Vec3 information_state_ = Vec3::Zero();
  double nees_sum_ = 0.0;
  std::uint64_t trials_ = 0, not_pd_ = 0;
};

struct FusionRow {
  std::string geometry;
  int fused = 0;
  std::vector<double> nees_per_dim;  // one per converter, in the order given
  bool any_not_positive_definite = false;
};

inline FusionRow run_fusion_study(const ComponentFactory& make, const std::vector<std::string>& types,
                                  const StudyGeometry& g, int fused, std::uint64_t trials, std::uint64_t seed) {
  const Vec3 truth = g.sensor_position + spherical_to_enu(g.range, g.azimuth, g.elevation, g.convention);
  ConverterBench<FusionAccumulator> bench(make, types, truth);
  Measurement m = study_measurement(g);
  Rng rng(seed);
  for (std::uint64_t k = 0; k < trials; ++k) {
    for (int j = 0; j < fused; ++j) {
      draw_measurement(m, g, rng);
      bench.feed(m);
    }
    for (auto& s : bench.sinks) s->end_trial();
  }
  FusionRow row{g.name, fused, {}, false};
  for (const auto& s : bench.sinks) {
    row.nees_per_dim.push_back(s->nees_per_dim());
    row.any_not_positive_definite = row.any_not_positive_definite || s->not_positive_definite() > 0;
  }
  return row;
}

inline std::string fusion_markdown_table(const std::vector<std::string>& types, const std::vector<FusionRow>& rows) {
  std::string s = "| geometry | fused |";
  std::string rule = "|---|---|";
  for (const auto& t : types) {
    s += " `" + t + "` |";
    rule += "---|";
  }
  s += "\n" + rule + "\n";
  char buf[64];
  for (const auto& r : rows) {
    s += "| " + r.geometry + " | " + std::to_string(r.fused) + " |";
    for (double v : r.nees_per_dim) {
      std::snprintf(buf, sizeof buf, " %.2f |", v);
      s += buf;
    }
    if (r.any_not_positive_definite) s += " (some R not PD)";
    s += "\n";
  }
  return s;
}

}  // namespace trackflow::conversion
