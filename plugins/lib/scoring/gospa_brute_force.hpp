// Purpose: GOSPA's two definitions by enumerating every assignment, the reference of the GOSPA tests.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <vector>

namespace trackflow::metrics::test {

// Eq. (2) (Proposition 1, alpha = 2) of Rahmathullah et al.: the minimum over every partial
// assignment gamma -- each truth paired with a distinct track or with none -- of
// sum_{gamma} d^p + c^p / 2 (|X| + |Y| - 2 |gamma|), with the base distance d not cut off.
template <int Dim>
class PartialAssignmentGospa {
 public:
  using Points = std::vector<Eigen::Matrix<double, Dim, 1>>;
  double pow_p(const Points& truth, const Points& tracks, double c, double p) {
    truth_ = &truth;
    tracks_ = &tracks;
    half_cp_ = std::pow(c, p) / 2.0;
    p_ = p;
    used_.assign(tracks.size(), false);
    best_ = std::numeric_limits<double>::infinity();
    visit(0, 0.0, 0);
    return best_;
  }

 private:
  void visit(std::size_t i, double so_far, int pairs) {
    if (i == truth_->size()) {
      const double total = so_far + half_cp_ * static_cast<double>(truth_->size() + tracks_->size() - 2 * pairs);
      if (total < best_) best_ = total;
      return;
    }
    visit(i + 1, so_far, pairs);  // truth i missed
    for (std::size_t j = 0; j < tracks_->size(); ++j) {
      if (used_[j]) continue;
      used_[j] = true;
      visit(i + 1, so_far + std::pow(((*truth_)[i] - (*tracks_)[j]).norm(), p_), pairs + 1);
      used_[j] = false;
    }
  }
  const Points* truth_ = nullptr;
  const Points* tracks_ = nullptr;
  double half_cp_ = 0.0, p_ = 1.0, best_ = 0.0;
  std::vector<bool> used_;
};

// Eq. (1) (Definition 1) and OSPA's numerator: the minimum over every injection pi of the smaller
// set into the larger of sum min(d, c)^p, plus `per_unmatched` for each element left over
// (c^p / alpha for GOSPA, c^p for OSPA before its division by the larger size).
template <int Dim>
class InjectionGospa {
 public:
  using Points = std::vector<Eigen::Matrix<double, Dim, 1>>;
  double pow_p(const Points& truth, const Points& tracks, double c, double p, double per_unmatched) {
    small_ = truth.size() <= tracks.size() ? &truth : &tracks;
    large_ = truth.size() <= tracks.size() ? &tracks : &truth;
    c_ = c;
    p_ = p;
    used_.assign(large_->size(), false);
    best_ = std::numeric_limits<double>::infinity();
    visit(0, 0.0);
    return best_ + per_unmatched * static_cast<double>(large_->size() - small_->size());
  }

 private:
  void visit(std::size_t i, double so_far) {
    if (i == small_->size()) {
      if (so_far < best_) best_ = so_far;
      return;
    }
    for (std::size_t j = 0; j < large_->size(); ++j) {
      if (used_[j]) continue;
      used_[j] = true;
      visit(i + 1, so_far + std::pow(std::min(((*small_)[i] - (*large_)[j]).norm(), c_), p_));
      used_[j] = false;
    }
  }
  const Points* small_ = nullptr;
  const Points* large_ = nullptr;
  double c_ = 1.0, p_ = 1.0, best_ = 0.0;
  std::vector<bool> used_;
};

}  // namespace trackflow::metrics::test
