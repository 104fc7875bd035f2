// Purpose: the clusters of JPDA — connected components of tracks that share a gated detection (union-find), in a deterministic order, each with its tracks, detections and pairs renumbered locally.
#pragma once

#include "memory/grow.hpp"

#include <algorithm>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow::association {

// One gated pair of a scan as JPDA weighs it: log l_ij, l_ij = P_D g_ij / lambda (the log of the
// likelihood ratio whose negative is assoc.gnn's cost). Log domain so that likelihoods of 1e-300
// or 1e300 neither underflow nor overflow before the per-track scaling (jpda_weights.hpp).
struct JpdaPair {
  int track = 0, detection = 0;
  double log_weight = 0.0;
};

// A pair of one cluster in its local numbering (track and detection: positions in the cluster's
// lists); `source` is its index in the list given to JpdaClusters::build.
struct JpdaClusterPair {
  int track = 0, detection = 0;
  double log_weight = 0.0;
  int source = 0;
};

// One cluster. Views into JpdaClusters; valid until its next build.
struct JpdaCluster {
  std::span<const int> tracks;             // scan track indices, ascending
  std::span<const int> detections;         // scan detection indices, ascending
  std::span<const JpdaClusterPair> pairs;  // by local track, then local detection
  std::span<const int> track_begin;        // pairs of local track t: [track_begin[t], track_begin[t + 1])
  int size_tracks() const { return static_cast<int>(tracks.size()); }
  int size_detections() const { return static_cast<int>(detections.size()); }
};

