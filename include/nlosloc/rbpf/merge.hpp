#pragma once
/// \file merge.hpp
/// Merge and select of the RBPF (Huerta Sec. V-A.3): particles with the same current situation vector whose
/// kinetic means are closer than d_min (distance eq. 29) are merged by moving the weight of the lighter one
/// to the heavier one (eq. 30); then the M heaviest are kept (pruning). Weights are logs throughout.
///
/// Order of the merge (the paper leaves it open when chains a-b-c exist): particles are visited by
/// decreasing weight; each particle not yet absorbed absorbs every lighter, not yet absorbed particle of its
/// group within d_min. The result therefore does not depend on the input order (ties by index).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

#include "nlosloc/core/types.hpp"

namespace nlosloc::rbpf {

/// log(exp(a) + exp(b)) without overflow; exact for -inf.
inline double log_add(double a, double b) {
  if (a < b) std::swap(a, b);
  if (b == -std::numeric_limits<double>::infinity()) return a;
  return a + std::log1p(std::exp(b - a));
}

/// Default merge threshold of Huerta eq. (31): d_min = sigma^2 / (10 M), with sigma^2 the variance of the
/// position estimate (m^2) and M the number of particles.
inline double default_merge_threshold(double position_variance, int num_particles) {
  NLOSLOC_ENSURE(num_particles >= 1, "num_particles: expected M >= 1");
  nlosloc::detail::ensure_nonnegative(position_variance, "position_variance");
  return position_variance / (10.0 * static_cast<double>(num_particles));  // eq. (31)
}

/// Reusable buffers of the merge (sized on first use, reused afterwards; reserve(n) sizes them up front so
/// a merge of up to n particles does not allocate).
struct MergeWorkspace {
  std::vector<int> order, tmp_order;
  std::vector<std::uint64_t> sorted_keys, tmp_keys;
  std::vector<int> count;  // radix / counting-sort histogram
  static constexpr int kRadixBits = 11;
  /// Above this size the grouping uses the LSD radix sort (linear) instead of a comparison sort.
  static constexpr int kRadixMin = 4096;
  /// Keys spanning at most this many values per particle (plus kCountSlack) are grouped by one counting
  /// pass, whatever n: the RBPF's merge groups a few hundred children over N_z^B = 64 keys (H2), where
  /// the whole merge took 22 us of a 120 us step with the comparison sort, 9.9 us with this pass (4.4 us
  /// of it the ordering; instrumented, one thread).
  static constexpr std::size_t kCountPerItem = 2, kCountSlack = 64, kCountMax = std::size_t{1} << 16;
  static std::size_t count_limit(std::size_t n) {
    return std::min(kCountPerItem * n + kCountSlack, kCountMax);
  }
  void reserve(std::size_t n) {
    order.reserve(n);
    sorted_keys.reserve(n);
    const bool radix = n >= static_cast<std::size_t>(kRadixMin);
    count.reserve(std::max(count_limit(n) + 1, radix ? std::size_t{1} << kRadixBits : 0));
    if (radix) {
      tmp_order.reserve(n);
      tmp_keys.reserve(n);
    }
  }
};

/// The strict order of merge and selection: heavier log weight first, ties to the lower index, so the
/// kept set and the merge's visiting order are unique whatever order the candidates arrive in.
inline bool heavier_first(double wa, int a, double wb, int b) { return wa != wb ? wa > wb : a < b; }
/// That order on indices into the log weights `logw`.
struct HeavierFirst {
  const double* logw;
  bool operator()(int a, int b) const { return heavier_first(logw[a], a, logw[b], b); }
};
/// A candidate child of the reordered RBPF by value: log weight, index (p x children per parent + j: the
/// tie break of the strict order), parent p and situation key. The threads keep their candidates in
/// their own buffers, so selection and the UKF bank read them sequentially from the thread that made them
/// instead of scattered entries of shared arrays last written by another core.
struct ChildRecord {
  double logw;
  int idx;
  int parent;
  std::uint64_t key;
};
/// heavier_first on records.
struct HeavierRecordFirst {
  bool operator()(const ChildRecord& a, const ChildRecord& b) const {
    return heavier_first(a.logw, a.idx, b.logw, b.idx);
  }
};

/// The value at 0-based position k of a[0..n) sorted in decreasing order (k < n; no NaN); a and tmp (size
/// >= n) are scratch. Quickselect with a branch-free partition: the comparisons of a selection over a
/// few hundred weights are unpredictable, and the mispredictions of std::nth_element cost more than the
/// passes here.
inline double kth_largest(double* a, double* tmp, int n, int k) {
  int lo = 0, hi = n;
  while (hi - lo > 16) {
    const int mid = lo + (hi - lo) / 2;
    double x = a[lo], y = a[mid], z = a[hi - 1];  // median of three
    if (x > y) std::swap(x, y);
    if (y > z) std::swap(y, z);
    if (x > y) std::swap(x, y);
    const double pivot = y;
    // greater to the front of tmp[lo..), less to the back of tmp[..hi), equal counted
    int g = lo, l = hi;
    for (int i = lo; i < hi; ++i) {
      const double v = a[i];
      tmp[g] = v;
      g += v > pivot ? 1 : 0;
      tmp[l - 1] = v;
      l -= v < pivot ? 1 : 0;
    }
    // tmp[lo, g): greater; tmp[l, hi): less; the rest equals pivot
    if (k < g) {
      std::copy(tmp + lo, tmp + g, a + lo);
      hi = g;
    } else if (k < l) {
      return pivot;
    } else {
      std::copy(tmp + l, tmp + hi, a + l);
      lo = l;
    }
  }
  std::sort(a + lo, a + hi, std::greater<double>());
  return a[k];
}

/// Keeps in v its M heaviest records (strict order heavier_first) in no particular order; w, tmp and ties
/// are scratch (capacity >= v.size() for no allocation).
inline void keep_heaviest(std::vector<ChildRecord>& v, std::size_t M, std::vector<double>& w,
                          std::vector<double>& tmp, std::vector<ChildRecord>& ties) {
  if (v.size() <= M) return;
  const std::size_t n = v.size();
  if (M == 0) {
    v.clear();
    return;
  }
  w.resize(n);
  tmp.resize(n);
  for (std::size_t i = 0; i < n; ++i) w[i] = v[i].logw;
  const double cut = kth_largest(w.data(), tmp.data(), static_cast<int>(n), static_cast<int>(M) - 1);
  // heavier than the cut: all kept (fewer than M); equal to it: the lowest indices fill the rest
  std::size_t m = 0;
  ties.clear();
  for (std::size_t i = 0; i < n; ++i) {  // m <= i: only records already read are overwritten
    if (v[i].logw > cut)
      v[m++] = v[i];
    else if (v[i].logw == cut)
      ties.push_back(v[i]);
  }
  const std::size_t need = M - m;
  if (ties.size() > need)
    std::sort(ties.begin(), ties.end(),
              [](const ChildRecord& a, const ChildRecord& b) { return a.idx < b.idx; });
  for (std::size_t i = 0; i < need; ++i) v[m + i] = ties[i];
  v.resize(M);
}

namespace detail {
/// Sorts each run of equal keys in ws.order[0, n) (ws.sorted_keys) by `heavier`: an insertion sort for
/// the short runs of the merge (a few children per key), std::sort above 16.
template <class Heavier>
void sort_groups(std::size_t N, MergeWorkspace& ws, const Heavier& heavier) {
  for (std::size_t g0 = 0; g0 < N;) {
    std::size_t g1 = g0 + 1;
    while (g1 < N && ws.sorted_keys[g1] == ws.sorted_keys[g0]) ++g1;
    int* o = ws.order.data();
    if (g1 - g0 > 16) {
      std::sort(o + g0, o + g1, heavier);
    } else {
      for (std::size_t i = g0 + 1; i < g1; ++i) {
        const int v = o[i];
        std::size_t j = i;
        for (; j > g0 && heavier(v, o[j - 1]); --j) o[j] = o[j - 1];
        o[j] = v;
      }
    }
    g0 = g1;
  }
}

/// The smallest power of two that is at least n and at least lo (lo a power of two): the size of a table
/// indexed by a mask (LineGrid's buckets, the parallel merge's hash tables).
inline std::size_t pow2_at_least(std::size_t n, std::size_t lo) {
  std::size_t p = lo;
  while (p < n) p *= 2;
  return p;
}

/// Stable counting sort of items 0..n-1 by bucket(i) in [0, nb): calls place(i, position) once per item,
/// positions in bucket order (items of a bucket in index order). `ends` (nb + 1 entries) is the histogram;
/// on return ends[b] is where bucket b ends. Linear in n + nb; used wherever items are grouped by a small
/// integer (merge keys in a narrow range, the RBPF's sweep cells and kept children's parents).
template <class Count, class Bucket, class Place>
void counting_scatter(std::size_t n, std::size_t nb, Count* ends, Bucket bucket, Place place) {
  std::fill(ends, ends + nb + 1, Count{0});
  for (std::size_t i = 0; i < n; ++i) ++ends[static_cast<std::size_t>(bucket(i)) + 1];
  for (std::size_t b = 0; b < nb; ++b) ends[b + 1] += ends[b];
  for (std::size_t i = 0; i < n; ++i)
    place(i, static_cast<std::size_t>(ends[static_cast<std::size_t>(bucket(i))]++));
}

/// Candidate pairs for a distance test along one coordinate (the reordered RBPF's neighbour sweep, eq. 29).
/// Each point with a finite coordinate x becomes a row in cell floor((x - min x) / w), and cell c goes to
/// bucket c mod nb (nb a power of two >= 2 x points), the rows placed by one counting pass: linear. With
/// w = max(d, spread / 2^31) (1 + 1e-5) >= d, two points closer than d (|dx_0| <= ||dx|| < d) lie in the
/// same or adjacent cells: the margin covers the rounding of (x - min x) / w (below 1e-6 with fewer than
/// 2^31 cells, whose numbers then fit in 32 bits). So from each row, the later rows of its own cell and the
/// rows of the next cell cover every such pair once. Cells as wide as d rather than as wide as the spread
/// allows leave few other pairs: the sweep before (at most one cell per point) tested about 2800 pairs per
/// step on rRBPF-128 (H2) and 28800 on rRBPF-512, this grid 190 and 950, of which 35 and 76 pass the
/// pre-test on two components (nlosloc-rbpf-phases, an instrumented copy, 2026-12-05).
class LineGrid {
 public:
  /// Room for n points: build() then never allocates for n points or fewer.
  void reserve(std::size_t n) {
    cell_.reserve(n);
    point_.reserve(n);
    xcell_.reserve(n);
    end_.reserve(buckets_for(n) + 2);
  }

