// Purpose: the data items that flow through a pipeline: Truth, the sensor frame and detection a Measurement is made of, Estimate (Scan: scan.hpp, TrackSet: tracks.hpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <string>

namespace trackflow {

// Largest state a filter may publish and largest measurement vector. Storage is inline
// (Eigen's MaxRows) so items never touch the heap.
inline constexpr int kMaxStateDim = 16;
inline constexpr int kMaxMeasDim = 6;
// Named per-estimate values adapters publish (a quality grade, an adapted sigma): at most this
// many per filter, over all its adapters.
inline constexpr int kMaxAnnotations = 8;

using StateVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxStateDim, 1>;
using StateCov = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxStateDim, kMaxStateDim>;
using MeasVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxMeasDim, 1>;
using MeasCov = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxMeasDim, kMaxMeasDim>;
using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// Scan: one look of one sensor with 0..N detections (scan.hpp); Tracks: a tracker's TrackSet (tracks.hpp).
enum class ItemKind : std::uint8_t { Truth = 1, Measurement = 2, Estimate = 4, Scan = 8, Tracks = 16 };
using ItemMask = std::uint8_t;
constexpr ItemMask mask(ItemKind k) { return static_cast<ItemMask>(k); }
constexpr ItemMask operator|(ItemKind a, ItemKind b) { return mask(a) | mask(b); }
inline constexpr ItemKind kItemKinds[] = {ItemKind::Truth, ItemKind::Measurement, ItemKind::Estimate, ItemKind::Scan,
                                          ItemKind::Tracks};
const char* to_string(ItemKind k);

// Target state in the pipeline's local ENU frame (x east, y north, z up), metres and seconds.
struct Truth {
  double time = 0.0;
  std::uint32_t target = 0;
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
};

// Spherical: value = [range, azimuth, elevation(, range_rate)].
// Cartesian: value = [x, y, z(, range_rate)] in the ENU frame (origin included).
// Polar: value = [range, azimuth(, range_rate)], a 2-D surveillance radar (no elevation).
// Planar: value = [x, y] in the ENU frame, a position sensor of the plane z = 0.
// The values are bits, so a FrameMask names several and a Frame is the mask of itself.
enum class Frame : std::uint8_t { Spherical = 1, Cartesian = 2, Polar = 4, Planar = 8 };
// The measurement frames a component accepts or produces (ComponentDecl), as a bit mask.
using FrameMask = std::uint8_t;
constexpr FrameMask mask(Frame f) { return static_cast<FrameMask>(f); }
inline constexpr FrameMask kAnyFrame = 0xFF;
inline constexpr Frame kFrames[] = {Frame::Spherical, Frame::Cartesian, Frame::Polar, Frame::Planar};
const char* to_string(Frame f);
// The frames of a mask for messages: "spherical/cartesian", or "no".
std::string frame_names(FrameMask m);

// How many position values a detection of frame f has before its optional range rate: 3, or 2
// for the 2-D frames (Polar, Planar).
constexpr int position_values(Frame f) { return f == Frame::Polar || f == Frame::Planar ? 2 : 3; }
// Whether value(1) is an azimuth (Spherical, Polar): residuals against it are wrapped.
constexpr bool has_azimuth(Frame f) { return f == Frame::Spherical || f == Frame::Polar; }

// north_clockwise: compass bearing, x = r cos(el) sin(az), y = r cos(el) cos(az).
// x_counterclockwise: mathematical angle from x (east) toward y (north).
enum class AzimuthConvention : std::uint8_t { NorthClockwise, XCounterClockwise };

enum class MeasMode : std::uint8_t { Unknown, Skin, Beacon };

// Where a sensor is and how it measures: shared by every detection of one look.
struct SensorFrame {
  std::uint32_t sensor = 0;
  Frame frame = Frame::Spherical;
  AzimuthConvention azimuth = AzimuthConvention::NorthClockwise;
  // sensor_axes is the identity: consumers skip the rotation, so level sensors give bit-for-bit
  // the results they always did.
  bool sensor_level = true;
  Vec3 sensor_position = Vec3::Zero();  // sensor location in the ENU frame
  // The sensor's own east, north and up axes (columns, in the frame's axes): its azimuth and
  // elevation are measured from its own horizon, d_sensor = sensor_axes' d_frame. A radar at a
  // geodetic site away from the frame's origin is tilted against the frame (1 deg of arc per
  // ~111 km). Consumers that do not rotate refuse a tilted sensor (require_level_sensor, geometry.hpp).
  Mat3 sensor_axes = Mat3::Identity();
};

// Origin labels of a detection (Detection::origin), besides a truth target id. They are for
// scoring only (track purity, set metrics): no estimator may read them.
inline constexpr std::uint32_t kOriginUnknown = 0xFFFFFFFFu;  // recorded data: nobody knows
inline constexpr std::uint32_t kOriginClutter = 0xFFFFFFFEu;  // a false alarm of a simulation

// What a sensor reported about one object in one look, in its SensorFrame.
struct Detection {
  MeasMode mode = MeasMode::Unknown;
  bool has_range_rate = false;  // last element of value is range rate
  bool has_snr = false;
  double snr_db = 0.0;
  std::uint32_t origin = kOriginUnknown;  // the truth target id that caused it, or kOriginClutter
  MeasVec value;
  MeasCov covariance;
};

// One detection with its sensor frame and time: the single-detection shorthand every filter,
// converter and sink takes. A const Measurement& binds to const SensorFrame& and const
// Detection& without a copy, so the per-track estimators (estimator.hpp) see scans and
// measurements alike.
struct Measurement : SensorFrame, Detection {
  double time = 0.0;
  bool valid = true;  // false: radar not locked / data flagged; filters coast

