// Purpose: chi_square_mean_band (chi_square.hpp) through Boost.Math, so filters' headers need not include it.
#include <trackflow/chi_square.hpp>

#include <boost/math/distributions/chi_squared.hpp>

namespace trackflow {

ChiSquareBand chi_square_mean_band(double dof, double confidence) {
  if (!(dof > 0.0) || !(confidence > 0.0 && confidence < 1.0)) return {};
  const boost::math::chi_squared_distribution<double> chi2(dof);
  return {boost::math::quantile(chi2, 0.5 * (1.0 - confidence)) / dof,
          boost::math::quantile(chi2, 0.5 * (1.0 + confidence)) / dof};
}

}  // namespace trackflow
