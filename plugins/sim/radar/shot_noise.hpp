// Purpose: which samples of a run fall in a shot-noise burst (paper 000 Case 1: 10 samples every 4000).
#pragma once

namespace trackflow::sim {

// Bursts of `length` samples starting at sample `offset`, `offset + period`, ... (samples are
// the radar's emitted measurements of one run, counted from 0).
struct ShotNoise {
  bool enabled = false;
  long long length = 10, period = 4000, offset = 4000;
  double magnitude = 1e6;  // multiplies the σ of every channel during a burst

  bool in_burst(long long sample) const {
    return enabled && sample >= offset && (sample - offset) % period < length;
  }
  double factor(long long sample) const { return in_burst(sample) ? magnitude : 1.0; }
};

}  // namespace trackflow::sim
