// Purpose: convert.debiased — additive debiased converted measurement (Lerro & Bar-Shalom 1993, 3-D per Suchomski 1999).
#include "conversion/statistical_converter.hpp"

#include <trackflow/plugin.hpp>

namespace trackflow {
namespace {

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "convert.debiased";
  d.kind = ComponentKind::Converter;
  d.summary = "Spherical to Cartesian ENU, additive debiased (Lerro & Bar-Shalom 1993; 3-D: Suchomski 1999)";
  d.doc = "z = p(m) - (D - I) D p(m), R = C(2S) - D C(S) D: the average true bias and covariance given the "
          "measurement, D = diag(la le, la le, le), l = exp(-sigma^2/2), C(S) the exact covariance of the "
          "spherical-to-ENU map under Gaussian errors S. Removes the classical bias; somewhat optimistic "
          "(NEES/dim > 1) when r*sigma_angle^2/sigma_r >> 1. Uses the diagonal of the (r, az, el) covariance. "
          "Range rate passes through. Cartesian and invalid inputs pass unchanged. See docs/converters.md.";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Measurement);
  d.produces_frames = mask(Frame::Cartesian);  // valid measurements; invalid ones pass unconverted
  d.create = [](const Params& p) {
    return std::make_unique<conversion::StatisticalConverter>("convert.debiased", p.node(), &conversion::debiased);
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("convert.debiased", trackflow::register_components)
