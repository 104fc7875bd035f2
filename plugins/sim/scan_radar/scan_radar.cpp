// Purpose: sim.scan_radar — a radar in scan mode: per instant one Scan of every target in its coverage, detected with P_D (constant, Swerling 0 or I from SNR), spherical noise, Poisson clutter uniform over its range–azimuth(–elevation) cells, optional merged unresolved plots; 3-D or 2-D (range, azimuth).
#include "detection_models.hpp"
#include "simulation/detection_order.hpp"
#include "simulation/poisson.hpp"

#include <trackflow/common_params.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/scan.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace trackflow {
namespace {

using scan_radar::pd_swerling0;
using scan_radar::pd_swerling1;
using scan_radar::snr_at_range;
using simulation::poisson;

enum class DetectionModel { Constant, Swerling0, Swerling1 };
// What a plot measures: range, azimuth and elevation, or a 2-D surveillance radar's range and azimuth.
enum class Measures { RangeAzimuthElevation, RangeAzimuth };
constexpr double kTwoPi = 2.0 * std::numbers::pi;

struct Settings {
  SensorFrame sensor;
  Vec3 sigma = Vec3::Zero();  // range m, azimuth rad, elevation rad
  DetectionModel model = DetectionModel::Constant;
  double pd = 1.0, pfa = 1e-6, snr_reference_db = 20.0, snr_reference_range = 100e3;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // coverage [range, azimuth, elevation]; azimuth hi may pass +pi
  double clutter_mean = 0.0;
  bool merge = false;
  Vec3 resolution = Vec3::Zero();  // range resolution, azimuth and elevation beamwidths
  // Measured dimensions: 3 (r, az, el) or 2 (r, az; Frame::Polar). A 2-D radar's fan beam covers
  // [elevation_min, elevation_max] but does not resolve elevation: cells, clutter and merging are in
  // (r, az) only.
  int dims = 3;
};

struct ScanRadarRunResult final : RunResult {
  std::uint64_t looks = 0, in_coverage = 0, outside = 0, detections = 0, missed = 0, clutter = 0, merged = 0;
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.looks, r.in_coverage, r.outside, r.detections, r.missed, r.clutter, r.merged);
  }
};

// A target at one instant as the radar sees it before noise.
struct Echo {
  std::uint32_t target = 0;
  Vec3 rae = Vec3::Zero();
  bool merged = false;  // taken into an earlier echo's plot
};

double cell_count(const Settings& s) {
  double n = 1.0;
  for (int i = 0; i < s.dims; ++i) n *= (s.hi[i] - s.lo[i]) / s.resolution[i];
  return n;
}

// The coverage's volume in measurement space: m rad² (3-D) or m rad (2-D).
double coverage_volume(const Settings& s) {
  double v = 1.0;
  for (int i = 0; i < s.dims; ++i) v *= s.hi[i] - s.lo[i];
  return v;
}

