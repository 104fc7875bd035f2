// Purpose: reading, checking and looking up the radar's schedule windows.
#include "time_windows.hpp"

#include <trackflow/number_text.hpp>

#include <algorithm>
#include <cstdio>
#include <numeric>

namespace trackflow::sim {
namespace {

std::optional<double> optional_real(const Params& rec, const char* name) {
  return rec.has(name) ? std::optional<double>(rec.real(name)) : std::nullopt;
}

std::string seconds(double t) {
  return number_text::general(t, 10) + " s";
}

}  // namespace

TimeWindows::TimeWindows(const Params& p, const std::string& name, bool with_mode) {
  if (!p.has(name)) return;
  const auto& records = p.records(name);
  windows_.reserve(records.size());
  for (size_t i = 0; i < records.size(); ++i) {
    const Params& rec = records[i];
    TimeWindow w;
    w.start = rec.real("start");
    w.end = rec.real("end");
    if (!(w.end > w.start))
      throw rec.error("end", name + " entry " + std::to_string(i + 1) + ": end (" + seconds(w.end) +
                                 ") must be after start (" + seconds(w.start) + ")");
    if (with_mode) {
      w.mode = rec.choice<MeasMode>("mode");
      w.sigma_range = optional_real(rec, "sigma_range");
      w.sigma_azimuth = optional_real(rec, "sigma_azimuth");
      w.sigma_elevation = optional_real(rec, "sigma_elevation");
      w.sigma_range_rate = optional_real(rec, "sigma_range_rate");
    }
    windows_.push_back(w);
  }
  // Sorted copy of the entry numbers, so an overlap names both entries as the analyst wrote them.
  std::vector<size_t> order(windows_.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return windows_[a].start < windows_[b].start; });
  for (size_t k = 1; k < order.size(); ++k) {
    const TimeWindow& before = windows_[order[k - 1]];
    const TimeWindow& after = windows_[order[k]];
    if (after.start < before.end)
      throw records[order[k]].error(
          "start", name + " entry " + std::to_string(order[k] + 1) + " [" + seconds(after.start) + ", " +
                       seconds(after.end) + ") overlaps entry " + std::to_string(order[k - 1] + 1) + " [" +
                       seconds(before.start) + ", " + seconds(before.end) + ")");
  }
  std::vector<TimeWindow> sorted;
  sorted.reserve(windows_.size());
  for (size_t i : order) sorted.push_back(windows_[i]);
  windows_ = std::move(sorted);
}

const TimeWindow* TimeWindows::find(double t) const {
  // First window starting after t; the one before it is the only candidate.
  const auto it = std::upper_bound(windows_.begin(), windows_.end(), t,
                                   [](double time, const TimeWindow& w) { return time < w.start; });
  if (it == windows_.begin()) return nullptr;
  const TimeWindow& w = *(it - 1);
  return t < w.end ? &w : nullptr;
}

}  // namespace trackflow::sim
