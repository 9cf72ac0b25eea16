#pragma once
/// \file offspring.hpp
/// Offspring expansion of an RBPF particle (Huerta eq. 23): every situation vector s_t in {0..N_z-1}^B is a
/// candidate child, with the prior factor prod_b T_b(s_{b,t-1}, s_{b,t}) p(o_b | s_{b,t}) of eqs. (25)/(32).
/// Situation vectors are encoded as base-N_z integers (key = sum_b s_b N_z^b), so N_z^B must fit in 62 bits.
///
/// Bounded enumeration: when N_z^B exceeds a limit K, only the K children with the largest prior factor
/// are generated, exactly, by a best-first search over the per-anchor factors (the factor is a product
/// over anchors, so the K best vectors are found without visiting the others), in preallocated buffers. With
/// K >= N_z^B it is the full enumeration (same set); in the classical RBPF the UKF likelihood of a child is
/// only known after its UKF, so the bound ranks by prior times quality likelihood.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nlosloc/core/types.hpp"

namespace nlosloc::rbpf {

/// N_z^B, or 0 when it exceeds 2^62 (too many to encode).
inline std::uint64_t situation_count(int num_conditions, int num_anchors) {
  NLOSLOC_ENSURE(num_conditions >= 1,
                 "num_conditions: expected an integer >= 1, got " + std::to_string(num_conditions));
  NLOSLOC_ENSURE(num_anchors >= 0,
                 "num_anchors: expected an integer >= 0, got " + std::to_string(num_anchors));
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
/// prob(b, s_b) += w for every anchor b of the situation `key` (prob is B x N_z): a particle's weight added
/// to the per-anchor situation probabilities, without decoding into a vector.
template <class D>
void add_situation_weight(std::uint64_t key, double w, Eigen::MatrixBase<D>& prob) {
  const auto nz = static_cast<std::uint64_t>(prob.cols());
  for (Eigen::Index b = 0; b < prob.rows(); ++b) {
    prob(b, static_cast<Eigen::Index>(key % nz)) += w;
    key /= nz;
  }
}

namespace detail {
/// True when a log weight `x` computed in one summation order may reach `cut` computed in another: x is
/// compared with a relative 1e-9 margin, so pruning by a bound never drops a child the exact order keeps.
/// An impossible weight (-inf, or NaN) reaches nothing.
inline bool may_reach(double x, double cut) {
  return x > -std::numeric_limits<double>::infinity() && !(x + 1e-9 * (1.0 + std::abs(x)) < cut);
}
}  // namespace detail

namespace detail {
/// o[0..N_z) = anchor b's conditions by decreasing factor A(b, .), ties in condition order: a stable
/// insertion sort (N_z is small, and std::stable_sort may allocate a buffer).
inline void order_conditions(const MatX& A, int b, int* o) {
  const int nz = static_cast<int>(A.cols());
  for (int z = 0; z < nz; ++z) {
    int j = z;
    for (; j > 0 && A(b, o[j - 1]) < A(b, z); --j) o[j] = o[j - 1];
    o[j] = z;
  }
}
}  // namespace detail

/// Calls emit(key, sum_b A(b, s_b)) for every s in {0..N_z-1}^B (A is B x N_z, log factors), by an
/// odometer that updates the running sum in O(1) amortised per child. A factor of -inf (a zero transition
/// probability or quality density) makes its children -inf: the running sum skips it and counts it
/// instead, as -inf - (-inf) would turn every later child into NaN.
template <class Emit>
void enumerate_all(const MatX& A, Emit&& emit) {
  const int B = static_cast<int>(A.rows()), nz = static_cast<int>(A.cols());
  constexpr double kNegInf = -std::numeric_limits<double>::infinity();
  auto finite_part = [](double a) { return a == kNegInf ? 0.0 : a; };
  std::uint64_t pow_b[64];
  pow_b[0] = 1;
  for (int b = 1; b < B && b < 64; ++b) pow_b[b] = pow_b[b - 1] * static_cast<std::uint64_t>(nz);
  int digit[64] = {0};
  double sum = 0.0;
  int impossible = 0;  // digits whose factor is -inf
  for (int b = 0; b < B; ++b) {
    sum += finite_part(A(b, 0));
    impossible += A(b, 0) == kNegInf ? 1 : 0;
  }
  auto move = [&](int b, int to) {
    const double from_a = A(b, digit[b]), to_a = A(b, to);
    sum += finite_part(to_a) - finite_part(from_a);
    impossible += (to_a == kNegInf ? 1 : 0) - (from_a == kNegInf ? 1 : 0);
  };
  std::uint64_t key = 0;
  for (;;) {
    emit(key, impossible > 0 ? kNegInf : sum);
    int b = 0;
    while (b < B) {
      if (digit[b] + 1 < nz) {
        move(b, digit[b] + 1);
        ++digit[b];
        key += pow_b[b];
        break;
      }
      move(b, 0);
      key -= pow_b[b] * static_cast<std::uint64_t>(digit[b]);
      digit[b] = 0;
      ++b;
    }
    if (b == B) return;
  }
}

/// One node of the best-first search: a rank vector (rank r_b of anchor b's option, base-N_z encoded like
/// a key), its sum, and the highest anchor whose rank is non-zero (0 for the root).
struct BestFirstNode {
  double sum;
  std::uint64_t ranks;
  int last;
};

/// Reusable buffers of enumerate_best. reserve(B, N_z, limit) sizes them once; the search then never
/// allocates for those sizes (the RBPF keeps one per thread so its step does no heap allocation).
struct BestFirstWorkspace {
  std::vector<int> order;            // B x N_z: anchor b's options by decreasing factor (row b)
  std::vector<BestFirstNode> heap;   // open nodes; at most 1 + limit * B are ever pushed
  std::vector<std::uint64_t> power;  // N_z^b
  void reserve(int B, int nz, std::uint64_t limit) {
    order.reserve(static_cast<std::size_t>(B) * static_cast<std::size_t>(nz));
    power.reserve(static_cast<std::size_t>(B));
    heap.reserve(static_cast<std::size_t>(1 + limit * static_cast<std::uint64_t>(B)));
  }
};

/// Calls emit(key, sum) for the `limit` situation vectors with the largest sum_b A(b, s_b), in decreasing
/// order, ties by the smaller rank vector (exact best-first search). Each anchor's options are sorted by
/// factor; a node's children raise the rank of one anchor b >= its `last`, so every rank vector has exactly
/// one parent (lower its highest non-zero rank) whose sum is not smaller: a heap over this tree pops the
/// vectors in decreasing order without a visited set. limit >= N_z^B gives every vector.
template <class Emit>
void enumerate_best(const MatX& A, std::uint64_t limit, BestFirstWorkspace& ws, Emit&& emit) {
  const int B = static_cast<int>(A.rows()), nz = static_cast<int>(A.cols());
  const auto unz = static_cast<std::uint64_t>(nz);
  ws.order.resize(static_cast<std::size_t>(B) * static_cast<std::size_t>(nz));
  ws.power.resize(static_cast<std::size_t>(B));
  auto opt = [&](int b, int r) {
    return ws.order[static_cast<std::size_t>(b) * static_cast<std::size_t>(nz) + static_cast<std::size_t>(r)];
  };
  for (int b = 0; b < B; ++b) {
    detail::order_conditions(A, b,
                             ws.order.data() + static_cast<std::size_t>(b) * static_cast<std::size_t>(nz));
    ws.power[static_cast<std::size_t>(b)] = b == 0 ? 1 : ws.power[static_cast<std::size_t>(b - 1)] * unz;
  }
  // Max-heap by sum, then by the smaller rank vector (deterministic ties).
  auto lower = [](const BestFirstNode& a, const BestFirstNode& b) {
    return a.sum != b.sum ? a.sum < b.sum : a.ranks > b.ranks;
  };
  ws.heap.clear();
  constexpr double kNegInf = -std::numeric_limits<double>::infinity();
  double root = 0.0;
  for (int b = 0; b < B; ++b) root += A(b, opt(b, 0));
  ws.heap.push_back({root, 0, 0});
  std::uint64_t emitted = 0;
  while (!ws.heap.empty() && emitted < limit) {
    std::pop_heap(ws.heap.begin(), ws.heap.end(), lower);
    const BestFirstNode it = ws.heap.back();
    ws.heap.pop_back();
    std::uint64_t key = 0, rest = it.ranks;
    for (int b = 0; b < B; ++b) {
      key += ws.power[static_cast<std::size_t>(b)] *
             static_cast<std::uint64_t>(opt(b, static_cast<int>(rest % unz)));
      rest /= unz;
    }
    emit(key, it.sum);
    ++emitted;
    for (int b = it.last; b < B; ++b) {
      const int r = static_cast<int>((it.ranks / ws.power[static_cast<std::size_t>(b)]) % unz);
      if (r + 1 >= nz) continue;
      // Options only get lighter along the tree: a -inf node's children are -inf (not -inf - (-inf)).
      const double sum = it.sum == kNegInf ? kNegInf : it.sum - A(b, opt(b, r)) + A(b, opt(b, r + 1));
      ws.heap.push_back({sum, it.ranks + ws.power[static_cast<std::size_t>(b)], b});
      std::push_heap(ws.heap.begin(), ws.heap.end(), lower);
    }
  }
}

/// enumerate_best with its own (allocated) workspace.
template <class Emit>
void enumerate_best(const MatX& A, std::uint64_t limit, Emit&& emit) {
  BestFirstWorkspace ws;
  enumerate_best(A, limit, ws, std::forward<Emit>(emit));
}

namespace detail {
/// Depth-first search of enumerate_above: anchors [b, B) open, `sum` = base plus the chosen factors,
/// `bound` = sum plus the best factor of every open anchor (the heaviest completion).
template <class Cut, class Emit>
struct AboveSearch {
  const MatX& A;
  const int* opt;  // B x N_z, row b: anchor b's conditions by decreasing factor
  const std::uint64_t* pow;
  int B, nz;
  Cut& cut;
  Emit& emit;
  void run(int b, double sum, double bound, std::uint64_t key) {
    if (b == B) {
      emit(key, sum);
      return;
    }
    const int* o = opt + static_cast<std::size_t>(b) * static_cast<std::size_t>(nz);
    const double best = A(b, o[0]);
    for (int r = 0; r < nz; ++r) {
      const double a = A(b, o[r]);
      const double ub = bound - best + a;  // heaviest completion with this condition
      if (!may_reach(ub, cut())) break;    // the next conditions are lighter still
      run(b + 1, sum + a, ub, key + static_cast<std::uint64_t>(o[r]) * pow[b]);
    }
  }
};
}  // namespace detail

/// Calls emit(key, base + sum_b A(b, s_b)) for the situation vectors whose weight reaches cut(), without
/// visiting the others (the reordered RBPF's children above its running M-th weight): a depth-first
/// search over the anchors, each anchor's conditions by decreasing factor, that abandons a branch as soon
/// as its heaviest completion falls below cut(). cut() is read as the search goes and must not decrease;
/// vectors up to a relative 1e-9 below it may be emitted too (summation-order margin). `pow` holds N_z^b
/// (size B); `opt` is caller-owned scratch of B x N_z ints (no allocation).
template <class Cut, class Emit>
void enumerate_above(const MatX& A, double base, const std::uint64_t* pow, int* opt, Cut&& cut, Emit&& emit) {
  const int B = static_cast<int>(A.rows()), nz = static_cast<int>(A.cols());
  double bound = base;
  for (int b = 0; b < B; ++b) {
    int* o = opt + static_cast<std::size_t>(b) * static_cast<std::size_t>(nz);
    detail::order_conditions(A, b, o);
    bound += A(b, o[0]);
  }
  detail::AboveSearch<std::remove_reference_t<Cut>, std::remove_reference_t<Emit>> search{A,  opt, pow, B,
                                                                                          nz, cut, emit};
  search.run(0, base, bound, 0);
}

/// Enumerates the children of one particle: all N_z^B when N_z^B <= limit, else the `limit` best (above).
/// `ws` serves the bounded case (see BestFirstWorkspace::reserve).
template <class Emit>
void enumerate_offspring(const MatX& A, std::uint64_t limit, BestFirstWorkspace& ws, Emit&& emit) {
  const std::uint64_t total = situation_count(static_cast<int>(A.cols()), static_cast<int>(A.rows()));
  if (total != 0 && total <= limit)
    enumerate_all(A, std::forward<Emit>(emit));
  else
    enumerate_best(A, limit, ws, std::forward<Emit>(emit));
}

/// enumerate_offspring with its own workspace.
template <class Emit>
void enumerate_offspring(const MatX& A, std::uint64_t limit, Emit&& emit) {
  BestFirstWorkspace ws;
  enumerate_offspring(A, limit, ws, std::forward<Emit>(emit));
}

}  // namespace nlosloc::rbpf
