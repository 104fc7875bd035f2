// Purpose: chi-square quantiles: the two-sided acceptance band of a mean of normalised squared errors (NIS, NEES), for summaries, and the gate threshold of a gate probability.
#pragma once

#include <boost/config.hpp>

namespace trackflow {

struct ChiSquareBand {
  double lo = 0.0, hi = 0.0;
};

// A sum of normalised squared errors with `dof` degrees of freedom in all, divided by `dof`:
// [chi2inv((1-c)/2, dof), chi2inv((1+c)/2, dof)] / dof. A mean NIS per measurement element inside
// it is consistent with the filter's innovation covariance at confidence c.
BOOST_SYMBOL_VISIBLE ChiSquareBand chi_square_mean_band(double dof, double confidence);
// chi2inv(probability, dof): the NIS below which a measurement of `dof` elements falls with that
// probability (a validation gate of gate probability P_G). NaN outside dof > 0, 0 < p < 1.
BOOST_SYMBOL_VISIBLE double chi_square_quantile(double dof, double probability);

}  // namespace trackflow