Settings read_settings(const Params& p) {
  Settings s;
  s.sensor.frame = Frame::Spherical;
  if (p.choice<Measures>("measures") == Measures::RangeAzimuth) {
    s.dims = 2;
    s.sensor.frame = Frame::Polar;
    for (const char* name : {"sigma_elevation", "beamwidth_elevation", "clutter_density"})
      if (p.given(name))
        throw p.error(name, std::string("has no use with 'measures: range_azimuth' (a 2-D radar measures no elevation)") +
                                (std::string(name) == "clutter_density" ? "; give clutter_rate (per scan)" : ""));
  }
  s.sensor.sensor = static_cast<std::uint32_t>(p.integer("sensor_id"));
  s.sensor.azimuth = p.choice<AzimuthConvention>("azimuth_convention");
  s.sensor.sensor_position = p.vec3("position");
  s.sigma = {p.real("sigma_range"), p.real("sigma_azimuth"), p.real("sigma_elevation")};
  s.model = p.choice<DetectionModel>("detection_model");
  s.pd = p.real("detection_probability");
  s.pfa = p.real("false_alarm_probability");
  s.snr_reference_db = p.real("snr_reference");
  s.snr_reference_range = p.real("snr_reference_range");
  if (s.model != DetectionModel::Constant && p.given("detection_probability"))
    throw p.error("detection_probability", "is for detection_model: constant; with a Swerling model P_D follows from the SNR");
  if (s.model == DetectionModel::Constant) {
    for (const char* name : {"false_alarm_probability", "snr_reference", "snr_reference_range"})
      if (p.given(name))
        throw p.error(name, "is for detection_model: swerling0 or swerling1 (P_D from the SNR); constant uses detection_probability");
  }
  s.lo = {p.real("range_min"), p.real("azimuth_min"), p.real("elevation_min")};
  s.hi = {p.real("range_max"), p.real("azimuth_max"), p.real("elevation_max")};
  if (!(s.lo[0] < s.hi[0])) throw p.error("range_max", "must be above range_min");
  if (!(s.lo[1] >= -std::numbers::pi && s.lo[1] <= std::numbers::pi))
    throw p.error("azimuth_min", "must be within [-180 deg, 180 deg] (azimuth_max may pass 180 deg)");
  if (!(s.lo[1] < s.hi[1] && s.hi[1] <= s.lo[1] + kTwoPi))
    throw p.error("azimuth_max", "must be above azimuth_min and at most 360 deg beyond it");
  if (!(s.lo[2] < s.hi[2])) throw p.error("elevation_max", "must be above elevation_min");
  s.merge = p.boolean("merge_unresolved");
  s.resolution = {p.real("range_resolution"), p.real("beamwidth_azimuth"), p.real("beamwidth_elevation")};
  if (p.given("clutter_rate") && p.given("clutter_density"))
    throw p.error("clutter_density", "give either 'clutter_rate' (per scan) or 'clutter_density' (per m rad2), not both");
  const double volume = coverage_volume(s);
  if (p.given("clutter_density"))
    s.clutter_mean = p.real("clutter_density") * volume;
  else if (p.given("clutter_rate"))
    s.clutter_mean = p.real("clutter_rate");
  else if (s.model != DetectionModel::Constant)
    s.clutter_mean = s.pfa * cell_count(s);  // every resolution cell of the coverage may false-alarm
  const char* clutter_param = p.given("clutter_density") ? "clutter_density" : p.given("clutter_rate") ? "clutter_rate" : "false_alarm_probability";
  if (s.clutter_mean > 1e7)
    throw p.error(clutter_param, "gives more than 1e7 clutter detections per scan (" + std::to_string(s.clutter_mean) + "); lower it");
  return s;
}

class ScanRadar final : public Component, public FieldListCodec<ScanRadarRunResult> {
 public:
  ScanRadar(const Params& p) : node_(p.node()), s_(read_settings(p)) {
    scan_.sensor = s_.sensor;
    scan_.region.known = true;
    scan_.region.dim = s_.dims;
    for (int i = 0; i < s_.dims; ++i) {
      scan_.region.lo[i] = s_.lo[i];
      scan_.region.hi[i] = s_.hi[i];
    }
    scan_.clutter_density = s_.clutter_mean / coverage_volume(s_);
    scan_.detection_probability = s_.model == DetectionModel::Constant ? s_.pd : std::numeric_limits<double>::quiet_NaN();
    const double clutter = s_.clutter_mean + 6.0 * std::sqrt(s_.clutter_mean) + 8.0;
    detections_.reserve(64 + static_cast<std::size_t>(clutter));
    pending_.reserve(64);
    echoes_.reserve(64);
  }

  void start_run(const RunContext& ctx) override {
    rng_.reseed(ctx.seed);
    run_ = ScanRadarRunResult{};
    pending_.clear();
    diagnostics_ = ctx.diagnostics;
  }

  void on_truth(const Truth& t, int) override {
    if (!t.position.allFinite() || !std::isfinite(t.time)) {
      if (diagnostics_) diagnostics_->skip(node_, "truth of target " + std::to_string(t.target) + " at t = " + std::to_string(t.time) + " is not finite; not seen");
      return;
    }
    pending_.push_back(t);
  }

  // One look per distinct truth time gathered in the instant (normally exactly one).
  void on_time_complete(double) override {
    if (pending_.empty()) return;
    std::stable_sort(pending_.begin(), pending_.end(), [](const Truth& a, const Truth& b) {
      return a.time != b.time ? a.time < b.time : a.target < b.target;
    });
    std::size_t begin = 0;
    while (begin < pending_.size()) {
      std::size_t end = begin;
      while (end < pending_.size() && pending_[end].time == pending_[begin].time) ++end;
      look(begin, end);
      begin = end;
    }
    pending_.clear();
  }

