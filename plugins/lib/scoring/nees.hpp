// Purpose: the terms of a NEES e' C^-1 e (6-D ENU state) from one U D U' factorisation of C, whose leading three also give the position NEES.
#pragma once

#include <trackflow/items.hpp>

namespace trackflow::metrics {

// C = U D U' (U unit lower triangular, read from C's lower triangle), y = U^-1 e:
// e' C^-1 e = sum_j y_j^2 / D_j, and terms[j] = y_j^2 / D_j. The leading 3x3 block of C has the
// leading factors, so the position NEES is terms[0] + terms[1] + terms[2]. No square roots:
// the one division per column is all that chains one column to the next (a Cholesky factor adds
// a square root to each, which for a 6x6 is most of its time). False when C is not positive
// definite (a non-positive or NaN pivot); infinities are the caller's to check.
inline bool nees_terms(const Mat6& C, const Vec6& e, double terms[6]) {
  double U[6][6], W[6][6], y[6];  // W(i, k) = U(i, k) D(k)
  for (int j = 0; j < 6; ++j) {
    double d = C(j, j);
    for (int k = 0; k < j; ++k) d -= W[j][k] * U[j][k];
    if (!(d > 0.0)) return false;
    const double inv = 1.0 / d;
    for (int i = j + 1; i < 6; ++i) {
      double s = C(i, j);
      for (int k = 0; k < j; ++k) s -= W[i][k] * U[j][k];
      W[i][j] = s;
      U[i][j] = s * inv;
    }
    double t = e(j);
    for (int k = 0; k < j; ++k) t -= U[j][k] * y[k];
    y[j] = t;
    terms[j] = t * t * inv;
  }
  return true;
}

}  // namespace trackflow::metrics
