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
    const int n = static_cast<int>(in.value.size());
    if ((n != 3 && n != 4) || in.covariance.rows() != n || in.covariance.cols() != n) {
      convert_any(in);
      return;
    }
    // Everything but the value and covariance as in `in` (not a copy of the whole item: the
    // two are rewritten below, in fixed-size arithmetic).
    m_.time = in.time;
    m_.sensor = in.sensor;
    m_.frame = Frame::Cartesian;
    m_.azimuth = in.azimuth;
    m_.mode = in.mode;
    m_.valid = in.valid;
    m_.has_range_rate = in.has_range_rate;
    m_.has_snr = in.has_snr;
    m_.snr_db = in.snr_db;
    m_.origin = in.origin;
    m_.sensor_position = in.sensor_position;
    // spherical_to_enu and spherical_to_enu_jacobian (geometry.hpp) written out on one set of
    // sines and cosines, from glibc's sincos (which the compiler made of their sin and cos calls
    // before, and may not do here): the same expressions, the same bits.
    double saz, caz, se, ce;
    ::sincos(az, &saz, &caz);
    ::sincos(el, &se, &ce);
    const AzimuthBasis b = in.azimuth == AzimuthConvention::NorthClockwise ? AzimuthBasis{saz, caz, caz, -saz}
                                                                           : AzimuthBasis{caz, saz, -saz, caz};
    m_.value.resize(n);
    m_.value.head<3>() = Vec3(r * ce * b.east, r * ce * b.north, r * se) + in.sensor_position;
    Mat3 J;
    J << ce * b.east, r * ce * b.d_east, -r * se * b.east,
         ce * b.north, r * ce * b.d_north, -r * se * b.north,
         se, 0.0, r * ce;
    m_.covariance.resize(n, n);
    if (n == 4) {
      m_.value(3) = in.value(3);
      Eigen::Matrix4d J4 = Eigen::Matrix4d::Identity();
      J4.topLeftCorner<3, 3>() = J;
      const Eigen::Matrix4d R = in.covariance.topLeftCorner<4, 4>();
      const Eigen::Matrix4d JR = J4 * R;
      const Eigen::Matrix4d C = JR * J4.transpose();
      // J R J' is symmetric only up to rounding; downstream Cholesky factorisations want it exact.
      m_.covariance.topLeftCorner<4, 4>() = 0.5 * (C + C.transpose());
    } else {
      // J R J' with every sum from left to right (as the 3x3 blocks of the general product
      // below add them, so the result is the same to the bit).
      const Mat3 R = in.covariance.topLeftCorner<3, 3>();
      Mat3 JR, C;
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) JR(i, k) = J(i, 0) * R(0, k) + J(i, 1) * R(1, k) + J(i, 2) * R(2, k);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) C(i, j) = JR(i, 0) * J(j, 0) + JR(i, 1) * J(j, 1) + JR(i, 2) * J(j, 2);
      m_.covariance.topLeftCorner<3, 3>() = 0.5 * (C + C.transpose());
    }
    out.emit(m_);
  }

 private:
  // Any other shape (not produced by the in-tree radars): the general products, as before.
  void convert_any(const Measurement& in) {
    const double r = in.value(0), az = in.value(1), el = in.value(2);
    m_ = in;
    m_.frame = Frame::Cartesian;
    const int n = static_cast<int>(in.value.size());
    m_.value.resize(n);
    m_.value.head<3>() = spherical_to_enu(r, az, el, in.azimuth) + in.sensor_position;
    Eigen::Matrix<double, 4, 4> J = Eigen::Matrix<double, 4, 4>::Identity();
    J.topLeftCorner<3, 3>() = spherical_to_enu_jacobian(r, az, el, in.azimuth);
    m_.covariance = J.topLeftCorner<3, 3>() * in.covariance * J.topLeftCorner<3, 3>().transpose();
    m_.covariance = 0.5 * (m_.covariance + m_.covariance.transpose()).eval();
    out.emit(m_);
  }

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
