// Purpose: the Monte Carlo consistency study of the convert.* plugins (fixed-truth bias and NEES), shared by its test and convert-consistency.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/items.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace trackflow::conversion {

struct StudyGeometry {
  std::string name;
  double range = 0.0, azimuth = 0.0, elevation = 0.0;            // the fixed truth, sensor-relative
  double sigma_range = 0.0, sigma_azimuth = 0.0, sigma_elevation = 0.0;
  AzimuthConvention convention = AzimuthConvention::NorthClockwise;
  Vec3 sensor_position = Vec3::Zero();
  // The classical conversion's bias relative to its range noise grows like r σ² / σ_r.
  double nonlinearity() const {
    const double s2 = std::max(sigma_azimuth * sigma_azimuth, sigma_elevation * sigma_elevation);
    return range * s2 / sigma_range;
  }
};

// The two geometries of the acceptance check (issue 3): classical known to fail, and all agree.
inline std::vector<StudyGeometry> standard_geometries() {
  const double deg = 3.14159265358979323846 / 180.0;
  const Vec3 sensor(1500.0, -2500.0, 40.0);
  return {
      {"A: r 100 km, σ_angle 2°, σ_r 10 m", 100e3, 40 * deg, 20 * deg, 10.0, 2 * deg, 2 * deg,
       AzimuthConvention::NorthClockwise, sensor},
      {"B: r 10 km, σ_angle 1 mrad, σ_r 10 m", 10e3, 40 * deg, 20 * deg, 10.0, 1e-3, 1e-3,
       AzimuthConvention::NorthClockwise, sensor},
  };
}

struct StudyRow {
  std::string converter;
  std::string geometry;
  std::uint64_t draws = 0;
  Vec3 mean_error = Vec3::Zero();       // mean of (converted - truth), m
  Vec3 bias_in_se = Vec3::Zero();       // mean error / its standard error, per axis
  double bias_mahalanobis = 0.0;        // N ē' S⁻¹ ē (Hotelling T², ~χ²(3) when unbiased)
  double nees_per_dim = 0.0;            // mean of e' R⁻¹ e / 3 with R the converter's own covariance
  std::uint64_t not_positive_definite = 0;  // draws whose R had no Cholesky factor (left out of NEES)
};

// Accumulates the errors of one converter's output against the fixed truth.
class ErrorAccumulator final : public Component {
 public:
  explicit ErrorAccumulator(Vec3 truth) : truth_(std::move(truth)) {}
  void on_measurement(const Measurement& m, int) override {
    const Vec3 e = m.value.head<3>() - truth_;
    sum_ += e;
    sum_sq_ += e * e.transpose();
    const Eigen::LLT<Mat3> llt(Mat3(m.covariance.topLeftCorner<3, 3>()));
    if (llt.info() == Eigen::Success) {
      nees_sum_ += e.dot(llt.solve(e));
      ++nees_count_;
    } else {
      ++not_pd_;
    }
    ++count_;
  }
  StudyRow row(const std::string& converter, const std::string& geometry) const {
    StudyRow r;
    r.converter = converter;
    r.geometry = geometry;
    r.draws = count_;
    const double n = static_cast<double>(count_);
    r.mean_error = sum_ / n;
    const Mat3 S = (sum_sq_ - n * r.mean_error * r.mean_error.transpose()) / (n - 1.0);
    r.bias_in_se = r.mean_error.cwiseQuotient((S.diagonal() / n).cwiseSqrt());
    r.bias_mahalanobis = n * r.mean_error.dot(S.ldlt().solve(r.mean_error));
    r.nees_per_dim = nees_count_ > 0 ? nees_sum_ / static_cast<double>(nees_count_) / 3.0 : 0.0;
    r.not_positive_definite = not_pd_;
    return r;
  }

 private:
  Vec3 truth_;
  Vec3 sum_ = Vec3::Zero();
  Mat3 sum_sq_ = Mat3::Zero();
  double nees_sum_ = 0.0;
  std::uint64_t nees_count_ = 0, not_pd_ = 0, count_ = 0;
};

