// Purpose: delete.existence — deletes a confirmed track when its existence probability (JIPDA, IPDA) falls below min_existence.
#include <trackflow/plugin.hpp>
#include <trackflow/tracker.hpp>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace trackflow {
namespace {

// Musicki & Evans 2004, sec. V: a track whose probability of being a target is low is terminated.
class ExistenceDeleter final : public Deleter {
 public:
  ExistenceDeleter(double min_existence, std::string node) : min_(min_existence), node_(std::move(node)) {}
  bool reads_existence() const override { return true; }
  bool drop(const TrackView& t) const override {
    if (std::isnan(t.existence))
      throw std::logic_error("delete.existence (node '" + node_ + "'): track " + std::to_string(t.id) +
                             " has no existence probability (the associator keeps none; checked before the run)");
    return t.existence < min_;
  }

 private:
  double min_;
  std::string node_;
};

std::unique_ptr<TrackerPart> create_part(const Params& p) {
  return std::make_unique<ExistenceDeleter>(p.real("min_existence"), p.node());
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "delete.existence";
  d.kind = ComponentKind::Deleter;
  d.summary = "Deletes a confirmed track when its existence probability (JIPDA, IPDA) falls below min_existence";
  d.doc =
      "The existence probability is the associator's (assoc.jpda, or assoc.pda with survival_probability; Musicki & "
      "Evans 2004): it falls with each look that finds nothing for the track and with the survival probability. An "
      "associator that keeps no existence is refused before the run. See docs/multi-target.md.";
  d.params = {
      ParamSpec::real("min_existence", Dimension{}, "a confirmed track below this existence probability is deleted")
          .def("0.05")
          .positive()
          .at_most(1),
  };
  d.create_part = create_part;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("delete.existence", trackflow::register_components)