  /// Grid of points i = 0..n-1 with coordinate x(i) for distance d. With d not above 0 (or NaN) no
  /// distance is below it: no rows.
  template <class X>
  void build(std::size_t n, X x, double d) {
    cell_.clear();
    point_.clear();
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t i = 0; i < n; ++i) {
      const double v = x(i);
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (!(d > 0.0) || !(lo <= hi)) return;  // no rows: nothing reads the buckets
    const std::size_t nb = buckets_for(n);
    // end_[nb]: the points without a row (non-finite x), placed after every row
    end_.resize(nb + 2);
    mask_ = static_cast<std::uint32_t>(nb - 1);
    const double width = std::max(d, (hi - lo) * 0x1p-31) * (1.0 + 1e-5), inv = 1.0 / width;
    xcell_.resize(n);
    std::size_t rows = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double v = x(i);
      std::uint32_t c = kNone;
      if (std::isfinite(v))  // an infinite width (d or the spread): one cell
        c = std::isfinite(width) ? static_cast<std::uint32_t>((v - lo) * inv) : 0;
      xcell_[i] = c;
      rows += c != kNone ? 1 : 0;
    }
    cell_.resize(rows);
    point_.resize(rows);
    counting_scatter(
        n, nb + 1, end_.data(), [&](std::size_t i) { return xcell_[i] != kNone ? xcell_[i] & mask_ : nb; },
        [&](std::size_t i, std::size_t pos) {
          if (pos >= rows) return;  // no row
          cell_[pos] = xcell_[i];
          point_[pos] = static_cast<int>(i);
        });
  }

