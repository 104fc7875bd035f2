// Purpose: delete.misses — a confirmed track is deleted after a number of consecutive looks without a detection, or after M misses in its last N looks.
#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <bit>
#include <memory>

namespace trackflow {
namespace {

class MissesDeleter final : public Deleter {
 public:
  MissesDeleter(int consecutive, int m, int n) : consecutive_(consecutive), m_(m), n_(n) {}
  bool drop(const TrackView& t) const override {
    if (t.misses >= consecutive_) return true;
    if (m_ <= 0) return false;
    const int window = n_ < t.looks ? n_ : t.looks;
    const std::uint64_t mask = window >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << window) - 1;
    const int misses = window - std::popcount(t.history & mask);
    return misses >= m_;
  }

 private:
  int consecutive_, m_, n_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  const bool window = p.given("misses_in_window") || p.given("window");
  if (window && !(p.given("misses_in_window") && p.given("window")))
    throw p.error(p.given("window") ? "window" : "misses_in_window", "give misses_in_window and window together");
  const int m = window ? static_cast<int>(p.integer("misses_in_window")) : 0;
  const int n = window ? static_cast<int>(p.integer("window")) : 0;
  if (window && m > n) throw p.error("misses_in_window", "cannot exceed window");
  return std::make_unique<MissesDeleter>(static_cast<int>(p.integer("max_misses")), m, n);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "delete.misses";
  d.kind = ComponentKind::Deleter;
  d.summary = "Deletes a confirmed track after max_misses consecutive misses, or misses_in_window misses in its last window looks";
  d.doc =
      "A look of the sensor without a detection for the track is a miss (a scan with valid: false is no look). "
      "The track is deleted when its consecutive misses reach max_misses, or, with misses_in_window and window, "
      "when at least misses_in_window of its last window looks were misses. See docs/multi-target.md.";
  d.params = {
      ParamSpec::integer("max_misses", "consecutive misses that delete a confirmed track").def("3").at_least(1),
      ParamSpec::integer("misses_in_window", "M of an M-of-N deletion rule (with window)").at_least(1),
      ParamSpec::integer("window", "N of an M-of-N deletion rule: the last N looks (at most 64)").at_least(1).at_most(64),
  };
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("delete.misses", trackflow::register_components)
