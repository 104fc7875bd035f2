// Purpose: filter.ekf — extended Kalman filter with a Cartesian ENU state (CV, CA or Singer motion) on spherical [r, az, el(, rdot)] measurements.
#include "cartesian_radar_filter.hpp"
#include "zenith_linearisation.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <string>

namespace trackflow {
namespace {

// Settings, measurement checks, initialisation, prediction and publishing: cartesian_radar_filter.hpp.
// This class is the EKF update: h linearised at the predicted state.
template <int Order>
class ExtendedKalmanFilter final
    : public cartesian_filter::CartesianRadarFilter<Order, ExtendedKalmanFilter<Order>> {
  using Base = cartesian_filter::CartesianRadarFilter<Order, ExtendedKalmanFilter<Order>>;
  friend Base;
  using Base::N;
  using Base::x_;
  using Base::P_;
  using Base::R_;
  using Base::idx_;
  using Layout = typename Base::Layout;

 public:
  explicit ExtendedKalmanFilter(cartesian_filter::Settings s) : Base(std::move(s)) {}

  static std::vector<std::string> counter_names() { return {"azimuth_dropped", "azimuth_deweighted"}; }

 private:
  enum Counter { kAzimuthDropped, kAzimuthDeweighted };

  void on_start_run() { zenith_reported_ = false; }
  void on_end_run_report() {}

  // H = dh/dx is non-zero only in the position columns (and, for the range rate, the velocity
  // columns): P H' and H P H' are formed from those (kalman.hpp, joseph_update_cross), never the
  // M x N H or an N x N x N product.
  template <int M>
  bool correct(const Measurement& m) {
    using MatM = Eigen::Matrix<double, M, M>;
    // In the sensor's own axes (a tilted sensor: Measurement::sensor_axes); J is turned back into
    // the frame's below.
    const Vec3 d = frame_to_sensor(m, Layout::position(x_) - m.sensor_position);
    const Vec3 v = frame_to_sensor(m, Layout::velocity(x_));
    SphericalJacobian<M> J;  // columns [x y z vx vy vz]
    SphericalVec<M> h;
    const SphericalSingularity sing = spherical_measurement_with_jacobian<M>(d, v, m.azimuth, h, J);
    if (sing == SphericalSingularity::AtSensor) {
      this->warn("predicted position at the sensor at t=" + std::to_string(m.time) +
                 " s: no direction to linearise about; measurement not used");
      return false;
    }
    const SphericalVec<M> z = m.value.template head<M>();
    SphericalVec<M> nu = spherical_residual<M>(z, h);
    MatM R = R_.template topLeftCorner<M, M>();
    if (this->settings().zenith == cartesian_filter::Settings::Zenith::Curvature) condition_near_zenith<M>(m, d, sing, J, nu, R);
    if (!m.sensor_level) {  // dh/dx_frame = dh/dd_sensor A' (position and velocity columns)
      const Mat3 At = m.sensor_axes.transpose();
      for (int k = 0; k < M; ++k) {
        const Eigen::RowVector3d jp = J.template block<1, 3>(k, 0) * At;
        J.template block<1, 3>(k, 0) = jp;
        if (k == 3) {
          const Eigen::RowVector3d jv = J.template block<1, 3>(k, 3) * At;
          J.template block<1, 3>(k, 3) = jv;
        }
      }
    }
    // Rows r, az, el depend on the position only; the range rate's also on the velocity.
    Eigen::Matrix<double, N, M> PHt;
    for (int k = 0; k < M; ++k)
      for (int r = 0; r < N; ++r) {
        double s = P_(r, idx_[0]) * J(k, 0) + P_(r, idx_[1]) * J(k, 1) + P_(r, idx_[2]) * J(k, 2);
        if (k == 3) s += P_(r, idx_[3]) * J(k, 3) + P_(r, idx_[4]) * J(k, 4) + P_(r, idx_[5]) * J(k, 5);
        PHt(r, k) = s;
      }
    MatM S;
    for (int k = 0; k < M; ++k)
      for (int l = k; l < M; ++l) {
        const int c = l == 3 ? 6 : 3;  // H P H' = H (P H'): row l of H against column k of P H'
        double s = R(l, k);
        for (int j = 0; j < c; ++j) s += J(l, j) * PHt(idx_[j], k);
        S(l, k) = s;
      }
    double nis = 0.0;
    if (joseph_update_cross<N, M>(x_, P_, nu, PHt, S, nis)) {
      this->template accept_update<M>(nu, S, nis);
      return true;
    }
    this->warn("innovation covariance not positive definite at t=" + std::to_string(m.time) +
               " s; measurement not used");
    return false;
  }

  // Curvature of the angles over the predicted horizontal uncertainty (zenith_linearisation.hpp):
  // negligible at ordinary ranges, it de-weights the azimuth smoothly as the target nears the
  // zenith. When the zenith itself is within 3 sigma of the predicted horizontal position the
  // azimuth may flip by pi and is dropped: zero row, zero innovation, R decorrelated (an
  // infinitely uncertain azimuth; range, elevation and range rate still update).
  template <int M>
  void condition_near_zenith(const Measurement& m, const Vec3& d, SphericalSingularity sing, SphericalJacobian<M>& J,
                             SphericalVec<M>& nu, Eigen::Matrix<double, M, M>& R) {
    Eigen::Matrix2d Ph;
    Ph << P_(idx_[0], idx_[0]), P_(idx_[0], idx_[1]), P_(idx_[1], idx_[0]), P_(idx_[1], idx_[1]);
    if (!m.sensor_level) {  // the horizontal block in the sensor's own axes
      Mat3 Pp;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) Pp(i, j) = P_(idx_[i], idx_[j]);
      Ph = (m.sensor_axes.transpose() * Pp * m.sensor_axes).topLeftCorner<2, 2>();
    }
    const ekf::AngleCurvature curvature = ekf::angle_curvature_variance(d, Ph, kZenithFraction * d.norm());
    const double raz = R(1, 1);
    R(2, 2) += curvature.elevation;
    const bool drop_azimuth = sing == SphericalSingularity::Zenith || curvature.azimuth_unusable;
    if (drop_azimuth) {
      J.row(1).setZero();
      nu(1) = 0.0;
      R.row(1).setZero();
      R.col(1).setZero();
      R(1, 1) = raz > 0.0 ? raz : 1.0;
      this->count(kAzimuthDropped);
    } else {
      R(1, 1) += curvature.azimuth;
      if (curvature.azimuth > raz) this->count(kAzimuthDeweighted);
    }
    if (!zenith_reported_ && (drop_azimuth || curvature.azimuth > raz)) {
      this->warn("target near the zenith at t=" + std::to_string(m.time) + " s: azimuth " +
                 (drop_azimuth ? "not used" : "de-weighted") +
                 " (its linearisation fails over the predicted uncertainty); counted in the summary, reported once "
                 "per run");
      zenith_reported_ = true;
    }
  }

