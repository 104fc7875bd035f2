// Purpose: default behaviour of the SDK base classes and names of the SDK enums.
#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/registry.hpp>

namespace trackflow {

namespace detail {
thread_local constinit Component* executing = nullptr;
// Set by the engine (host/guard.hpp) for the threads of one ensemble.
thread_local const std::string* output_dir = nullptr;
}  // namespace detail

const std::string& output_directory() {
  static const std::string none;
  return detail::output_dir ? *detail::output_dir : none;
}

const char* to_string(ItemKind k) {
  switch (k) {
    case ItemKind::Truth: return "truth";
    case ItemKind::Measurement: return "measurement";
    case ItemKind::Estimate: return "estimate";
    case ItemKind::Scan: return "scan";
    case ItemKind::Tracks: return "tracks";
  }
  return "?";
}

const char* to_string(Frame f) {
  switch (f) {
    case Frame::Spherical: return "spherical";
    case Frame::Cartesian: return "cartesian";
    case Frame::Polar: return "polar (range-azimuth)";
    case Frame::Planar: return "planar (x-y)";
  }
  return "unknown";
}

std::string frame_names(FrameMask m) {
  std::string out;
  for (Frame f : kFrames)
    if (m & mask(f)) out += (out.empty() ? "" : "/") + std::string(to_string(f));
  return out.empty() ? "no" : out;
}

const char* to_string(ComponentKind k) {
  switch (k) {
    case ComponentKind::Source: return "source";
    case ComponentKind::Converter: return "converter";
    case ComponentKind::Filter: return "filter";
    case ComponentKind::Adapter: return "adapter";
    case ComponentKind::Sink: return "sink";
    case ComponentKind::Tracker: return "tracker";
    case ComponentKind::Associator: return "associator";
    case ComponentKind::Initiator: return "initiator";
    case ComponentKind::Deleter: return "deleter";
  }
  return "?";
}

// The graph builder checks item kinds against each declaration, so reaching these means a
// plugin declared `accepts` it does not implement.
void Component::on_truth(const Truth&, int) { throw std::logic_error("component received truth it does not handle"); }
void Component::on_measurement(const Measurement&, int) {
  throw std::logic_error("component received a measurement it does not handle");
}
void Component::on_estimate(const Estimate&, int) { throw std::logic_error("component received an estimate it does not handle"); }
void Component::on_scan(const Scan&, int) { throw std::logic_error("component received a scan it does not handle"); }
void Component::on_tracks(const TrackSet&, int) { throw std::logic_error("component received a track set it does not handle"); }

const char* to_string(TrackStatus s) {
  switch (s) {
    case TrackStatus::Tentative: return "tentative";
    case TrackStatus::Confirmed: return "confirmed";
    case TrackStatus::Coasting: return "coasting";
    case TrackStatus::Deleted: return "deleted";
  }
  return "?";
}

void Adapter::before_update(const Measurement&, Filter&) {}
void Adapter::after_update(const Measurement&, const Estimate&, Filter&) {}

}  // namespace trackflow