  /// Rows of the grid (the points with a finite coordinate; none when d <= 0).
  std::size_t rows() const { return cell_.size(); }
  /// The point of row r.
  int point(std::size_t r) const { return point_[r]; }

  /// Calls f(s) for the rows s that row r is paired with: over all rows, every pair of points closer than
  /// d along the coordinate exactly once (s > r within a cell), and few others.
  template <class F>
  void for_candidates(std::size_t r, F f) const {
    const std::uint32_t c = cell_[r];
    for (std::size_t s = r + 1, e = end_[c & mask_]; s < e; ++s)
      if (cell_[s] == c) f(s);
    const std::uint32_t c1 = c + 1, k1 = c1 & mask_;
    for (std::size_t s = begin(k1), e = end_[k1]; s < e; ++s)
      if (cell_[s] == c1) f(s);
  }

  /// Rows that for_candidates(r) reads, plus one: the cost of row r, to split the rows into chunks.
  double cost(std::size_t r) const {
    const std::uint32_t k = cell_[r] & mask_, k1 = (cell_[r] + 1) & mask_;
    return static_cast<double>(end_[k] - r + end_[k1] - begin(k1));
  }

 private:
  static constexpr std::uint32_t kNone = ~std::uint32_t{0};
  static std::size_t buckets_for(std::size_t n) { return pow2_at_least(2 * n, 2); }
  std::size_t begin(std::uint32_t k) const { return k == 0 ? 0 : end_[k - 1]; }

