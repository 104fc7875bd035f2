// Purpose: single-look detection probability of a square-law detector against a steady (Swerling 0) or a slowly fluctuating (Swerling I) target, and the radar-equation SNR over range.
#pragma once

#include <boost/math/distributions/non_central_chi_squared.hpp>

#include <algorithm>
#include <cmath>

namespace trackflow::scan_radar {

// SNR (linear) of a skin echo at range r: SNR(dB) = snr_reference - 40 log10(r / reference_range),
// the two-way radar equation (R^-4). r is taken as at least 1 m and the dB value held within
// [-200, 300] so the linear SNR stays finite (as sim.radar's snr model).
inline double snr_at_range(double r, double snr_reference_db, double reference_range) {
  const double db = snr_reference_db - 40.0 * std::log10(std::max(r, 1.0) / reference_range);
  return std::pow(10.0, std::clamp(db, -200.0, 300.0) / 10.0);
}

// Swerling I (and II, one look): the echo's amplitude is Rayleigh, its power exponential, so the
// detector output is exponential with mean 1 + SNR and P_D = P_FA^(1 / (1 + SNR))
// (Skolnik, Introduction to Radar Systems, 3rd ed., §2.8; Richards, Fundamentals of Radar Signal
// Processing, 2nd ed., eq 7.40 for N = 1).
inline double pd_swerling1(double snr, double pfa) { return std::pow(pfa, 1.0 / (1.0 + snr)); }

// Swerling 0 (steady target), square-law detector: 2|y|^2 / sigma^2 is chi-square with 2 degrees of
// freedom and non-centrality 2 SNR; the threshold that gives P_FA on noise alone is -2 ln P_FA, so
// P_D = Q_1(sqrt(2 SNR), sqrt(-2 ln P_FA)), the Marcum Q function (Richards eq 6.25).
inline double pd_swerling0(double snr, double pfa) {
  const double threshold = -2.0 * std::log(pfa);
  if (!(snr > 0.0)) return pfa;
  boost::math::non_central_chi_squared dist(2.0, 2.0 * snr);
  return boost::math::cdf(boost::math::complement(dist, threshold));
}

}  // namespace trackflow::scan_radar
