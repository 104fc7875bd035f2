// Purpose: convert.unbiased — multiplicative unbiased converted measurement (Mo Longbin et al. 1998).
#include "conversion/statistical_converter.hpp"

#include <trackflow/plugin.hpp>

namespace trackflow {
namespace {

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "convert.unbiased";
  d.kind = ComponentKind::Converter;
  d.summary = "Spherical to Cartesian ENU, multiplicative unbiased (Mo, Song, Zhou, Sun & Bar-Shalom 1998)";
  d.doc = "z = D^-1 p(m) with D = diag(la le, la le, le), l = exp(-sigma^2/2) (eq 9, 12): unbiased given the "
          "true position. R = D^-1 C(2S) D^-1 - C(S) (eq 11): the true covariance averaged given the measurement, "
          "C(S) the exact covariance of the spherical-to-ENU map under Gaussian errors S. Uses the diagonal of "
          "the (r, az, el) covariance. Range rate passes through. Cartesian and invalid inputs pass unchanged. "
          "See docs/converters.md.";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Measurement);
  d.produces_frames = mask(Frame::Cartesian);  // valid measurements; invalid ones pass unconverted
  d.create = [](const Params& p) {
    return std::make_unique<conversion::StatisticalConverter>("convert.unbiased", p.node(), &conversion::unbiased);
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("convert.unbiased", trackflow::register_components)
