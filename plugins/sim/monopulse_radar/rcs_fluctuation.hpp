// Purpose: Swerling I-IV radar cross-section fluctuation with the time correlation of paper 003 eq 3-15, and the uniform variate behind it that the glint shares (Fig 9c).
#pragma once

#include "lorentzian_process.hpp"

#include <trackflow/rng.hpp>

namespace trackflow::sim {

enum class SwerlingCase { Constant = 0, One = 1, Two = 2, Three = 3, Four = 4 };

// RCS = mean x, with x >= 0 of mean 1:
//   Swerling I, II  : x = (g1^2 + g2^2) / 2, exponential (Rayleigh amplitude), chi-square 2 dof
//   Swerling III, IV: x = (g1^2 + .. + g4^2) / 4, chi-square 4 dof (one dominant scatterer)
//   constant (Swerling 0/V): x = 1.
// Each g is a unit Gaussian with the spectrum of eq 3-15, A^2(f) ~ 1/(B^2 + f^2) (the paper shapes the
// I and Q Gaussians with it before taking the magnitude, Fig 9): II and IV evaluate it at every look
// (fast fluctuation); I and III hold it over a scan of `scan_period` and evaluate it at scan starts
// only (slow, scan-to-scan), so the case picks the distribution and the hold, eq 3-15 the correlation.
// For a complex Gaussian of correlation rho the power x has correlation rho^2: x decorrelates at twice
// the rate of the I/Q components (exp(-4 pi B tau)).
class RcsFluctuation {
 public:
  RcsFluctuation(SwerlingCase c, double bandwidth, double scan_period)
      : case_(c), bandwidth_(bandwidth), scan_period_(scan_period) {}

  // First look of a run at time t: a stationary draw (one normal per component; the RCS has its own
  // random stream, so the case changes no other effect's draws).
  void start(double t, Rng& rng);
  // Look at time t >= the previous one.
  void advance(double t, Rng& rng);

  // x, mean 1.
  double factor() const { return x_; }
  // F(x), the CDF of x at its value: uniform on (0, 1) whatever the case. Small in a fade. For the
  // constant case there is no fluctuation to share: NaN.
  double uniform() const;
  int components() const { return case_ == SwerlingCase::Three || case_ == SwerlingCase::Four ? 4 : 2; }
  bool fluctuating() const { return case_ != SwerlingCase::Constant; }
  bool holds_per_scan() const { return case_ == SwerlingCase::One || case_ == SwerlingCase::Three; }

 private:
  void update_factor();

  SwerlingCase case_;
  double bandwidth_, scan_period_;
  GaussMarkov g_[4];
  double x_ = 1.0;
  double last_time_ = 0.0;  // time of the last evaluation of the g's
  double last_dt_ = -1.0, rho_ = 0.0;
  double scan_start_ = 0.0;
  long long scan_ = 0;
};

// CDF of the chi-square fluctuation of mean 1 with 2 (exponential) or 4 degrees of freedom.
double rcs_cdf(double x, int components);

}  // namespace trackflow::sim