// Why clusters (Bar-Shalom, Willett & Tian 2011, §8.3; Fortmann, Bar-Shalom & Scheffe 1983): two
// tracks that share no detection, directly or through a chain of tracks, are independent in every
// joint event — the event weights factor over the components of the bipartite gating graph — so
// each component's marginal association probabilities are computed on its own, and the cost of
// exact JPDA grows with the largest cluster rather than with the scan.
//
// Components by union-find (path halving, union by index) over tracks 0..n-1 and detections
// n..n+m-1. Every track is in exactly one cluster (alone, with no detection, when it gates none);
// a detection gated by no track is in none.
//
// Order (deterministic, whatever the order of the input pairs): clusters by their smallest track
// index; in a cluster, tracks ascending, detections ascending, pairs by (track, detection).
//
// Storage: members, grown by the largest scan; after that build allocates nothing.
class JpdaClusters {
 public:
  // n tracks, m detections; every pair's indices in range, no pair twice (std::invalid_argument).
  void build(int n, int m, std::span<const JpdaPair> pairs) {
    if (n < 0 || m < 0) throw std::invalid_argument("jpda clusters: negative size");
    const auto N = static_cast<std::size_t>(n) + static_cast<std::size_t>(m);
    parent_.resize(N);
    for (std::size_t k = 0; k < N; ++k) parent_[k] = static_cast<int>(k);
    for (const JpdaPair& p : pairs) {
      if (p.track < 0 || p.track >= n || p.detection < 0 || p.detection >= m)
        throw std::invalid_argument("jpda clusters: pair (" + std::to_string(p.track) + ", " +
                                    std::to_string(p.detection) + ") out of range");
      unite(p.track, n + p.detection);
    }
    // Cluster ids in order of each component's smallest track: the first track met (ascending)
    // names its component.
    memory::assign_grown(cluster_of_root_, N, -1);
    memory::assign_grown(local_, N, 0);
    clusters_ = 0;
    memory::assign_grown(count_, static_cast<std::size_t>(n) + 1, 0);
    for (int i = 0; i < n; ++i) {
      int& c = cluster_of_root_[static_cast<std::size_t>(find(i))];
      if (c < 0) c = clusters_++;
      local_[static_cast<std::size_t>(i)] = count_[static_cast<std::size_t>(c)]++;  // tracks ascending
    }
    // Offsets of each cluster's tracks, detections and pairs (counting sort by cluster id).
    offsets(track_start_, count_, clusters_);
    memory::assign_grown(count_, static_cast<std::size_t>(clusters_) + 1, 0);
    for (int j = 0; j < m; ++j) {
      const int c = cluster_of_root_[static_cast<std::size_t>(find(n + j))];
      if (c >= 0) local_[static_cast<std::size_t>(n + j)] = count_[static_cast<std::size_t>(c)]++;
    }
    offsets(detection_start_, count_, clusters_);
    memory::assign_grown(count_, static_cast<std::size_t>(clusters_) + 1, 0);
    for (const JpdaPair& p : pairs) ++count_[static_cast<std::size_t>(cluster_of(p.track))];
    offsets(pair_start_, count_, clusters_);
    tracks_.resize(static_cast<std::size_t>(n));
    detections_.resize(static_cast<std::size_t>(detection_start_.back()));
    pairs_.resize(pairs.size());
    for (int i = 0; i < n; ++i)
      tracks_[static_cast<std::size_t>(track_start_[static_cast<std::size_t>(cluster_of(i))] + local(i))] = i;
    for (int j = 0; j < m; ++j) {
      const int c = cluster_of_root_[static_cast<std::size_t>(find(n + j))];
      if (c >= 0)
        detections_[static_cast<std::size_t>(detection_start_[static_cast<std::size_t>(c)] + local(n + j))] = j;
    }
    memory::assign_grown(fill_, static_cast<std::size_t>(clusters_), 0);
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const JpdaPair& p = pairs[k];
      const auto c = static_cast<std::size_t>(cluster_of(p.track));
      pairs_[static_cast<std::size_t>(pair_start_[c] + fill_[c]++)] = {local(p.track), local(n + p.detection),
                                                                       p.log_weight, static_cast<int>(k)};
    }
    // Per cluster: pairs by (local track, local detection) — unique keys, so std::sort's result is
    // the same for every input order — and each local track's first pair.
    track_begin_.resize(static_cast<std::size_t>(n + clusters_));
    for (int c = 0; c < clusters_; ++c) {
      const auto first = pairs_.begin() + pair_start_[static_cast<std::size_t>(c)];
      const auto last = pairs_.begin() + pair_start_[static_cast<std::size_t>(c) + 1];
      std::sort(first, last, [](const JpdaClusterPair& a, const JpdaClusterPair& b) {
        return a.track != b.track ? a.track < b.track : a.detection < b.detection;
      });
      for (auto it = first; it != last && it + 1 != last; ++it)
        if (it->track == (it + 1)->track && it->detection == (it + 1)->detection)
          throw std::invalid_argument(
              "jpda clusters: pair (" + std::to_string(pairs[static_cast<std::size_t>(it->source)].track) + ", " +
              std::to_string(pairs[static_cast<std::size_t>(it->source)].detection) + ") given twice");
      const int nt = track_start_[static_cast<std::size_t>(c) + 1] - track_start_[static_cast<std::size_t>(c)];
      int* begin = track_begin_.data() + track_start_[static_cast<std::size_t>(c)] + c;
      int k = 0;
      const int np = static_cast<int>(last - first);
      for (int t = 0; t <= nt; ++t) {
        while (k < np && first[k].track < t) ++k;
        begin[t] = k;
      }
    }
  }

  int size() const { return clusters_; }

  JpdaCluster operator[](int c) const {
    const auto k = static_cast<std::size_t>(c);
    const std::span<const int> all_tracks(tracks_), all_detections(detections_), all_begin(track_begin_);
    const std::span<const JpdaClusterPair> all_pairs(pairs_);
    const auto nt = static_cast<std::size_t>(track_start_[k + 1] - track_start_[k]);
    return {all_tracks.subspan(static_cast<std::size_t>(track_start_[k]), nt),
            all_detections.subspan(static_cast<std::size_t>(detection_start_[k]),
                                   static_cast<std::size_t>(detection_start_[k + 1] - detection_start_[k])),
            all_pairs.subspan(static_cast<std::size_t>(pair_start_[k]),
                              static_cast<std::size_t>(pair_start_[k + 1] - pair_start_[k])),
            all_begin.subspan(static_cast<std::size_t>(track_start_[k]) + k, nt + 1)};
  }

  // The cluster of scan track i (valid after build).
  int cluster_of(int i) const { return cluster_of_root_[static_cast<std::size_t>(root(i))]; }

 private:
  int find(int k) {
    while (parent_[static_cast<std::size_t>(k)] != k) {
      parent_[static_cast<std::size_t>(k)] = parent_[static_cast<std::size_t>(parent_[static_cast<std::size_t>(k)])];
      k = parent_[static_cast<std::size_t>(k)];
    }
    return k;
  }
  int root(int k) const {
    while (parent_[static_cast<std::size_t>(k)] != k) k = parent_[static_cast<std::size_t>(k)];
    return k;
  }
  // The smaller index becomes the root (any deterministic rule would do: cluster ids come from
  // each component's smallest track, not from its root).
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent_[static_cast<std::size_t>(b)] = a;
  }
  int local(int k) const { return local_[static_cast<std::size_t>(k)]; }
  // start[c] = sum of count[0..c-1], c = 0..clusters.
  static void offsets(std::vector<int>& start, const std::vector<int>& count, int clusters) {
    start.resize(static_cast<std::size_t>(clusters) + 1);
    start[0] = 0;
    for (int c = 0; c < clusters; ++c)
      start[static_cast<std::size_t>(c) + 1] = start[static_cast<std::size_t>(c)] + count[static_cast<std::size_t>(c)];
  }

  std::vector<int> parent_, cluster_of_root_, local_, count_, fill_;
  std::vector<int> track_start_, detection_start_, pair_start_, track_begin_;
  std::vector<int> tracks_, detections_;
  std::vector<JpdaClusterPair> pairs_;
  int clusters_ = 0;
};

}  // namespace trackflow::association