  std::vector<std::uint32_t> cell_;   // cell of each row (rows by bucket)
  std::vector<int> point_;            // point of each row
  std::vector<std::uint32_t> xcell_;  // cell of each point (kNone: no row)
  std::vector<std::uint32_t> end_;    // end_[k]: where bucket k's rows end
  std::uint32_t mask_ = 1;
};

/// ws.order = 0..n-1 grouped by key (ascending), heaviest first within a group, ties by index: the order
/// the greedy merge visits; ws.sorted_keys[i] = keys[ws.order[i]]. Keys within a narrow range
/// (MergeWorkspace::count_limit): one stable counting pass. Otherwise small n: one comparison sort; large n
/// (the PF's 1e6 particles): a stable LSD radix sort on the 64-bit keys. The counting and radix passes keep
/// indices ascending inside a group, then each group of two or more is sorted by weight: linear in n
/// instead of n log n with scattered key/weight reads.
inline void merge_order(const std::uint64_t* keys, const double* logw, int n, MergeWorkspace& ws) {
  const auto N = static_cast<std::size_t>(n);
  ws.order.resize(N);
  const HeavierFirst heavier{logw};
  ws.sorted_keys.resize(N);
  if (N == 0) return;
  // One pass over the keys: their range picks the grouping; `used` (every set bit) bounds the radix passes.
  std::uint64_t kmin = keys[0], kmax = keys[0], used = 0;
  for (std::size_t i = 0; i < N; ++i) {
    kmin = std::min(kmin, keys[i]);
    kmax = std::max(kmax, keys[i]);
    used |= keys[i];
  }
  if (kmax - kmin < MergeWorkspace::count_limit(N)) {
    const auto range = static_cast<std::size_t>(kmax - kmin) + 1;
    ws.count.resize(range + 1);  // within the capacity reserve() gives
    counting_scatter(
        N, range, ws.count.data(), [&](std::size_t i) { return keys[i] - kmin; },
        [&](std::size_t i, std::size_t dst) {
          ws.order[dst] = static_cast<int>(i);
          ws.sorted_keys[dst] = keys[i];
        });
    sort_groups(N, ws, heavier);
    return;
  }
  if (n < MergeWorkspace::kRadixMin) {
    std::iota(ws.order.begin(), ws.order.end(), 0);
    std::sort(ws.order.begin(), ws.order.end(),
              [&](int a, int b) { return keys[a] != keys[b] ? keys[a] < keys[b] : heavier(a, b); });
    for (std::size_t i = 0; i < N; ++i) ws.sorted_keys[i] = keys[ws.order[i]];
    return;
  }
  constexpr int kBits = MergeWorkspace::kRadixBits;
  constexpr std::size_t kBuckets = std::size_t{1} << kBits;
  ws.tmp_order.resize(N);
  ws.tmp_keys.resize(N);
  ws.count.resize(kBuckets);
  std::iota(ws.order.begin(), ws.order.end(), 0);
  std::copy(keys, keys + n, ws.sorted_keys.begin());
  // digits above the highest set bit of every key need no pass
  for (int shift = 0; shift < 64 && (used >> shift) != 0; shift += kBits) {
    std::fill(ws.count.begin(), ws.count.end(), 0);
    for (std::size_t i = 0; i < N; ++i) ++ws.count[(ws.sorted_keys[i] >> shift) & (kBuckets - 1)];
    if (ws.count[(ws.sorted_keys[0] >> shift) & (kBuckets - 1)] == n) continue;  // one digit: no move
    int sum = 0;
    for (auto& c : ws.count) {
      const int v = c;
      c = sum;
      sum += v;
    }
    for (std::size_t i = 0; i < N; ++i) {
      const std::uint64_t key = ws.sorted_keys[i];
      const auto dst = static_cast<std::size_t>(ws.count[(key >> shift) & (kBuckets - 1)]++);
      ws.tmp_keys[dst] = key;
      ws.tmp_order[dst] = ws.order[i];
    }
    ws.sorted_keys.swap(ws.tmp_keys);
    ws.order.swap(ws.tmp_order);
  }
  sort_groups(N, ws, heavier);
}
/// Absorb callback of merge_group that does nothing.
struct NoAbsorb {
  void operator()(int, int, double) const {}
};

/// The greedy merge of one group (eqs. 29-30): positions [g0, g1) in visiting order, at(i) the particle
/// at position i; each particle not yet absorbed absorbs every later one within d_min, calling
/// absorb(a, b, logw_b) first (b has absorbed nothing yet: logw_b is its own weight). Returns the count.
template <class At, class Close, class Absorb = NoAbsorb>
int merge_group(int g0, int g1, At at, double* logw, Close& close, Absorb&& absorb = {}) {
  constexpr double kNegInf = -std::numeric_limits<double>::infinity();
  int absorbed = 0;
  for (int i = g0; i + 1 < g1; ++i) {
    const int a = at(i);
    if (logw[a] == kNegInf) continue;  // absorbed (or impossible)
    for (int j = i + 1; j < g1; ++j) {
      const int b = at(j);
      if (logw[b] == kNegInf || !close(a, b)) continue;
      absorb(a, b, logw[b]);
      logw[a] = log_add(logw[a], logw[b]);  // eq. (30): w_a <- w_a + w_b
      logw[b] = kNegInf;                    //            w_b <- 0
      ++absorbed;
    }
  }
  return absorbed;
}
}  // namespace detail