  std::unique_ptr<RunResult> end_run() override {
    // A source that stopped mid-instant cannot happen (the engine closes the last instant), so
    // anything left here would be a lost look: say so rather than drop it.
    if (!pending_.empty() && diagnostics_)
      diagnostics_->skip(node_, std::to_string(pending_.size()) + " truth item(s) never closed into a look");
    return std::make_unique<ScanRadarRunResult>(run_);
  }
  void merge(RunResult& r) override {
    const auto& c = static_cast<ScanRadarRunResult&>(r);
    ++runs_;
    ScanRadarRunResult::fields(total_, [&](auto&... t) {
      ScanRadarRunResult::fields(c, [&](const auto&... x) { ((t += x), ...); });
    });
  }
  void finish(Summary& s, const FinishContext&) override {
    if (runs_ == 0) return;
    const double n = static_cast<double>(runs_);
    s.metric("looks", static_cast<double>(total_.looks) / n);
    s.metric("target_detections", static_cast<double>(total_.detections) / n);
    s.metric("missed_detections", static_cast<double>(total_.missed) / n);
    s.metric("clutter_detections", static_cast<double>(total_.clutter) / n);
    s.metric("targets_outside_coverage", static_cast<double>(total_.outside) / n);
    if (s_.merge) s.metric("merged_targets", static_cast<double>(total_.merged) / n);
    s.notes.push_back("per run averages over " + std::to_string(runs_) + " run(s); a target look outside the coverage is " +
                      "neither detected nor missed");
  }

 private:
  // Azimuth measured from the coverage's lower edge, in [0, 2 pi): inside when at most its width.
  double azimuth_offset(double az) const {
    double a = std::fmod(az - s_.lo[1], kTwoPi);
    return a < 0.0 ? a + kTwoPi : a;
  }
  bool covers(const Vec3& rae) const {
    return rae[0] >= s_.lo[0] && rae[0] <= s_.hi[0] && azimuth_offset(rae[1]) <= s_.hi[1] - s_.lo[1] &&
           rae[2] >= s_.lo[2] && rae[2] <= s_.hi[2];
  }
  double detection_probability(double range) const {
    if (s_.model == DetectionModel::Constant) return s_.pd;
    const double snr = snr_at_range(range, s_.snr_reference_db, s_.snr_reference_range);
    return s_.model == DetectionModel::Swerling0 ? pd_swerling0(snr, s_.pfa) : pd_swerling1(snr, s_.pfa);
  }

  void look(std::size_t begin, std::size_t end) {
    const double t = pending_[begin].time;
    ++run_.looks;
    echoes_.clear();
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 rae = enu_to_spherical(pending_[i].position - s_.sensor.sensor_position, s_.sensor.azimuth);
      if (!covers(rae)) {
        ++run_.outside;
        continue;
      }
      ++run_.in_coverage;
      echoes_.push_back({pending_[i].target, rae, false});
    }
    detections_.clear();
    const bool elevation = s_.dims == 3;
    Detection d;
    d.value.resize(s_.dims);
    d.covariance.setZero(s_.dims, s_.dims);
    for (int i = 0; i < s_.dims; ++i) d.covariance(i, i) = s_.sigma[i] * s_.sigma[i];
    for (std::size_t i = 0; i < echoes_.size(); ++i) {
      Echo& e = echoes_[i];
      if (e.merged) continue;
      // Unresolved: targets within one resolution cell of this (the lowest-id) one give one plot
      // at their mean position in measurement space, labelled with this target.
      Vec3 centre = e.rae;
      int group = 1;
      if (s_.merge) {
        for (std::size_t j = i + 1; j < echoes_.size(); ++j) {
          Echo& o = echoes_[j];
          if (o.merged) continue;
          const double daz = wrap_angle(o.rae[1] - e.rae[1]);
          if (std::fabs(o.rae[0] - e.rae[0]) <= s_.resolution[0] && std::fabs(daz) <= s_.resolution[1] &&
              (!elevation || std::fabs(o.rae[2] - e.rae[2]) <= s_.resolution[2])) {
            o.merged = true;
            centre += Vec3(o.rae[0], e.rae[1] + daz, o.rae[2]);
            ++group;
            ++run_.merged;
          }
        }
        centre /= static_cast<double>(group);
      }
      if (!(rng_.uniform() < detection_probability(centre[0]))) {
        run_.missed += static_cast<std::uint64_t>(group);
        continue;
      }
      d.value[0] = centre[0] + s_.sigma[0] * rng_.normal();
      d.value[1] = wrap_angle(centre[1] + s_.sigma[1] * rng_.normal());
      if (elevation) d.value[2] = centre[2] + s_.sigma[2] * rng_.normal();
      d.origin = e.target;
      detections_.push_back(d);
      run_.detections += static_cast<std::uint64_t>(group);
    }
    d.origin = kOriginClutter;
    for (std::uint64_t n = poisson(rng_, s_.clutter_mean); n > 0; --n) {
      d.value[0] = s_.lo[0] + (s_.hi[0] - s_.lo[0]) * rng_.uniform();
      d.value[1] = wrap_angle(s_.lo[1] + (s_.hi[1] - s_.lo[1]) * rng_.uniform());
      if (elevation) d.value[2] = s_.lo[2] + (s_.hi[2] - s_.lo[2]) * rng_.uniform();
      detections_.push_back(d);
      ++run_.clutter;
    }
    // Sorted by range, then azimuth, then elevation, so the order gives nothing of the origin away.
    simulation::sort_detections(detections_);
    scan_.time = t;
    scan_.detections = std::span<const Detection>(detections_.data(), detections_.size());
    out.emit(scan_);
  }

  std::string node_;
  Settings s_;
  Rng rng_;
  Diagnostics* diagnostics_ = nullptr;
  std::vector<Truth> pending_;
  std::vector<Echo> echoes_;
  std::vector<Detection> detections_;
  Scan scan_;
  ScanRadarRunResult run_, total_;
  std::uint64_t runs_ = 0;
};

