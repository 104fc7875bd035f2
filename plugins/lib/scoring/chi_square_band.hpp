// Purpose: two-sided chi-square acceptance band of an average normalised squared error (ANEES, ANIS).
#pragma once

#include <boost/math/distributions/chi_squared.hpp>

namespace trackflow::metrics {

struct Band {
  double lo = 0.0, hi = 0.0;
};

// M runs of an n-dimensional normalised error: M * n * ANEES ~ chi2(n M) when the filter is
// consistent, so the band is [chi2inv((1-c)/2, nM), chi2inv((1+c)/2, nM)] / (nM)
// (Bar-Shalom, Li & Kirubarajan 2001 §5.4.2).
inline Band chi_square_band(double total_dof, double confidence) {
  const boost::math::chi_squared_distribution<double> chi2(total_dof);
  return {boost::math::quantile(chi2, 0.5 * (1.0 - confidence)) / total_dof,
          boost::math::quantile(chi2, 0.5 * (1.0 + confidence)) / total_dof};
}

}  // namespace trackflow::metrics
