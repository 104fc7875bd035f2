// Purpose: sink.metrics' per-step ensemble series: one row per time step from the run-ordered per-step sums.
#include "scoring/chi_square_band.hpp"
#include "ensemble.hpp"

#include <cmath>
#include <limits>
#include <map>

namespace trackflow::metrics {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Chi-square quantiles are costly and steps share few distinct degrees of freedom.
class BandCache {
 public:
  explicit BandCache(double confidence) : confidence_(confidence) {}
  Band get(std::uint64_t total_dof) {
    auto it = cache_.find(total_dof);
    if (it == cache_.end()) it = cache_.emplace(total_dof, chi_square_band(static_cast<double>(total_dof), confidence_)).first;
    return it->second;
  }

 private:
  double confidence_;
  std::map<std::uint64_t, Band> cache_;
};

const StepSums& sums_of(const std::pair<long long, StepSums>& step) { return step.second; }
const StepSums& sums_of(const SeriesBin& bin) { return bin.sums; }

// One row per entry of `rows`: the ensemble's time steps, or (a run without truth) its bins.
template <class Rows>
Series series_of(const Ensemble& e, const Rows& rows, const ReportOptions& opt, const AnnotationChannels& channels) {
  Series s;
  s.name = "ensemble";
  s.description = "per time step over the runs: RMSE, mean error, ANEES/ANIS with their " +
                  std::to_string(static_cast<int>(std::lround(opt.confidence * 100))) +
                  " % chi-square band for the runs at that step, measurement RMSE, fractions of runs";
  s.add_column("time", "s");
  s.add_column("runs_scored");  // runs whose estimate at this step was matched to truth
  s.add_column("position_rmse", "m");
  s.add_column("velocity_rmse", "m/s");
  for (const char* a : {"x", "y", "z"}) s.add_column(std::string("mean_error_") + a, "m");
  for (const char* a : {"vx", "vy", "vz"}) s.add_column(std::string("mean_error_") + a, "m/s");
  s.add_column("anees");
  s.add_column("anees_band_lo");
  s.add_column("anees_band_hi");
  s.add_column("anees_position");
  s.add_column("anis");
  s.add_column("anis_band_lo");
  s.add_column("anis_band_hi");
  s.add_column("measurement_rmse", "m");
  s.add_column("initialised_fraction");
  s.add_column("updated_fraction");
  // Only channels that some estimate carried: a filter without adapters gets no empty columns.
  std::vector<int> used;
  for (int c = 0; c < channels.count() && c < kMaxAnnotations; ++c) {
    bool any = false;
    for (const auto& row : rows) any = any || sums_of(row).annotations.count[c] > 0;
    if (any) {
      used.push_back(c);
      s.add_column(channels.name(c) + "_mean", channels.unit(c));
    }
  }

  BandCache nees_bands(opt.confidence), nis_bands(opt.confidence);
  const double runs = static_cast<double>(e.runs);
  s.values.reserve(rows.size() * s.columns.size());
  // A bin of several steps: its fractions are over the (run, step) pairs it holds.
  const bool binned = e.bin_width > 1;
  for (const auto& row : rows) {
    const StepSums& st = sums_of(row);
    const double runs_here = binned ? static_cast<double>(st.run_steps) : runs;
    auto put = [&](double v) { s.values.push_back(v); };
    put(st.time);
    put(static_cast<double>(st.matched));
    if (st.matched) {
      const double n = static_cast<double>(st.matched);
      put(std::sqrt((st.sq[0] + st.sq[1] + st.sq[2]) / n));
      put(std::sqrt((st.sq[3] + st.sq[4] + st.sq[5]) / n));
      for (int i = 0; i < 6; ++i) put(st.sum[i] / n);
    } else {
      for (int i = 0; i < 8; ++i) put(kNaN);
    }
    if (st.nees_count) {
      // The same per-step value and band (M_k = runs with a NEES at this step) as the summary's
      // anees and anees_steps_in_band, so the series' mean is the summary's anees.
      const double m = static_cast<double>(st.nees_count);
      const Band b = nees_bands.get(6 * st.nees_count);
      put(st.nees / (6.0 * m));
      put(b.lo);
      put(b.hi);
      put(st.nees_position / (3.0 * m));
    } else {
      for (int i = 0; i < 4; ++i) put(kNaN);
    }
    if (st.nis_count) {
      const Band b = nis_bands.get(st.nis_dof);
      put(st.nis / static_cast<double>(st.nis_dof));
      put(b.lo);
      put(b.hi);
    } else {
      for (int i = 0; i < 3; ++i) put(kNaN);
    }
    put(st.measurements ? std::sqrt(st.measurement_sq / static_cast<double>(st.measurements)) : kNaN);
    put(runs_here > 0 ? static_cast<double>(st.initialised) / runs_here : kNaN);
    put(runs_here > 0 ? static_cast<double>(st.updated) / runs_here : kNaN);
    for (int c : used) put(st.annotations.mean(c));
  }
  return s;
}

}  // namespace

Series ensemble_series(const Ensemble& e, const ReportOptions& opt, const AnnotationChannels& channels) {
  return e.bin_width > 0 ? series_of(e, e.bins, opt, channels) : series_of(e, e.steps, opt, channels);
}

}  // namespace trackflow::metrics