  bool zenith_reported_ = false;
};

std::unique_ptr<Component> create(const Params& p) {
  cartesian_filter::Settings s = cartesian_filter::parse_settings(p, "filter.ekf");
  s.zenith = p.choice<cartesian_filter::Settings::Zenith>("zenith");
  if (s.order() == 2) return std::make_unique<ExtendedKalmanFilter<2>>(s);
  return std::make_unique<ExtendedKalmanFilter<3>>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.ekf";
  d.kind = ComponentKind::Filter;
  d.summary = "Extended Kalman filter: Cartesian ENU state (CV, CA or Singer) on spherical [r, az, el(, rdot)] "
              "measurements";
  d.doc =
      "State [x vx (ax) y vy (ay) z vz (az)] in ENU; linear prediction, measurement h(x) = [r, az, el(, rdot)] "
      "relative to the (stationary) sensor in its azimuth convention, analytic Jacobian (paper 000 eq 3.22-3.24, "
      "corrected), azimuth innovation wrapped to (-pi, pi], Joseph-form update. Motion: CV (white acceleration, q), "
      "CA (Wiener-process acceleration, q_jerk, paper 000 eq 3.19), sigma_accel for the discrete white-noise "
      "variants, or Singer (alpha, sigma_m; exact discretisation). Near the zenith the angles' curvature variance is "
      "added to R and the azimuth is dropped while the zenith is within 3 sigma (zenith: curvature; zenith: textbook "
      "is the plain EKF); dropped and de-weighted azimuths are counted in the summary. Invalid measurements: predict "
      "only. "
      "R from each measurement in spherical space (adapters may replace it; q per ENU axis)."
      " Several inputs (up to 8 radars, each at its own site with its own noise, rate and biases): the measurements are used one after another in time order, equal time stamps in the engine's delivery order (the order of the radars' declaration when they share a truth source); a tilted sensor (a geodetic site away from the frame's origin) is measured in its own axes; the summary then gives updates.<input> and nis_mean.<input> (mean NIS per element with its 95 % chi-square band) per sensor. See docs/filters.md.";
  d.accepts = mask(ItemKind::Measurement);
  // Several radars into one track: one input per sensor (docs/filters.md, "Several sensors").
  d.min_inputs = 1;
  d.max_inputs = FrontEndRunResult::kMaxPorts;
  d.produces = mask(ItemKind::Estimate);
  d.accepts_frames = mask(Frame::Spherical);
  d.params = cartesian_filter::param_specs();
  using Zenith = cartesian_filter::Settings::Zenith;
  d.params.push_back(ParamSpec::choice<Zenith>("zenith", {{Zenith::Curvature, "curvature"}, {Zenith::Textbook, "textbook"}},
                                               "near the zenith: add the angles' curvature variance to R and drop the "
                                               "azimuth within 3 sigma of it (curvature), or the textbook EKF (textbook)")
                         .def("curvature"));
  d.create = create;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.ekf", trackflow::register_components)