/// Greedy merge (eqs. 29-30) of n particles with situation keys `keys`, log weights `logw` (modified in
/// place: absorbed particles get -inf). close(a, b) says whether ||x_a - x_b|| < d_min (only asked for
/// particles with equal keys; eq. 29 makes the distance infinite otherwise). absorb(a, b, logw_b) is
/// called as a absorbs b, before the transfer: each absorbed particle once, with its own weight (the
/// classical RBPF moves its moments with it). Returns the number absorbed.
template <class Close, class Absorb = detail::NoAbsorb>
int merge_greedy(const std::uint64_t* keys, double* logw, int n, Close&& close, MergeWorkspace& ws,
                 Absorb&& absorb = {}) {
  if (n <= 0) return 0;
  detail::merge_order(keys, logw, n, ws);  // by key, heaviest first within a group (ties by index)
  int absorbed = 0;
  std::size_t g0 = 0;
  const auto N = static_cast<std::size_t>(n);
  const std::uint64_t* sk = ws.sorted_keys.data();  // keys in visiting order: no scattered reads
  while (g0 < N) {
    std::size_t g1 = g0 + 1;
    while (g1 < N && sk[g1] == sk[g0]) ++g1;
    if (g1 - g0 == 1) {  // a particle alone in its group: nothing to merge
      g0 = g1;
      continue;
    }
    absorbed += detail::merge_group(
        static_cast<int>(g0), static_cast<int>(g1),
        [&](int i) { return ws.order[static_cast<std::size_t>(i)]; }, logw, close, absorb);
    g0 = g1;
  }
  return absorbed;
}

