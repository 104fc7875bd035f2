// Purpose: the noise σ's of one radar look: constant, from SNR (paper 001 eq 6-8) or from paper 000 Table 4, and their scale factors.
#pragma once

#include <trackflow/params.hpp>
#include <trackflow/rng.hpp>

namespace trackflow::sim {

// Standard deviations of the white noise on each channel for one look.
struct NoiseSigmas {
  double range = 0.0, azimuth = 0.0, elevation = 0.0, range_rate = 0.0;

  NoiseSigmas scaled(double k) const { return {k * range, k * azimuth, k * elevation, k * range_rate}; }
};

// Paper 000 Table 4 (Naro tracking radar random-error spec) at one range, interpolated.
struct Table4Row {
  double range = 0.0;        // m
  double snr_db = 0.0;
  double sigma_range = 0.0;  // m
  double sigma_angle = 0.0;  // rad, azimuth and elevation alike
};

// Up to the first row's range (158.48 km) the first row; from the last (2000 km) on the last;
// between rows σ is a power law in range (linear in log σ vs log R) and S/N is linear in log R.
// Both are exact for the table's own law: its S/N falls 20 dB per decade (R^-2) and σ grows ~ R.
Table4Row table4_at(double range);

// SNR of a link over range, in dB: reference SNR at a reference range, falling 10·n dB per
// decade, n = 4 for a skin return (two-way radar equation), n = 2 for a beacon (each leg one-way).
struct LinkBudget {
  double reference_db = 0.0;
  double reference_range = 1.0;  // m
  int exponent = 4;

  double snr_db(double range) const;
};

// Paper 001 eq 6-8: σ_r = Δr / sqrt(2 SNR), σ_az = θ_BW / (k_m sqrt(2 SNR)), σ_el = φ_BW / (k_m sqrt(2 SNR)),
// SNR linear. The range-rate σ is not part of this model and is left at 0.
struct SnrAccuracy {
  double range_resolution = 0.0;  // Δr, m
  double beamwidth_azimuth = 0.0;  // rad
  double beamwidth_elevation = 0.0;
  double monopulse_slope = 1.0;   // k_m, dimensionless

  NoiseSigmas sigmas(double snr_db) const;
};

// SNR values are kept within these bounds (dB) before σ is derived, so σ stays finite and
// non-zero for any finite geometry and parameters.
inline constexpr double kMinSnrDb = -200.0;
inline constexpr double kMaxSnrDb = 300.0;
// The link budget is evaluated no closer than this: a target at the radar has a finite SNR.
inline constexpr double kMinLinkRange = 1.0;  // m

// The σ's of a look before mode-window overrides and the noise scale.
struct Look {
  NoiseSigmas sigmas;
  bool has_snr = false;
  double snr_db = 0.0;
};

enum class NoiseModelKind { Constant, Snr, Table4 };
// The radar's other choice parameters, as enums (ParamSpec::choice<E>).
enum class SnrLaw { RadarR4 = 4, BeaconR2 = 2 };  // the value is the path-loss exponent
enum class NoisePreset { None, Best, Normal, Worst };

// Chooses and evaluates the noise model named by the `noise_model` parameter and owns the
// overall noise scale (noise_factor × noise_preset). Validates that only the parameters of the
// chosen model are given.
class NoiseModel {
 public:
  explicit NoiseModel(const Params& p);

  // Draws exactly one standard normal (the SNR jitter) for the snr model, none otherwise.
  Look look(double range, Rng& rng) const;
  // noise_factor × preset factor: multiplies every σ (all channels, all models).
  double scale() const { return scale_; }
  NoiseModelKind kind() const { return kind_; }

 private:
  NoiseModelKind kind_ = NoiseModelKind::Constant;
  NoiseSigmas constant_;  // constant model; range_rate σ for all models
  LinkBudget link_;
  SnrAccuracy accuracy_;
  double jitter_db_ = 0.0;
  double scale_ = 1.0;
};

}  // namespace trackflow::sim