const char* const kDoc =
    "One look per instant: every Truth arriving at one time (from one or several sources; the engine closes the instant "
    "when nothing more of that time can come) is seen in one Scan of that time. Geometry from `position` in the ENU "
    "frame, [r, az, el] as sim.radar's (geometry.hpp enu_to_spherical, azimuth_convention). A target is in coverage when "
    "range_min <= r <= range_max, its azimuth lies in [azimuth_min, azimuth_max] (the interval may pass 180 deg: "
    "azimuth_max up to azimuth_min + 360 deg) and elevation_min <= el <= elevation_max; outside it it is neither "
    "detected nor missed (counted). A covered target is detected with probability P_D: constant (detection_probability), "
    "or from the SNR of a skin echo, SNR(dB) = snr_reference - 40 log10(r / snr_reference_range), for a square-law "
    "detector at false_alarm_probability P_FA: swerling1 P_D = P_FA^(1/(1+SNR)) (Skolnik §2.8; Richards eq 7.40, one "
    "look), swerling0 P_D = Q_1(sqrt(2 SNR), sqrt(-2 ln P_FA)) (Marcum Q; Richards eq 6.25). A detection is "
    "[r, az, el] + N(0, diag(sigma_range², sigma_azimuth², sigma_elevation²)), azimuth wrapped to (-180, 180] deg, "
    "covariance that diagonal, origin its target id. merge_unresolved: targets within one resolution cell of a "
    "lower-id one (|dr| <= range_resolution, |daz| <= beamwidth_azimuth, |del| <= beamwidth_elevation, true "
    "positions) give one plot at their mean [r, az, el], detected with the P_D at its range, origin the lower id "
    "(counted as merged_targets). Clutter: a Poisson number of mean clutter_rate (or clutter_density × coverage "
    "volume in m rad²; with a Swerling model by default P_FA × the number of resolution cells, (Δr/range_resolution)"
    "(Δaz/beamwidth_azimuth)(Δel/beamwidth_elevation)), uniform over the coverage in [r, az, el], origin clutter. "
    "Detections sorted by range, azimuth, elevation. The Scan states its region (the coverage, dim 3), its "
    "clutter_density (expected clutter per m rad²) and, with constant P_D, its detection_probability (NaN with a "
    "Swerling model: P_D varies with range; give the associator its own). Random draws per look, from the run's "
    "seed: per plot in target-id order one uniform (detection) and, if detected, three normals; then the clutter "
    "count and three uniforms per clutter detection; identical for any --threads. Elevation is not folded. "
    "measures: range_azimuth makes it a 2-D surveillance radar: plots [r, az] (Frame::Polar; r the slant range) with "
    "covariance diag(sigma_range², sigma_azimuth²), the fan beam covering [elevation_min, elevation_max]; resolution "
    "cells, merging and clutter in (r, az) only (clutter_rate, or P_FA × (Δr/range_resolution)(Δaz/beamwidth_azimuth)), "
    "region dim 2, clutter_density per m rad; two normals per plot and two uniforms per clutter detection. filter.ekf "
    "tracks such plots in the radar's horizontal plane.";

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sim.scan_radar";
  d.kind = ComponentKind::Source;
  d.summary = "Simulated radar in scan mode: per instant one Scan of every covered target with P_D (constant, "
              "Swerling 0/I from SNR), spherical noise, Poisson clutter over its range-azimuth-elevation cells";
  d.doc = kDoc;
  const Dimension per_m_rad2{-1, 0, -2, 0};
  d.params = {
      ParamSpec::real_list("position", dim::length, "radar position in the ENU frame [x east, y north, z up]", 3)
          .def("[0, 0, 0]"),
      azimuth_convention_param("azimuth reference: compass bearing, or math angle from east toward north"),
      ParamSpec::integer("sensor_id", "sensor number written into each Scan").def("0").at_least(0).at_most(4294967295.0),
      ParamSpec::real("sigma_range", dim::length, "range noise standard deviation").def("10 m").at_least(0),
      ParamSpec::real("sigma_azimuth", dim::angle, "azimuth noise standard deviation").def("1 mrad").at_least(0)
          .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint),
      ParamSpec::real("sigma_elevation", dim::angle, "elevation noise standard deviation").def("1 mrad").at_least(0)
          .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint),
      ParamSpec::choice<DetectionModel>("detection_model",
                                        {{DetectionModel::Constant, "constant"},
                                         {DetectionModel::Swerling0, "swerling0"},
                                         {DetectionModel::Swerling1, "swerling1"}},
                                        "P_D: constant, or from the SNR over range for a steady (swerling0) or "
                                        "slowly fluctuating (swerling1) target")
          .def("constant"),
      ParamSpec::real("detection_probability", dim::none, "constant model: P_D of a covered target").def("1").at_least(0).at_most(1),
      ParamSpec::real("false_alarm_probability", dim::none, "Swerling models: P_FA per resolution cell").def("1e-6").positive().at_most(0.5),
      ParamSpec::real("snr_reference", dim::decibel, "Swerling models: SNR at snr_reference_range").def("20 dB"),
      ParamSpec::real("snr_reference_range", dim::length, "Swerling models: range of snr_reference").def("100 km").positive(),
      ParamSpec::real("range_min", dim::length, "coverage: nearest range").def("0 m").at_least(0),
      ParamSpec::real("range_max", dim::length, "coverage: farthest range").req().positive(),
      ParamSpec::real("azimuth_min", dim::angle, "coverage: lower azimuth edge, in [-180, 180] deg").def("-180 deg"),
      ParamSpec::real("azimuth_max", dim::angle, "coverage: upper azimuth edge (may pass 180 deg)").def("180 deg"),
      ParamSpec::real("elevation_min", dim::angle, "coverage: lowest elevation").def("0 deg"),
      ParamSpec::real("elevation_max", dim::angle, "coverage: highest elevation").def("90 deg"),
      ParamSpec::real("clutter_rate", dim::none, "expected clutter detections per scan (or clutter_density)").at_least(0),
      ParamSpec::real("clutter_density", per_m_rad2, "instead of clutter_rate: expected clutter per m rad2 of the coverage").at_least(0),
      ParamSpec::boolean("merge_unresolved", "targets within one resolution cell give one plot").def("false"),
      ParamSpec::choice<Measures>("measures",
                                  {{Measures::RangeAzimuthElevation, "range_azimuth_elevation"},
                                   {Measures::RangeAzimuth, "range_azimuth"}},
                                  "what a plot holds: [r, az, el], or a 2-D surveillance radar's [r, az] (polar)")
          .def("range_azimuth_elevation"),
      ParamSpec::real("range_resolution", dim::length, "resolution cell: range extent (merging, Swerling clutter)").def("15 m").positive(),
      ParamSpec::real("beamwidth_azimuth", dim::angle, "resolution cell: azimuth beamwidth").def("1 deg").positive(),
      ParamSpec::real("beamwidth_elevation", dim::angle, "resolution cell: elevation beamwidth").def("1 deg").positive(),
  };
  d.accepts = mask(ItemKind::Truth);
  d.min_inputs = 1;
  d.max_inputs = -1;
  d.produces = mask(ItemKind::Scan);
  d.groups_by_time = true;
  d.create = [](const Params& p) { return std::make_unique<ScanRadar>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sim.scan_radar", trackflow::register_components)