/// Buffers of merge_greedy_parallel (reserve(n, threads) sizes them so a merge of up to n particles does
/// not allocate).
struct ParallelMergeWorkspace {
  static constexpr int kBucketBits = 11;
  static constexpr int kBuckets = 1 << kBucketBits;
  /// Buckets of up to kTable / 2 entries are grouped through a hash table of kTable slots per thread (in
  /// L1), larger ones by a sort.
  static constexpr int kTable = 4096;
  std::vector<std::uint32_t> keys;     // merge_greedy_parallel: the 64-bit keys, checked and narrowed
  std::vector<std::uint64_t> entries;  // key << 32 | index, scattered by bucket (stable: index order inside)
  std::vector<int> offset;             // (thread, bucket) start of each thread's share of a bucket
  std::vector<int> absorbed;           // per thread
  std::vector<std::uint32_t> above;    // per thread: OR of the keys' bits >= 32 (input check)
  std::vector<int> link;               // next position of the same key in its bucket (-1: last)
  std::vector<int> slot, tail;         // per thread: first and last position of a key in the bucket
  std::vector<int> multi;              // per thread: slots of keys with two or more entries
  std::vector<std::uint64_t> group;    // per thread: one group's entries
  void reserve(std::size_t n, int threads) {
    const auto T = static_cast<std::size_t>(threads);
    keys.reserve(n);
    entries.reserve(n);
    offset.reserve(T * kBuckets + 1);
    absorbed.reserve(T);
    above.reserve(T);
    link.reserve(n);
    slot.reserve(T * kTable);
    tail.reserve(T * kTable);
    multi.reserve(T * kTable / 2);
    group.reserve(T * kTable / 2);
  }
};

