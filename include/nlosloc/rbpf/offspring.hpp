#pragma once
/// \file offspring.hpp
/// Offspring expansion of an RBPF particle (Huerta eq. 23): every situation vector s_t in {0..N_z-1}^B is a
/// candidate child, with the prior factor prod_b T_b(s_{b,t-1}, s_{b,t}) p(o_b | s_{b,t}) of eqs. (25)/(32).
/// Situation vectors are encoded as base-N_z integers (key = sum_b s_b N_z^b), so N_z^B must fit in 62 bits.
///
/// Bounded enumeration: when N_z^B exceeds a limit K, only the K children with the largest prior factor
/// are generated, exactly, by a best-first search over the per-anchor factors (the factor is a product
/// over anchors, so the K best vectors are found without visiting the others). With K >= N_z^B it is the
/// full enumeration (same set); in the classical RBPF the UKF likelihood of a child is only known after
/// its UKF, so the bound ranks by prior times quality likelihood.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <queue>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "nlosloc/core/types.hpp"

namespace nlosloc::rbpf {

/// N_z^B, or 0 when it exceeds 2^62 (too many to encode).
inline std::uint64_t situation_count(int num_conditions, int num_anchors) {
  std::uint64_t c = 1;
  for (int b = 0; b < num_anchors; ++b) {
    if (c > (std::uint64_t{1} << 62) / static_cast<std::uint64_t>(num_conditions)) return 0;
    c *= static_cast<std::uint64_t>(num_conditions);
  }
  return c;
}

/// Key of a situation vector (base N_z digits, anchor 0 least significant).
template <class D>
std::uint64_t encode_situation(const Eigen::MatrixBase<D>& s, int num_conditions) {
  std::uint64_t k = 0;
  for (Eigen::Index b = s.size() - 1; b >= 0; --b)
    k = k * static_cast<std::uint64_t>(num_conditions) + static_cast<std::uint64_t>(s[b]);
  return k;
}
/// Inverse of encode_situation into s (size B).
template <class D>
void decode_situation(std::uint64_t key, int num_conditions, Eigen::MatrixBase<D>& s) {
  for (Eigen::Index b = 0; b < s.size(); ++b) {
    s[b] = static_cast<int>(key % static_cast<std::uint64_t>(num_conditions));
    key /= static_cast<std::uint64_t>(num_conditions);
  }
}

/// Calls emit(key, sum_b A(b, s_b)) for every s in {0..N_z-1}^B (A is B x N_z, log factors), by an
/// odometer that updates the running sum in O(1) amortised per child.
template <class Emit>
void enumerate_all(const MatX& A, Emit&& emit) {
  const int B = static_cast<int>(A.rows()), nz = static_cast<int>(A.cols());
  std::uint64_t pow_b[64];
  pow_b[0] = 1;
  for (int b = 1; b < B && b < 64; ++b) pow_b[b] = pow_b[b - 1] * static_cast<std::uint64_t>(nz);
  int digit[64] = {0};
  double sum = A.col(0).sum();
  std::uint64_t key = 0;
  for (;;) {
    emit(key, sum);
    int b = 0;
    while (b < B) {
      if (digit[b] + 1 < nz) {
        sum += A(b, digit[b] + 1) - A(b, digit[b]);
        ++digit[b];
        key += pow_b[b];
        break;
      }
      sum += A(b, 0) - A(b, digit[b]);
      key -= pow_b[b] * static_cast<std::uint64_t>(digit[b]);
      digit[b] = 0;
      ++b;
    }
    if (b == B) return;
  }
}

/// Calls emit(key, sum) for the `limit` situation vectors with the largest sum_b A(b, s_b), in decreasing
/// order (exact best-first search: each anchor's options sorted by factor, a heap of rank vectors, visited
/// set to avoid repeats). limit >= N_z^B gives every vector.
template <class Emit>
void enumerate_best(const MatX& A, std::uint64_t limit, Emit&& emit) {
  const int B = static_cast<int>(A.rows()), nz = static_cast<int>(A.cols());
  std::vector<std::vector<int>> order(static_cast<std::size_t>(B));
  for (int b = 0; b < B; ++b) {
    auto& o = order[static_cast<std::size_t>(b)];
    o.resize(static_cast<std::size_t>(nz));
    for (int z = 0; z < nz; ++z) o[static_cast<std::size_t>(z)] = z;
    std::stable_sort(o.begin(), o.end(), [&](int p, int q) { return A(b, p) > A(b, q); });
  }
  // A node is a rank vector, encoded base N_z like a key (rank r_b of anchor b).
  auto node_sum = [&](const std::vector<int>& r) {
    double s = 0.0;
    for (int b = 0; b < B; ++b)
      s += A(b, order[static_cast<std::size_t>(b)][static_cast<std::size_t>(r[static_cast<std::size_t>(b)])]);
    return s;
  };
  using Item = std::pair<double, std::vector<int>>;
  auto cmp = [](const Item& a, const Item& b) { return a.first < b.first; };
  std::priority_queue<Item, std::vector<Item>, decltype(cmp)> heap(cmp);
  std::unordered_set<std::uint64_t> seen;
  auto rank_key = [&](const std::vector<int>& r) {
    std::uint64_t k = 0;
    for (int b = B - 1; b >= 0; --b)
      k = k * static_cast<std::uint64_t>(nz) + static_cast<std::uint64_t>(r[static_cast<std::size_t>(b)]);
    return k;
  };
  std::vector<int> r0(static_cast<std::size_t>(B), 0);
  heap.emplace(node_sum(r0), r0);
  seen.insert(0);
  std::uint64_t emitted = 0;
  while (!heap.empty() && emitted < limit) {
    Item it = heap.top();
    heap.pop();
    std::uint64_t key = 0;
    for (int b = B - 1; b >= 0; --b)
      key =
          key * static_cast<std::uint64_t>(nz) +
          static_cast<std::uint64_t>(order[static_cast<std::size_t>(b)]
                                          [static_cast<std::size_t>(it.second[static_cast<std::size_t>(b)])]);
    emit(key, it.first);
    ++emitted;
    for (int b = 0; b < B; ++b) {
      auto& rb = it.second[static_cast<std::size_t>(b)];
      if (rb + 1 >= nz) continue;
      ++rb;
      if (seen.insert(rank_key(it.second)).second) heap.emplace(node_sum(it.second), it.second);
      --rb;
    }
  }
}

/// Enumerates the children of one particle: all N_z^B when N_z^B <= limit, else the `limit` best (above).
template <class Emit>
void enumerate_offspring(const MatX& A, std::uint64_t limit, Emit&& emit) {
  const std::uint64_t total = situation_count(static_cast<int>(A.cols()), static_cast<int>(A.rows()));
  if (total != 0 && total <= limit)
    enumerate_all(A, std::forward<Emit>(emit));
  else
    enumerate_best(A, limit, std::forward<Emit>(emit));
}

}  // namespace nlosloc::rbpf
