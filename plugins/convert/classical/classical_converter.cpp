// Purpose: convert.classical — spherical to Cartesian measurement, covariance by the exact Jacobian.
#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>

#include <cmath>

namespace trackflow {
namespace {

// z_c = p(r, az, el) + sensor position; R_c = J R_s J' with J = dp/d(r, az, el) at the
// measured point (Bar-Shalom, Li & Kirubarajan 2001 §10.4.3). Range rate, when present, is
// carried unchanged as the 4th element with its variance and its covariance with (r, az, el)
// mapped through J.
class ClassicalConverter final : public Component {
 public:
  void on_measurement(const Measurement& in, int) override {
    if (in.frame == Frame::Cartesian || !in.valid) {
      out.emit(in);  // already Cartesian, or nothing to convert: pass on unchanged
      return;
    }
    if (!in.sensor_level) throw DataError("convert.classical: " + tilted_sensor_message(in));
    const double r = in.value(0), az = in.value(1), el = in.value(2);
    m_ = in;
    m_.frame = Frame::Cartesian;
    const int n = static_cast<int>(in.value.size());
    m_.value.resize(n);
    m_.value.head<3>() = spherical_to_enu(r, az, el, in.azimuth) + in.sensor_position;
    Eigen::Matrix<double, 4, 4> J = Eigen::Matrix<double, 4, 4>::Identity();
    J.topLeftCorner<3, 3>() = spherical_to_enu_jacobian(r, az, el, in.azimuth);
    if (n == 4) {
      m_.value(3) = in.value(3);
      m_.covariance = J * in.covariance * J.transpose();
    } else {
      m_.covariance = J.topLeftCorner<3, 3>() * in.covariance * J.topLeftCorner<3, 3>().transpose();
    }
    // J R J' is symmetric only up to rounding; downstream Cholesky factorisations want it exact.
    m_.covariance = 0.5 * (m_.covariance + m_.covariance.transpose()).eval();
    out.emit(m_);
  }

 private:
  Measurement m_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "convert.classical";
  d.kind = ComponentKind::Converter;
  d.summary = "Spherical (r, az, el[, rdot]) to Cartesian ENU; covariance J R J' with the exact Jacobian";
  d.doc = "Classical converted measurement. Becomes biased and inconsistent when r*sigma_angle^2/sigma_r grows "
          "(see docs/converters.md). Cartesian inputs pass through unchanged.";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Measurement);
  d.produces_frames = mask(Frame::Cartesian);  // valid measurements; invalid ones pass unconverted
  d.create = [](const Params&) { return std::make_unique<ClassicalConverter>(); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("convert.classical", trackflow::register_components)