/// merge_greedy for many particles with 32-bit keys, on a thread pool (`pool.parallel_for(n, fn(b, e, t))`,
/// `pool.size()`): the particles are scattered into 2^11 buckets by the keys' top bits (one stable
/// counting pass, each thread over its own index range); then each thread finds the groups of its range
/// of buckets in cache, orders each group heaviest first (ties by index) and merges it greedily. Groups
/// and their visiting order are merge_greedy's, so the result is identical to it, whatever the thread
/// count; only the order in which groups are visited differs, and groups are independent. Replaces three
/// radix passes over all n particles by one, and runs on all threads: the joint PF's merge of 1e6
/// particles, where almost no group has two members, spent 90 ms of a 139 ms step in merge_greedy.
/// Inside a bucket of up to kTable / 2 entries the groups are found by a hash table (linear probing, in
/// index order, so a group lists its members by index), in larger ones by a sort: the sorts took 15 of
/// the 20 ms of that merge. `close` is called from several threads at once.
template <class Pool, class Close>
int merge_greedy_parallel(const std::uint32_t* keys, double* logw, int n, Close&& close, Pool& pool,
                          ParallelMergeWorkspace& ws) {
  constexpr int kBuckets = ParallelMergeWorkspace::kBuckets;
  constexpr int kShift = 32 - ParallelMergeWorkspace::kBucketBits;
  if (n <= 0) return 0;
  const int T = pool.size();
  const auto TB = static_cast<std::size_t>(T) * kBuckets;
  ws.entries.resize(static_cast<std::size_t>(n));
  ws.offset.assign(TB + 1, 0);
  ws.absorbed.assign(static_cast<std::size_t>(T), 0);
  ws.link.resize(static_cast<std::size_t>(n));
  ws.slot.resize(static_cast<std::size_t>(T) * ParallelMergeWorkspace::kTable);
  ws.tail.resize(static_cast<std::size_t>(T) * ParallelMergeWorkspace::kTable);
  ws.multi.resize(static_cast<std::size_t>(T) * ParallelMergeWorkspace::kTable / 2);
  ws.group.resize(static_cast<std::size_t>(T) * ParallelMergeWorkspace::kTable / 2);
  // 1. per-thread histograms of the top bits (parallel_for gives thread t the same range every call)
  pool.parallel_for(n, [&](int b, int e, int t) {
    int* h = ws.offset.data() + static_cast<std::size_t>(t) * kBuckets;
    for (int i = b; i < e; ++i) ++h[keys[i] >> kShift];
  });
  // 2. exclusive prefix over (bucket, thread): thread t's share of bucket c follows threads < t's
  int sum = 0;
  for (int c = 0; c < kBuckets; ++c)
    for (int t = 0; t < T; ++t) {
      int& o = ws.offset[static_cast<std::size_t>(t) * kBuckets + static_cast<std::size_t>(c)];
      const int v = o;
      o = sum;
      sum += v;
    }
  // 3. stable scatter, each thread from its own index range
  pool.parallel_for(n, [&](int b, int e, int t) {
    int* o = ws.offset.data() + static_cast<std::size_t>(t) * kBuckets;
    for (int i = b; i < e; ++i) {
      const std::uint32_t k = keys[i];
      ws.entries[static_cast<std::size_t>(o[k >> kShift]++)] =
          std::uint64_t{k} << 32 | static_cast<std::uint32_t>(i);
    }
  });
  // Bucket c now ends at thread (T - 1)'s offset of c; it starts where bucket c - 1 ends.
  auto bucket_end = [&](int c) {
    return ws.offset[static_cast<std::size_t>(T - 1) * kBuckets + static_cast<std::size_t>(c)];
  };
  // 4. each thread: the groups of its buckets, each of two or more ordered heaviest first (ties by index:
  // merge_greedy's visiting order) and merged greedily
  const HeavierFirst heavier{logw};
  auto idx_of = [](std::uint64_t v) { return static_cast<int>(v & 0xFFFFFFFFULL); };
  auto key_at = [](std::uint64_t v) { return static_cast<std::uint32_t>(v >> 32); };
  // visiting order of a group's positions [g0, g1) (insertion sort: groups have a few members), then merge
  auto merge_members = [&](auto at, int g0, int g1) {
    for (int i = g0 + 1; i < g1; ++i) {
      const auto v = at(i);
      int j = i;
      for (; j > g0 && heavier(idx_of(v), idx_of(at(j - 1))); --j) at(j) = at(j - 1);
      at(j) = v;
    }
    return detail::merge_group(
        g0, g1, [&](int i) { return idx_of(at(i)); }, logw, close);
  };
  pool.parallel_for(kBuckets, [&](int c0, int c1, int t) {
    constexpr int kTable = ParallelMergeWorkspace::kTable;
    int absorbed = 0;
    std::uint64_t* en = ws.entries.data();
    int* link = ws.link.data();
    int* slot = ws.slot.data() + static_cast<std::size_t>(t) * kTable;
    int* tail = ws.tail.data() + static_cast<std::size_t>(t) * kTable;
    int* multi = ws.multi.data() + static_cast<std::size_t>(t) * (kTable / 2);
    std::uint64_t* group = ws.group.data() + static_cast<std::size_t>(t) * (kTable / 2);
    for (int c = c0; c < c1; ++c) {
      const int lo = c == 0 ? 0 : bucket_end(c - 1), hi = bucket_end(c);
      if (hi - lo < 2) continue;
      if (hi - lo > kTable / 2) {  // a large bucket (keys with few distinct top bits): sorted, in place
        std::sort(en + lo, en + hi);
        for (int g0 = lo; g0 < hi;) {
          int g1 = g0 + 1;
          while (g1 < hi && key_at(en[g1]) == key_at(en[g0])) ++g1;
          if (g1 - g0 > 1) absorbed += merge_members([&](int i) -> std::uint64_t& { return en[i]; }, g0, g1);
          g0 = g1;
        }
        continue;
      }
      // table of at least twice the bucket's entries: probes stay short
      const auto size = static_cast<int>(detail::pow2_at_least(2 * static_cast<std::size_t>(hi - lo), 16));
      const auto mask = static_cast<std::uint32_t>(size - 1);
      std::fill(slot, slot + size, -1);
      int nmulti = 0;
      for (int pos = lo; pos < hi; ++pos) {
        const std::uint32_t k = key_at(en[pos]);
        std::uint32_t h = ((k * 0x9E3779B1U) >> 16) & mask;  // mixed: the low bits alone may be structured
        while (slot[h] >= 0 && key_at(en[slot[h]]) != k) h = (h + 1) & mask;
        link[pos] = -1;
        if (slot[h] < 0) {
          slot[h] = tail[h] = pos;
        } else {
          if (tail[h] == slot[h]) multi[nmulti++] = static_cast<int>(h);
          link[tail[h]] = pos;
          tail[h] = pos;
        }
      }
      for (int q = 0; q < nmulti; ++q) {
        int m = 0;
        for (int pos = slot[multi[q]]; pos >= 0; pos = link[pos]) group[m++] = en[pos];
        absorbed += merge_members([&](int i) -> std::uint64_t& { return group[i]; }, 0, m);
      }
    }
    ws.absorbed[static_cast<std::size_t>(t)] = absorbed;
  });
  int total = 0;
  for (const int a : ws.absorbed) total += a;
  return total;
}

