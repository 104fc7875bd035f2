// Purpose: linear glint of paper 003 (eq 3-9..3-11, Table 1, Fig 18): a Gaussian/Laplacian mixture with a Lorentzian spectrum, tied to the RCS fade, rotated into azimuth and elevation.
#pragma once

#include "lorentzian_process.hpp"

#include <trackflow/rng.hpp>

namespace trackflow::sim {

struct GlintSettings {
  double sigma = 9.5;            // RMS of the linear glint, m (Table 1: 0.2 L for a rectangle of length L)
  double laplace_weight = 0.5;   // i of eq 3-9
  double variance_ratio = 100;   // Laplacian variance / Gaussian variance (the paper: 178.7 / 1.787)
  double bandwidth = 1.0;        // B of eq 3-10, Hz (the plugin's default is 10 Hz; tests use 1 Hz)
  // true: sigma is the RMS in each plane (Table 1's sigma = R/sqrt(2) is the scintillation in one
  // plane), so the rotated glint has RMS sqrt(2) sigma and each axis sigma; false: the rotated glint
  // itself has RMS sigma and each axis sigma/sqrt(2) (Fig 18 taken literally).
  bool per_plane = true;
};

// Gaussian and Laplacian variances of the mixture with total variance sigma^2:
// sigma^2 = (1 - i) s_g^2 + i ratio s_g^2 (for the paper: 90.25 = 0.5 * 1.787 + 0.5 * 178.7).
struct MixtureVariances {
  double gaussian = 0.0, laplacian = 0.0;
};
MixtureVariances mixture_variances(const GlintSettings& s);

// Draws of one renewal of the glint. The Laplacian is a Gaussian scale mixture, L = s_l sqrt(E) N with
// E ~ Exp(1) and N ~ N(0, 1) (variance s_l^2). `fade_uniform` in (0, 1) ties E to the RCS: E = -ln(U)
// with U = F(x) the RCS's CDF value, so E is exactly Exp(1) and large when the RCS is in a fade (one
// random source, Fig 9c: the glint and the RCS are uncorrelated but not independent). NaN: E is drawn
// from this generator's own uniform instead (independent, Fig 9b). The draws per renewal are fixed:
// 1 uniform (component), 1 uniform (own E), 1 normal, 1 uniform (rotation angle alpha ~ U(0, 2 pi)).
class GlintProcess {
 public:
  explicit GlintProcess(GlintSettings s);

  // First look of a run: a renewal.
  void start(double fade_uniform, Rng& rng) { renew(fade_uniform, rng); }
  // A later look dt after the previous one: DAR(1), the value holds with probability
  // exp(-2 pi B dt), so the glint's autocorrelation is exactly exp(-2 pi B tau) (eq 3-10).
  // `fade_uniform()` is only evaluated when the glint renews. Returns true when it did.
  template <class FadeUniform>
  bool advance(double dt, FadeUniform&& fade_uniform, Rng& rng) {
    if (dt != last_dt_) {  // fixed-rate looks: the exponential once
      rho_ = lorentzian_correlation(s_.bandwidth, dt);
      last_dt_ = dt;
    }
    if (!dar1_renew(rho_, rng)) return false;
    renew(fade_uniform(), rng);
    return true;
  }
  bool advance(double dt, double fade_uniform, Rng& rng) {
    return advance(dt, [fade_uniform] { return fade_uniform; }, rng);
  }

  double linear() const { return g_; }        // m, along the rotated direction
  double azimuth_m() const { return az_; }    // m, azimuth-plane component (eq 3-11 divides by range)
  double elevation_m() const { return el_; }  // m
  bool laplacian() const { return laplacian_; }
  const GlintSettings& settings() const { return s_; }

 private:
  void renew(double fade_uniform, Rng& rng);

  GlintSettings s_;
  double sd_gauss_ = 0.0, sd_laplace_ = 0.0, axis_scale_ = 1.0;
  double g_ = 0.0, az_ = 0.0, el_ = 0.0;
  double last_dt_ = -1.0, rho_ = 0.0;
  bool laplacian_ = false;
};

}  // namespace trackflow::sim