  int position_dim() const { return position_values(frame); }
};

// Names and units of a filter's state components, in the order of Estimate::state.
struct StateComponent {
  const char* name;
  const char* unit;
};
struct StateLayout {
  const StateComponent* components = nullptr;
  int dim = 0;
  // Position of the component named `name`, or -1: sinks look state up by name, never by index.
  int index_of(const char* name) const {
    for (int i = 0; i < dim; ++i)
      if (components && components[i].name && std::strcmp(components[i].name, name) == 0) return i;
    return -1;
  }
};

// What a filter publishes after each step. Whatever the filter's own state (Cartesian CV/CA,
// spherical, ...), it also fills the ENU position/velocity block so metrics and sinks need
// no knowledge of the state layout.
struct Estimate {
  double time = 0.0;
  std::uint32_t target = 0;    // the truth target a sink scores this estimate against
  bool updated = false;        // false: prediction only (coasting, invalid measurement)
  bool initialised = false;    // false while the filter is still collecting its first points
  StateVec state;
  StateCov covariance;
  Vec6 enu;                    // [x y z vx vy vz]
  Mat6 enu_covariance;
  MeasVec innovation;          // empty when not updated
  MeasCov innovation_covariance;
  double nis = 0.0;            // innovation' S^-1 innovation, valid when updated
  // Values the filter's adapters publish, in the order of the names sinks receive in
  // InputInfo::annotations; NaN: no value (yet).
  double annotations[kMaxAnnotations] = {};
  int annotation_count = 0;
};

// What a filter publishes while it is still collecting its first points: flagged, with a
// zero state of the filter's size and no innovation (never the previous run's values).
inline void set_uninitialised(Estimate& e, double time) {
  e.time = time;
  e.updated = false;
  e.initialised = false;
  e.state.setZero();
  e.covariance.setZero();
  e.enu.setZero();
  e.enu_covariance.setZero();
  e.innovation.resize(0);
  e.innovation_covariance.resize(0, 0);
  e.nis = 0.0;
}

}  // namespace trackflow
