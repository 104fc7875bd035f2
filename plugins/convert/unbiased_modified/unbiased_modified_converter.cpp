// Purpose: convert.unbiased_modified — measurement-conditioned unbiased conversion (Duan, Han & Li 2004).
#include "conversion/statistical_converter.hpp"

#include <trackflow/plugin.hpp>

namespace trackflow {
namespace {

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "convert.unbiased_modified";
  d.kind = ComponentKind::Converter;
  d.summary = "Spherical to Cartesian ENU, modified unbiased: posterior mean and covariance (Duan, Han & Li 2004)";
  d.doc = "z = E[p(t) | m] = D p(m) with D = diag(la le, la le, le), l = exp(-sigma^2/2) (multiplies by l where "
          "convert.unbiased divides), R = Cov[p(t) | m] = C(S), the exact covariance of the spherical-to-ENU map "
          "under Gaussian errors S. Consistent (NEES/dim near 1) even when r*sigma_angle^2/sigma_r >> 1. Uses the "
          "diagonal of the (r, az, el) covariance. Range rate passes through. Cartesian and invalid inputs pass "
          "unchanged. See docs/converters.md.";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Measurement);
  d.produces_frames = mask(Frame::Cartesian);  // valid measurements; invalid ones pass unconverted
  d.create = [](const Params& p) {
    return std::make_unique<conversion::StatisticalConverter>("convert.unbiased_modified", p.node(),
                                                              &conversion::unbiased_modified);
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("convert.unbiased_modified", trackflow::register_components)