/// merge_greedy_parallel with merge_greedy's 64-bit keys, which must be below 2^32 (std::invalid_argument
/// naming `keys`, before any weight changes).
template <class Pool, class Close>
int merge_greedy_parallel(const std::uint64_t* keys, double* logw, int n, Close&& close, Pool& pool,
                          ParallelMergeWorkspace& ws) {
  if (n <= 0) return 0;
  ws.keys.resize(static_cast<std::size_t>(n));
  ws.above.assign(static_cast<std::size_t>(pool.size()), 0);
  pool.parallel_for(n, [&](int b, int e, int t) {
    std::uint64_t hi = 0;
    for (int i = b; i < e; ++i) {
      hi |= keys[i] >> 32;
      ws.keys[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(keys[i]);
    }
    ws.above[static_cast<std::size_t>(t)] = hi != 0 ? 1U : 0U;
  });
  for (const std::uint32_t a : ws.above)
    NLOSLOC_ENSURE(a == 0, "keys: expected values below 2^32 for merge_greedy_parallel");
  return merge_greedy_parallel(ws.keys.data(), logw, n, std::forward<Close>(close), pool, ws);
}

/// Incremental selection of the M heaviest of the offered indices, by log weight then lower index. A
/// bounded heap keeps the M heaviest offered so far (its front is the lightest kept), so an offer costs
/// one comparison unless the entry enters. The kept set is unique under that order, whatever the order
/// of the offers. `out` is caller-owned storage (reserve M to avoid allocation).
class TopSelector {
 public:
  TopSelector(const double* logw, int M, std::vector<int>& out) : logw_(logw), M_(M), out_(out) {
    out_.clear();
  }
  bool heavier(int a, int b) const { return HeavierFirst{logw_}(a, b); }
  bool full() const { return static_cast<int>(out_.size()) >= M_; }
  /// Log weight of the lightest kept entry (valid when full()).
  double threshold() const { return logw_[out_.front()]; }
  void offer(int i) {
    if (!(logw_[i] > -std::numeric_limits<double>::infinity()) || M_ <= 0) return;
    const HeavierFirst cmp{logw_};
    if (!full()) {
      out_.push_back(i);
      std::push_heap(out_.begin(), out_.end(), cmp);
    } else if (heavier(i, out_.front())) {
      std::pop_heap(out_.begin(), out_.end(), cmp);
      out_.back() = i;
      std::push_heap(out_.begin(), out_.end(), cmp);
    }
  }
  /// Sorts the kept entries by decreasing weight.
  void finish() { std::sort(out_.begin(), out_.end(), HeavierFirst{logw_}); }

 private:
  const double* logw_;
  int M_;
  std::vector<int>& out_;
};

/// Writes to `out` the (at most) M entries idx(0..n-1) with the largest finite log weights, in decreasing
/// weight order, ties by index (prune step of Sec. V-A.3).
template <class IndexAt>
void select_top_of(const double* logw, int n, IndexAt idx, int M, std::vector<int>& out) {
  TopSelector top(logw, M, out);
  for (int j = 0; j < n; ++j) top.offer(idx(j));
  top.finish();
}

/// Indices of the (at most) M particles with the largest finite log weights, written to `out` (cleared
/// first), in decreasing weight order, ties by index (prune step of Sec. V-A.3).
inline void select_top(const double* logw, int n, int M, std::vector<int>& out) {
  select_top_of(
      logw, n, [](int j) { return j; }, M, out);
}

}  // namespace nlosloc::rbpf
