// Purpose: chi_square_mean_band and chi_square_quantile (chi_square.hpp) through Boost.Math, so filters' headers need not include it.
#include <trackflow/chi_square.hpp>

#include <boost/math/distributions/chi_squared.hpp>

#include <limits>

namespace trackflow {

ChiSquareBand chi_square_mean_band(double dof, double confidence) {
  if (!(dof > 0.0) || !(confidence > 0.0 && confidence < 1.0)) return {};
  const boost::math::chi_squared_distribution<double> chi2(dof);
  return {boost::math::quantile(chi2, 0.5 * (1.0 - confidence)) / dof,
          boost::math::quantile(chi2, 0.5 * (1.0 + confidence)) / dof};
}

double chi_square_quantile(double dof, double probability) {
  if (!(dof > 0.0) || !(probability > 0.0 && probability < 1.0)) return std::numeric_limits<double>::quiet_NaN();
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), probability);
}

}  // namespace trackflow
