// Purpose: evaluation of the constant / SNR (paper 001 eq 6-8) / Table 4 (paper 000) noise models and the noise scale.
#include "noise_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace trackflow::sim {
namespace {

// Paper 000 Table 4, "Tracking error standard of tracking radar system in Naro space center":
// range, S/N (dB), random noise error R, AZ & EL.
constexpr std::array<Table4Row, 4> kTable4 = {{
    {158.48e3, 45.0, 0.3, 50e-6},
    {1000e3, 29.0, 1.9, 320e-6},
    {1500e3, 25.47, 3.0, 500e-6},
    {2000e3, 22.97, 4.3, 630e-6},
}};

const char* const kConstantParams[] = {"sigma_range", "sigma_azimuth", "sigma_elevation"};
const char* const kSnrParams[] = {"range_resolution", "beamwidth_azimuth", "beamwidth_elevation", "monopulse_slope",
                                  "snr_reference", "snr_reference_range", "snr_law", "snr_jitter"};



double preset_factor(NoisePreset preset) {
  if (preset == NoisePreset::Best) return 0.5;
  if (preset == NoisePreset::Worst) return 2.0;
  return 1.0;  // none, normal
}

// A parameter of another model written by the analyst is almost certainly a mistake (it would
// be silently ignored), so it is refused.
template <size_t N>
void refuse_given(const Params& p, const char* const (&names)[N], const std::string& model) {
  for (const char* name : names)
    if (p.given(name))
      throw p.error(name, std::string("is not used by noise_model: ") + model + " (remove it or choose the model that uses it)");
}

}  // namespace

Table4Row table4_at(double range) {
  if (!(range > kTable4.front().range)) return {range, kTable4.front().snr_db, kTable4.front().sigma_range, kTable4.front().sigma_angle};
  if (range >= kTable4.back().range) return {range, kTable4.back().snr_db, kTable4.back().sigma_range, kTable4.back().sigma_angle};
  size_t i = 0;
  while (range >= kTable4[i + 1].range) ++i;
  const Table4Row& a = kTable4[i];
  const Table4Row& b = kTable4[i + 1];
  const double f = std::log(range / a.range) / std::log(b.range / a.range);
  return {range, a.snr_db + f * (b.snr_db - a.snr_db), a.sigma_range * std::pow(b.sigma_range / a.sigma_range, f),
          a.sigma_angle * std::pow(b.sigma_angle / a.sigma_angle, f)};
}

double LinkBudget::snr_db(double range) const {
  return reference_db - 10.0 * exponent * std::log10(std::max(range, kMinLinkRange) / reference_range);
}

NoiseSigmas SnrAccuracy::sigmas(double snr_db) const {
  const double root_2snr = std::sqrt(2.0 * std::pow(10.0, snr_db / 10.0));
  return {range_resolution / root_2snr, beamwidth_azimuth / (monopulse_slope * root_2snr),
          beamwidth_elevation / (monopulse_slope * root_2snr), 0.0};
}

NoiseModel::NoiseModel(const Params& p) {
  const std::string& model = p.choice_word("noise_model");
  kind_ = p.choice<NoiseModelKind>("noise_model");
  if (kind_ != NoiseModelKind::Constant) refuse_given(p, kConstantParams, model);
  if (kind_ != NoiseModelKind::Snr) refuse_given(p, kSnrParams, model);
  constant_ = {p.real("sigma_range"), p.real("sigma_azimuth"), p.real("sigma_elevation"), p.real("sigma_range_rate")};
  link_ = {p.real("snr_reference"), p.real("snr_reference_range"), static_cast<int>(p.choice<SnrLaw>("snr_law"))};
  accuracy_ = {p.real("range_resolution"), p.real("beamwidth_azimuth"), p.real("beamwidth_elevation"),
               p.real("monopulse_slope")};
  jitter_db_ = p.real("snr_jitter");
  scale_ = p.real("noise_factor") * preset_factor(p.choice<NoisePreset>("noise_preset"));
}

Look NoiseModel::look(double range, Rng& rng) const {
  Look look;
  switch (kind_) {
    case NoiseModelKind::Constant:
      look.sigmas = constant_;
      break;
    case NoiseModelKind::Snr: {
      const double jitter = jitter_db_ * rng.normal();
      look.has_snr = true;
      look.snr_db = std::clamp(link_.snr_db(range) + jitter, kMinSnrDb, kMaxSnrDb);
      look.sigmas = accuracy_.sigmas(look.snr_db);
      look.sigmas.range_rate = constant_.range_rate;
      break;
    }
    case NoiseModelKind::Table4: {
      const Table4Row row = table4_at(range);
      look.has_snr = true;
      look.snr_db = row.snr_db;
      look.sigmas = {row.sigma_range, row.sigma_angle, row.sigma_angle, constant_.range_rate};
      break;
    }
  }
  return look;
}

}  // namespace trackflow::sim