using ComponentFactory = std::function<std::shared_ptr<Component>(const std::string& type)>;

// The study's measurement template: spherical, the geometry's sensor and covariance.
inline Measurement study_measurement(const StudyGeometry& g) {
  Measurement m;
  m.frame = Frame::Spherical;
  m.azimuth = g.convention;
  m.sensor_position = g.sensor_position;
  m.value.resize(3);
  m.covariance = MeasCov::Zero(3, 3);
  m.covariance.diagonal() << g.sigma_range * g.sigma_range, g.sigma_azimuth * g.sigma_azimuth,
      g.sigma_elevation * g.sigma_elevation;
  return m;
}

// One noisy look at the fixed truth; the draw order (r, az, el) fixes the sequence for a seed.
inline void draw_measurement(Measurement& m, const StudyGeometry& g, Rng& rng) {
  m.value << g.range + g.sigma_range * rng.normal(), wrap_angle(g.azimuth + g.sigma_azimuth * rng.normal()),
      g.elevation + g.sigma_elevation * rng.normal();
}

// Each converter of `types` wired to its own accumulator of errors against `truth`.
template <class Accumulator>
struct ConverterBench {
  std::vector<std::shared_ptr<Component>> converters;
  std::vector<std::unique_ptr<Accumulator>> sinks;
  std::vector<Link> links;
  template <class Factory>
  ConverterBench(const Factory& make, const std::vector<std::string>& types, const Vec3& truth) : links(types.size()) {
    for (std::size_t i = 0; i < types.size(); ++i) {
      converters.push_back(make(types[i]));
      sinks.push_back(std::make_unique<Accumulator>(truth));
      links[i] = {sinks[i].get(), 0, 0xFF};
      converters[i]->out.connect(&links[i], 1);
    }
  }
  void feed(const Measurement& m) {
    for (auto& c : converters) c->on_measurement(m, 0);
  }
};

// Feeds the same `draws` noisy measurements of the fixed truth (Rng seeded with `seed`) through
// every converter in `types`, so the rows are paired comparisons.
inline std::vector<StudyRow> run_study(const ComponentFactory& make, const std::vector<std::string>& types,
                                       const StudyGeometry& g, std::uint64_t draws, std::uint64_t seed) {
  const Vec3 truth = g.sensor_position + spherical_to_enu(g.range, g.azimuth, g.elevation, g.convention);
  ConverterBench<ErrorAccumulator> bench(make, types, truth);
  Measurement m = study_measurement(g);
  Rng rng(seed);
  for (std::uint64_t k = 0; k < draws; ++k) {
    m.time = static_cast<double>(k);
    draw_measurement(m, g, rng);
    bench.feed(m);
  }
  std::vector<StudyRow> rows;
  for (std::size_t i = 0; i < types.size(); ++i) rows.push_back(bench.sinks[i]->row(types[i], g.name));
  return rows;
}

inline const std::vector<std::string>& study_converters() {
  static const std::vector<std::string> types = {"convert.classical", "convert.debiased", "convert.unbiased",
                                                 "convert.unbiased_modified"};
  return types;
}

// One Markdown table for all rows.
inline std::string markdown_table(const std::vector<StudyRow>& rows) {
  std::string s =
      "| geometry | converter | mean error x, y, z [m] | bias x, y, z [SE] | bias 3-D (T², χ²₃) | NEES/dim |\n"
      "|---|---|---|---|---|---|\n";
  char buf[512];
  for (const auto& r : rows) {
    std::snprintf(buf, sizeof buf, "| %s | `%s` | %.2f, %.2f, %.2f | %+.2f, %+.2f, %+.2f | %.1f | %.3f%s |\n",
                  r.geometry.c_str(), r.converter.c_str(), r.mean_error(0), r.mean_error(1), r.mean_error(2),
                  r.bias_in_se(0), r.bias_in_se(1), r.bias_in_se(2), r.bias_mahalanobis, r.nees_per_dim,
                  r.not_positive_definite ? " (some R not PD)" : "");
    s += buf;
  }
  return s;
}

}  // namespace trackflow::conversion
