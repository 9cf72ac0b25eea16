// RBPF engine: merge rule (eqs. 29-30) on hand-built sets, offspring counts and the bounded enumeration,
// RBPF weights (eq. 25) against a brute-force enumeration of situation histories, reordered RBPF, the
// thread pool, systematic resampling (unbiased) and the joint PF.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <numeric>
#include <set>
#include <thread>

#include "nlosloc/filters/iukf.hpp"
#include "nlosloc/filters/ukf.hpp"
#include "nlosloc/rbpf/pf.hpp"
#include "nlosloc/rbpf/rbpf.hpp"

using namespace nlosloc;
using namespace nlosloc::rbpf;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
namespace nn = nlosloc::noise;
namespace si = nlosloc::situation;

template class nlosloc::rbpf::Rbpf<ConstantVelocity2>;
template class nlosloc::rbpf::Rbpf<ConstantVelocityClock2>;
template class nlosloc::rbpf::ParticleFilter<ConstantVelocityClock2>;
template class nlosloc::rbpf::UkfKernel<ConstantVelocity2>;
template class nlosloc::rbpf::UkfKernel<TwoWayClock>;

namespace {
constexpr double kNegInf = -std::numeric_limits<double>::infinity();
/// B x N_z log factors A(b, z) = log U(0, 1), drawn row by row.
MatX random_factors(int B, int nz, Rng& rng) {
  MatX A(B, nz);
  for (int b = 0; b < B; ++b)
    for (int z = 0; z < nz; ++z) A(b, z) = std::log(rng.uniform());
  return A;
}
}  // namespace

TEST_CASE("merge rule on hand-built particle sets (eqs. 29-30)", "[rbpf][merge]") {
  // particles: key, 1-D mean, weight
  std::vector<std::uint64_t> key{0, 0, 0, 1, 0};
  std::vector<double> x{0.0, 0.05, 0.5, 0.01, 0.09};
  std::vector<double> w{0.1, 0.3, 0.2, 0.25, 0.15};
  std::vector<double> lw(w.size());
  for (std::size_t i = 0; i < w.size(); ++i) lw[i] = std::log(w[i]);
  MergeWorkspace ws;
  std::vector<std::pair<int, int>> pairs;
  std::vector<double> moved;
  const int n = merge_greedy(
      key.data(), lw.data(), 5,
      [&](int a, int b) {
        return std::abs(x[static_cast<std::size_t>(a)] - x[static_cast<std::size_t>(b)]) < 0.1;
      },
      ws,
      [&](int a, int b, double lwb) {
        pairs.emplace_back(a, b);
        moved.push_back(std::exp(lwb));
      });
  // heaviest of key 0 is particle 1 (0.3): absorbs 0 (d = 0.05) and 4 (d = 0.04); not 2 (d = 0.45);
  // particle 3 has another situation (eq. 29: infinite distance) although it is close.
  CHECK(n == 2);
  // the absorb callback: each absorbed particle once, in visiting order (key 0 by weight: 1, 2, 4, 0),
  // with its own weight
  CHECK(pairs == std::vector<std::pair<int, int>>{{1, 4}, {1, 0}});
  REQUIRE(moved.size() == 2);
  CHECK_THAT(moved[0], WithinAbs(0.15, 1e-15));
  CHECK_THAT(moved[1], WithinAbs(0.1, 1e-15));
  CHECK_THAT(std::exp(lw[1]), WithinAbs(0.55, 1e-14));
  CHECK(lw[0] == kNegInf);
  CHECK(lw[4] == kNegInf);
  CHECK_THAT(std::exp(lw[2]), WithinAbs(0.2, 1e-14));
  CHECK_THAT(std::exp(lw[3]), WithinAbs(0.25, 1e-14));
  std::vector<int> top;
  select_top(lw.data(), 5, 2, top);
  CHECK(top == std::vector<int>{1, 3});
  // a chain a-b-c: b is absorbed by the heavier a, so c (far from a) survives
  std::vector<std::uint64_t> k2{7, 7, 7};
  std::vector<double> x2{0.0, 0.08, 0.16}, lw2{std::log(0.5), std::log(0.3), std::log(0.2)};
  merge_greedy(
      k2.data(), lw2.data(), 3,
      [&](int a, int b) {
        return std::abs(x2[static_cast<std::size_t>(a)] - x2[static_cast<std::size_t>(b)]) < 0.1;
      },
      ws);
  CHECK_THAT(std::exp(lw2[0]), WithinAbs(0.8, 1e-14));
  CHECK(lw2[1] == kNegInf);
  CHECK_THAT(std::exp(lw2[2]), WithinAbs(0.2, 1e-14));
  CHECK_THAT(default_merge_threshold(12.8, 128), WithinRel(0.01, 1e-14));  // eq. (31)
}

namespace {
/// The merge's visiting order by a plain comparison sort: key, then weight descending, then index.
std::vector<int> reference_merge_order(const std::vector<std::uint64_t>& key, const std::vector<double>& lw) {
  std::vector<int> ref(key.size());
  std::iota(ref.begin(), ref.end(), 0);
  std::sort(ref.begin(), ref.end(), [&](int a, int b) {
    const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
    if (key[ua] != key[ub]) return key[ua] < key[ub];
    if (lw[ua] != lw[ub]) return lw[ua] > lw[ub];
    return a < b;
  });
  return ref;
}
}  // namespace

TEST_CASE("merge visiting order: the radix grouping equals the comparison sort", "[rbpf][merge]") {
  // n above kRadixMin: keys with many repeats (full 64-bit range, shared high and low digits), weights
  // with ties; the visiting order must be exactly by key, then weight descending, then index.
  for (int n : {MergeWorkspace::kRadixMin, 20000}) {
    Rng rng(static_cast<std::uint64_t>(n));
    std::vector<std::uint64_t> key(static_cast<std::size_t>(n));
    std::vector<double> lw(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      key[static_cast<std::size_t>(i)] = (rng.below(50) << 40) * 0x9E3779B97F4A7C15ULL + rng.below(3);
      lw[static_cast<std::size_t>(i)] = i % 7 == 0 ? -1.0 : std::log(rng.uniform());
    }
    std::vector<int> ref = reference_merge_order(key, lw);
    MergeWorkspace ws;
    nlosloc::rbpf::detail::merge_order(key.data(), lw.data(), n, ws);
    CHECK(ws.order == ref);
    // all keys equal: every radix digit is constant (passes skipped), order by weight only
    std::vector<std::uint64_t> same(static_cast<std::size_t>(n), 0x0123456789ABCDEFULL);
    nlosloc::rbpf::detail::merge_order(same.data(), lw.data(), n, ws);
    std::sort(ref.begin(), ref.end(), [&](int a, int b) {
      const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
      return lw[ua] != lw[ub] ? lw[ua] > lw[ub] : a < b;
    });
    CHECK(ws.order == ref);
  }
}

TEST_CASE("parallel bucketed merge equals merge_greedy on 1, 2 and 3 threads", "[rbpf][merge]") {
  // 32-bit keys with many repeats spread over every bucket (a few hundred distinct values times an odd
  // constant), log weights with ties and some already -inf, 2-D points: the absorbed count and every log
  // weight must equal the serial greedy merge's exactly (same groups, same visiting order).
  const int n = 20000;
  Rng rng(7);
  std::vector<std::uint64_t> key(static_cast<std::size_t>(n));
  std::vector<double> lw(static_cast<std::size_t>(n)), px(static_cast<std::size_t>(n)),
      py(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    key[u] = (rng.below(600) * 0x9E3779B1ULL) & 0xFFFFFFFFULL;
    lw[u] = i % 11 == 0 ? -1.5
                        : (i % 97 == 0 ? -std::numeric_limits<double>::infinity() : std::log(rng.uniform()));
    px[u] = rng.uniform();
    py[u] = rng.uniform();
  }
  auto close = [&](int a, int b) {
    const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
    return std::hypot(px[ua] - px[ub], py[ua] - py[ub]) < 0.05;
  };
  // Spread keys (600 values in as many buckets: the hash-table grouping), then keys below 2^21 (all in bucket
  // 0: the sorted grouping of large buckets).
  for (const std::uint64_t div : {std::uint64_t{1}, std::uint64_t{1} << 11}) {
    std::vector<std::uint64_t> kd = key;
    for (auto& v : kd) v /= div;
    std::vector<double> ref = lw;
    MergeWorkspace mws;
    const int absorbed = merge_greedy(kd.data(), ref.data(), n, close, mws);
    REQUIRE(absorbed > 1000);  // the case exercises real merging
    for (int threads : {1, 2, 3}) {
      ThreadPool pool(threads);
      ParallelMergeWorkspace ws;
      std::vector<double> got = lw;
      CHECK(merge_greedy_parallel(kd.data(), got.data(), n, close, pool, ws) == absorbed);
      CHECK(got == ref);
    }
  }
  // a key of 2^32 or more is refused and no weight changes
  ThreadPool pool(2);
  ParallelMergeWorkspace ws;
  std::vector<double> got = lw;
  key[123] = std::uint64_t{1} << 32;
  CHECK_THROWS_AS(merge_greedy_parallel(key.data(), got.data(), n, close, pool, ws), std::invalid_argument);
  CHECK_THROWS_WITH(merge_greedy_parallel(key.data(), got.data(), n, close, pool, ws),
                    "keys: expected values below 2^32 for merge_greedy_parallel");
  CHECK(got == lw);
}

TEST_CASE("merge visiting order: the counting-sort grouping of narrow key ranges equals the comparison sort",
          "[rbpf][merge]") {
  // keys spanning fewer values than the counting pass accepts (the RBPF's N_z^B situations), offset from
  // zero, at sizes on both sides of kRadixMin; weights with ties; one key (a single group); one particle;
  // and a wide span (2^40: the comparison sort, or the radix sort from kRadixMin on).
  for (int n : {1, 7, 300, MergeWorkspace::kRadixMin + 5}) {
    for (std::uint64_t span : {std::uint64_t{1}, std::uint64_t{64},
                               std::uint64_t{2} * static_cast<std::uint64_t>(n), std::uint64_t{1} << 40}) {
      Rng rng(static_cast<std::uint64_t>(n) * 31 + span);
      std::vector<std::uint64_t> key(static_cast<std::size_t>(n));
      std::vector<double> lw(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i) {
        key[static_cast<std::size_t>(i)] = (std::uint64_t{1} << 40) + rng.below(span);
        lw[static_cast<std::size_t>(i)] = i % 5 == 0 ? -2.0 : std::log(rng.uniform());
      }
      const std::vector<int> ref = reference_merge_order(key, lw);
      MergeWorkspace ws;
      ws.reserve(static_cast<std::size_t>(n));
      const auto cap = ws.count.capacity();
      nlosloc::rbpf::detail::merge_order(key.data(), lw.data(), n, ws);
      CHECK(ws.order == ref);
      CHECK(ws.count.capacity() == cap);  // reserve() covered the histogram: no allocation
      for (int i = 0; i < n; ++i)
        CHECK(ws.sorted_keys[static_cast<std::size_t>(i)] ==
              key[static_cast<std::size_t>(ref[static_cast<std::size_t>(i)])]);
    }
  }
}

TEST_CASE("neighbour grid: every pair closer than d along the coordinate once, few others", "[rbpf][merge]") {
  using nlosloc::rbpf::detail::LineGrid;
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  // Each case: coordinates and d. Visited pairs must include every finite pair with |dx| < d, none twice.
  auto check = [&](const std::vector<double>& x, double d, const char* what) {
    INFO(what);
    LineGrid g;
    g.reserve(x.size());
    g.build(
        x.size(), [&](std::size_t i) { return x[i]; }, d);
    std::set<std::pair<int, int>> seen;
    std::size_t visits = 0;
    std::vector<int> rows_of(x.size(), 0);
    for (std::size_t r = 0; r < g.rows(); ++r) {
      ++rows_of[static_cast<std::size_t>(g.point(r))];
      CHECK(g.cost(r) >= 1.0);
      g.for_candidates(r, [&](std::size_t s) {
        CHECK(s != r);
        const int a = std::min(g.point(r), g.point(s)), b = std::max(g.point(r), g.point(s));
        seen.insert({a, b});
        ++visits;
      });
    }
    CHECK(visits == seen.size());  // no pair twice
    std::size_t close = 0, finite = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      finite += std::isfinite(x[i]) ? 1 : 0;
      // a row per finite point when d > 0, none for the others
      CHECK(rows_of[i] == (std::isfinite(x[i]) && d > 0.0 ? 1 : 0));
      for (std::size_t j = i + 1; j < x.size(); ++j)
        if (std::isfinite(x[i]) && std::isfinite(x[j]) && std::abs(x[i] - x[j]) < d) {
          ++close;
          CHECK(seen.count({static_cast<int>(i), static_cast<int>(j)}) == 1);
        }
    }
    if (!(d > 0.0)) CHECK(g.rows() == 0);
    return std::pair<std::size_t, std::size_t>{visits, close};
  };
  Rng rng(2026);
  std::vector<double> uni(300);
  for (double& v : uni) v = 100.0 * rng.uniform();
  const auto [v_uni, c_uni] = check(uni, 0.2, "uniform on [0, 100], d = 0.2");
  CHECK(c_uni > 100);                      // (a case with close pairs)
  CHECK(v_uni <= 3 * c_uni + uni.size());  // cells about d wide: few pairs beyond the close ones
  // A tight cluster 50 d wide with far outliers: the spread is 1e9 d, the cells still d wide. The sweep
  // this replaces put the cluster in one cell and tested all of its 7140 pairs.
  std::vector<double> clu;
  for (int i = 0; i < 120; ++i) clu.push_back(5.0 + 0.5 * rng.uniform());
  clu.push_back(-1e7);
  clu.push_back(1e7);
  const auto [v_clu, c_clu] = check(clu, 0.01, "cluster and outliers");
  CHECK(v_clu <= 3 * c_clu + clu.size());
  // A chain spaced just below d, from far off the origin: every neighbour pair crosses a cell boundary.
  std::vector<double> chain;
  for (int i = 0; i < 200; ++i) chain.push_back(1e6 + i * 0.999999 * 0.37);
  const auto [v_ch, c_ch] = check(chain, 0.37, "chain");
  CHECK(c_ch == 199);
  // d wider than the spread (one cell: every pair), d = 0 and NaN (no pair is closer), non-finite points
  // (never close to anything, no row), a spread too wide for a double (one cell), no points.
  check({3.0, 1.0, 2.0, 1.5}, 10.0, "one cell");
  check({1.0, 1.0, 2.0}, 0.0, "d = 0");
  check({1.0, 1.0, 2.0}, nan, "d NaN");
  const auto [v_nf, c_nf] = check({nan, 1.0, inf, 1.05, -inf, 3.0, nan}, 0.1, "non-finite points");
  CHECK(c_nf == 1);
  check({-1.7e308, 1.7e308, 0.0, 0.5}, 1.0, "infinite spread");
  check({}, 1.0, "no points");
}

TEST_CASE("selection of the M heaviest records equals a full sort, ties by index", "[rbpf][merge]") {
  Rng rng(11);
  std::vector<double> w, tmp;
  std::vector<ChildRecord> v, ties, ref;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + static_cast<int>(rng.uniform() * 300);
    const int M = 1 + static_cast<int>(rng.uniform() * (n + 10));
    const bool tied = trial % 3 == 0;  // few distinct weights: many ties at the cut
    v.clear();
    for (int i = 0; i < n; ++i) {
      const double x = tied ? std::floor(rng.uniform() * 5.0) : std::log(rng.uniform());
      v.push_back({x, (i * 7919) % 100003, i, static_cast<std::uint64_t>(i)});
    }
    ref = v;
    std::sort(ref.begin(), ref.end(), HeavierRecordFirst{});
    ref.resize(std::min<std::size_t>(ref.size(), static_cast<std::size_t>(M)));
    // kth_largest: the value at each rank of the decreasing order
    w.resize(v.size());
    tmp.resize(v.size());
    const int k = static_cast<int>(rng.uniform() * n);
    for (int i = 0; i < n; ++i) w[static_cast<std::size_t>(i)] = v[static_cast<std::size_t>(i)].logw;
    std::vector<double> sorted(w);
    std::sort(sorted.begin(), sorted.end(), std::greater<double>());
    CHECK(kth_largest(w.data(), tmp.data(), n, k) == sorted[static_cast<std::size_t>(k)]);
    keep_heaviest(v, static_cast<std::size_t>(M), w, tmp, ties);
    std::sort(v.begin(), v.end(), HeavierRecordFirst{});
    REQUIRE(v.size() == ref.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
      CHECK(v[i].idx == ref[i].idx);
      CHECK(v[i].logw == ref[i].logw);
    }
  }
}

TEST_CASE("offspring counts and the bounded enumeration", "[rbpf][offspring]") {
  CHECK(situation_count(2, 6) == 64);
  CHECK(situation_count(3, 4) == 81);
  CHECK(situation_count(2, 70) == 0);
  Rng rng(2);
  for (int nz : {2, 3}) {
    const int B = nz == 2 ? 6 : 4;
    const MatX A = random_factors(B, nz, rng);
    std::vector<std::pair<double, std::uint64_t>> all;
    enumerate_all(A, [&](std::uint64_t k, double s) { all.emplace_back(s, k); });
    const auto total = situation_count(nz, B);
    CHECK(all.size() == total);
    std::set<std::uint64_t> keys;
    for (auto& [s, k] : all) {
      keys.insert(k);
      VecXi sv(B);
      decode_situation(k, nz, sv);
      double ref = 0.0;
      for (int b = 0; b < B; ++b) ref += A(b, sv(b));
      CHECK_THAT(s, WithinAbs(ref, 1e-12));
      CHECK(encode_situation(sv, nz) == k);
    }
    CHECK(keys.size() == total);
    // bounded: the K best are exactly the K largest of the full enumeration ...
    std::sort(all.begin(), all.end(), [](auto& a, auto& b) { return a.first > b.first; });
    BestFirstWorkspace shared;
    for (std::uint64_t K : {std::uint64_t{1}, std::uint64_t{5}, std::uint64_t{17}}) {
      std::vector<std::pair<double, std::uint64_t>> best;
      enumerate_best(A, K, [&](std::uint64_t k, double s) { best.emplace_back(s, k); });
      REQUIRE(best.size() == K);
      for (std::size_t i = 0; i < K; ++i) CHECK_THAT(best[i].first, WithinAbs(all[i].first, 1e-12));
      // a reused workspace gives the same sequence (the RBPF keeps one per thread)
      std::vector<std::pair<double, std::uint64_t>> again;
      enumerate_best(A, K, shared, [&](std::uint64_t k, double s) { again.emplace_back(s, k); });
      CHECK(again == best);
    }
    // ties (equal factors for every condition of anchor 0): the K best sums are still exact
    MatX At = A;
    At.row(0).setConstant(-0.5);
    std::vector<double> tall;
    enumerate_all(At, [&](std::uint64_t, double s) { tall.push_back(s); });
    std::sort(tall.begin(), tall.end(), std::greater<double>());
    std::vector<double> tbest;
    std::set<std::uint64_t> tkeys;
    enumerate_best(At, 9, shared, [&](std::uint64_t k, double s) {
      tbest.push_back(s);
      tkeys.insert(k);
    });
    REQUIRE(tbest.size() == 9);
    CHECK(tkeys.size() == 9);
    for (std::size_t i = 0; i < 9; ++i) CHECK_THAT(tbest[i], WithinAbs(tall[i], 1e-12));
    // ... and with K >= N_z^B it equals the full one (same set of keys and sums)
    std::set<std::uint64_t> kb;
    enumerate_offspring(A, total + 3, [&](std::uint64_t k, double) { kb.insert(k); });
    std::set<std::uint64_t> kbest;
    enumerate_best(A, total, [&](std::uint64_t k, double) { kbest.insert(k); });
    CHECK(kb == keys);
    CHECK(kbest == keys);
  }
}

TEST_CASE("children above a cut: the pruned search equals the filtered full enumeration",
          "[rbpf][offspring]") {
  Rng rng(4);
  for (int nz : {2, 3}) {
    const int B = nz == 2 ? 6 : 4;
    const MatX A = random_factors(B, nz, rng);
    std::vector<std::uint64_t> pow(static_cast<std::size_t>(B), 1);
    for (int b = 1; b < B; ++b) pow[static_cast<std::size_t>(b)] = pow[static_cast<std::size_t>(b) - 1] * nz;
    std::vector<int> opt(static_cast<std::size_t>(B * nz));
    const double base = -0.7;
    std::map<std::uint64_t, double> all;
    enumerate_all(A, [&](std::uint64_t k, double s) { all[k] = base + s; });
    std::vector<double> sorted;
    for (auto& [k, w] : all) sorted.push_back(w);
    std::sort(sorted.begin(), sorted.end(), std::greater<double>());
    // fixed cuts halfway between consecutive weights (so the 1e-9 margin decides nothing)
    for (std::size_t m : {std::size_t{1}, std::size_t{5}, sorted.size() / 2, sorted.size()}) {
      const double cut = m < sorted.size() ? 0.5 * (sorted[m - 1] + sorted[m]) : -1e300;
      std::map<std::uint64_t, double> got;
      enumerate_above(
          A, base, pow.data(), opt.data(), [&] { return cut; },
          [&](std::uint64_t k, double w) { got[k] = w; });
      REQUIRE(got.size() == m);
      for (auto& [k, w] : got) {
        REQUIRE(all.count(k) == 1);
        CHECK_THAT(w, WithinAbs(all[k], 1e-12));
        CHECK(w > cut);
      }
    }
    // a rising cut (the M-th weight of a top-M list as it fills): the M heaviest are always emitted
    const int K = 7;
    std::vector<int> out;
    std::vector<double> wbuf(all.size());
    TopSelector top(wbuf.data(), K, out);
    int emitted = 0;
    enumerate_above(
        A, base, pow.data(), opt.data(), [&] { return top.full() ? top.threshold() : -1e300; },
        [&](std::uint64_t k, double w) {
          wbuf[static_cast<std::size_t>(k)] = w;
          top.offer(static_cast<int>(k));
          ++emitted;
        });
    top.finish();
    REQUIRE(out.size() == static_cast<std::size_t>(K));
    for (int i = 0; i < K; ++i)
      CHECK_THAT(wbuf[static_cast<std::size_t>(out[static_cast<std::size_t>(i)])],
                 WithinAbs(sorted[static_cast<std::size_t>(i)], 1e-12));
    CHECK(emitted < static_cast<int>(all.size()));  // the search did prune
  }
}

TEST_CASE("impossible children (a -inf log factor) weigh -inf in every enumeration, never NaN",
          "[rbpf][offspring]") {
  // A zero transition probability or quality density gives a -inf factor; the odometer's running sum
  // once turned every child after it into -inf - (-inf) = NaN.
  MatX A(3, 2);
  A << kNegInf, std::log(0.3), std::log(0.5), kNegInf, std::log(0.2), std::log(0.8);
  auto reference = [](const MatX& F, std::uint64_t key) {
    VecXi s(F.rows());
    decode_situation(key, static_cast<int>(F.cols()), s);
    double r = 0.0;
    for (Eigen::Index b = 0; b < F.rows(); ++b) r += F(b, s(b));
    return r;
  };
  std::vector<double> all;
  enumerate_all(A, [&](std::uint64_t k, double s) {
    CHECK(k == all.size());
    all.push_back(s);
    const double r = reference(A, k);
    if (r == kNegInf)
      CHECK(s == kNegInf);
    else
      CHECK_THAT(s, WithinAbs(r, 1e-12));
  });
  REQUIRE(all.size() == 8);
  CHECK(std::count(all.begin(), all.end(), kNegInf) == 6);  // only s_0 = 1 and s_1 = 0 are possible
  // best-first over all 8 and the pruned search: the same sums, -inf last / not emitted
  std::vector<double> sorted = all;
  std::sort(sorted.begin(), sorted.end(), std::greater<double>());
  std::vector<double> best;
  enumerate_best(A, 8, [&](std::uint64_t k, double s) {
    best.push_back(s);
    if (s == kNegInf) CHECK(reference(A, k) == kNegInf);
  });
  REQUIRE(best.size() == 8);
  for (std::size_t i = 0; i < 8; ++i)
    if (sorted[i] == kNegInf)
      CHECK(best[i] == kNegInf);
    else
      CHECK_THAT(best[i], WithinAbs(sorted[i], 1e-12));
  const std::uint64_t pow[3] = {1, 2, 4};
  int opt[6];
  std::vector<std::uint64_t> above;
  enumerate_above(
      A, 0.0, pow, opt, [] { return kNegInf; }, [&](std::uint64_t k, double) { above.push_back(k); });
  std::sort(above.begin(), above.end());
  CHECK(above == std::vector<std::uint64_t>{1, 5});  // the two possible vectors (base 2, anchor 0 first)
  // a whole row impossible: every child is -inf, and the pruned search emits none
  A.row(1).setConstant(kNegInf);
  enumerate_all(A, [&](std::uint64_t, double s) { CHECK(s == kNegInf); });
  int n = 0;
  enumerate_best(A, 8, [&](std::uint64_t, double s) {
    CHECK(s == kNegInf);
    ++n;
  });
  CHECK(n == 8);
  above.clear();
  enumerate_above(
      A, 0.0, pow, opt, [] { return kNegInf; }, [&](std::uint64_t k, double) { above.push_back(k); });
  CHECK(above.empty());
}

namespace {
/// Tiny case: B = 2 anchors, N_z = 2, 1-D-ish CV model in 2-D with two TOA rows.
struct Tiny {
  ConstantVelocity2 motion{0.5, 1.0};
  MeasurementStack st;
  si::SightProcess proc;
  si::QualityModel q{{nn::Normal(0.8, 0.2), nn::Normal(0.3, 0.2)}};
  Gaussian<4> g;
  MatX T;
  std::vector<VecX> ys, os;
  /// rayleigh: NLOS noise Rayleigh(15) instead of Normal(20, 10), skewed so the noise forms differ.
  explicit Tiny(bool rayleigh = false) : st(ConstantVelocity2::layout(), anchors(), 2) {
    const nn::Distribution nlos =
        rayleigh ? nn::Distribution(nn::Rayleigh(15.0)) : nn::Distribution(nn::Normal(20, 10));
    st.add_toa(0, {nn::Normal(0, 2), nlos});
    st.add_toa(1, {nn::Normal(0, 2), nlos});
    T.resize(2, 2);
    T << 0.8, 0.2, 0.3, 0.7;
    VecX pi(2);
    pi << 0.9, 0.1;  // not stationary for T (pi T = (0.75, 0.25)), so "pi T" and "pi" differ at step 1
    proc = si::SightProcess(si::SightModel::fixed(T, 1, pi), 2);
    g.mean << 10, 20, 1, 0;
    g.cov = Vec<4>(25, 25, 1, 1).asDiagonal();
    const double yv[3][2] = {{91.0, 62.0}, {110.0, 60.0}, {93.5, 83.0}};
    const double ov[3][2] = {{0.75, 0.4}, {0.35, 0.7}, {0.8, 0.2}};
    for (int k = 0; k < 3; ++k) {
      ys.emplace_back(Eigen::Vector2d(yv[k][0], yv[k][1]));
      os.emplace_back(Eigen::Vector2d(ov[k][0], ov[k][1]));
    }
  }
  static MatX anchors() {
    MatX a(2, 2);
    a << 100, 0, 0, 80;
    return a;
  }
  /// log prior of the history (first step: pi T) times quality, and the UKF chain along it (Filter: Ukf
  /// for the additive noise form, UkfAugmented for Table III's noise sigma set).
  template <template <class, class> class Filter = Ukf>
  double history_logw(const std::vector<VecXi>& h, Vec<4>* mean) const {
    Filter<ConstantVelocity2, MeasurementStack> f(motion, st, g);
    double lw = 0.0;
    const VecX pi = proc.model(0).initial();
    for (std::size_t k = 0; k < h.size(); ++k) {
      for (int b = 0; b < 2; ++b) {
        const double pr = k == 0 ? (pi.transpose() * T)(h[k](b)) : T(h[k - 1](b), h[k](b));
        lw += std::log(pr) + q.log_likelihood(os[k](b), h[k](b));
      }
      lw += f.step(ys[k], h[k]).log_likelihood;
    }
    if (mean) *mean = f.mean();
    return lw;
  }
};
VecXi sv(int k) {
  VecXi s(2);
  s << k % 2, k / 2;
  return s;
}

using Histories = std::vector<std::vector<VecXi>>;
/// Brute-force prune to M = 2: sorts the candidate histories (log weight, history) by weight, checks the
/// filter's two particles against the best two (renormalised weights, last situation) and returns them.
Histories check_pruned_to_two(const Rbpf<ConstantVelocity2>& f,
                              std::vector<std::pair<double, std::vector<VecXi>>> cand) {
  std::sort(cand.begin(), cand.end(), [](auto& a, auto& b) { return a.first > b.first; });
  const double z = log_add(cand[0].first, cand[1].first);
  REQUIRE(f.num_particles() == 2);
  for (int i = 0; i < 2; ++i) {
    CHECK_THAT(f.log_weight(i), WithinAbs(cand[static_cast<std::size_t>(i)].first - z, 1e-6));
    CHECK(f.particle_situation(i) == cand[static_cast<std::size_t>(i)].second.back());
  }
  return {cand[0].second, cand[1].second};
}
}  // namespace

TEST_CASE("classical RBPF weights equal a brute-force enumeration (B=2, N_z=2, three steps)", "[rbpf]") {
  const Tiny tc;
  SECTION("no pruning (M = 64): exact posterior over the 64 histories") {
    RbpfOptions opt;
    opt.variant = RbpfVariant::kClassical;
    opt.num_particles = 64;
    opt.merge = false;
    Rbpf<ConstantVelocity2> f(tc.motion, tc.st, tc.proc, tc.q, tc.g, opt);
    for (int k = 0, parents = 1; k < 3; ++k, parents *= 4) {
      const RbpfStepInfo info =
          f.step(tc.ys[static_cast<std::size_t>(k)], tc.os[static_cast<std::size_t>(k)]);
      CHECK(info.offspring == 4 * parents);  // eq. (23): N_z^B = 4 children per particle
      CHECK(info.ukf_runs == 4 * parents);   // Table IV: a UKF for every child
      CHECK(f.step_index() == k + 1);
    }
    REQUIRE(f.num_particles() == 64);
    std::vector<double> lw;
    std::vector<Vec<4>> means;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int c = 0; c < 4; ++c) {
          Vec<4> m;
          lw.push_back(tc.history_logw({sv(a), sv(b), sv(c)}, &m));
          means.push_back(m);
        }
    const double z = log_sum_exp(Eigen::Map<VecX>(lw.data(), 64));
    Vec<4> est = Vec<4>::Zero();
    for (int i = 0; i < 64; ++i)
      est += std::exp(lw[static_cast<std::size_t>(i)] - z) * means[static_cast<std::size_t>(i)];
    // match every particle to its history by mean and weight
    std::vector<double> got, want;
    for (int i = 0; i < 64; ++i) got.push_back(f.log_weight(i));
    for (double v : lw) want.push_back(v - z);
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    // 1e-6: the scaled UT (alpha = 1e-3) has centre weights of order -1e6, so summation order shows at 1e-7
    for (int i = 0; i < 64; ++i)
      CHECK_THAT(got[static_cast<std::size_t>(i)], WithinAbs(want[static_cast<std::size_t>(i)], 1e-6));
    CHECK((f.estimate() - est).cwiseAbs().maxCoeff() < 1e-6);  // eq. (28)
  }
  SECTION("M = 2: the kept histories and weights of a brute-force prune") {
    RbpfOptions opt;
    opt.variant = RbpfVariant::kClassical;
    opt.num_particles = 2;
    opt.merge = false;
    Rbpf<ConstantVelocity2> f(tc.motion, tc.st, tc.proc, tc.q, tc.g, opt);
    std::vector<std::vector<VecXi>> kept{{}};
    for (int k = 0; k < 3; ++k) {
      f.step(tc.ys[static_cast<std::size_t>(k)], tc.os[static_cast<std::size_t>(k)]);
      std::vector<std::pair<double, std::vector<VecXi>>> cand;
      for (auto& h : kept)
        for (int c = 0; c < 4; ++c) {
          auto h2 = h;
          h2.push_back(sv(c));
          cand.emplace_back(tc.history_logw(h2, nullptr), h2);
        }
      kept = check_pruned_to_two(f, cand);
    }
  }
}

TEST_CASE("zero transition probabilities: the RBPF drops the impossible children, the limit of tiny ones",
          "[rbpf]") {
  // LOS is absorbing (T(0, 1) = 0): a LOS parent's NLOS children are impossible. With the full enumeration
  // (the default max_offspring), a -inf factor once made the children NaN: a wrong estimate from the
  // reordered step, NumericalError from the classical one. Reference: T(0, 1) = 1e-300 (those children
  // weigh e^-690 and change no estimate).
  Tiny z, e;
  VecX pi(2);
  pi << 0.9, 0.1;
  z.T << 1.0, 0.0, 0.3, 0.7;
  e.T << 1.0, 1e-300, 0.3, 0.7;
  z.proc = si::SightProcess(si::SightModel::fixed(z.T, 1, pi), 2);
  e.proc = si::SightProcess(si::SightModel::fixed(e.T, 1, pi), 2);
  for (const RbpfVariant variant : {RbpfVariant::kClassical, RbpfVariant::kReordered})
    for (const double d : {-1.0, 8.0})  // eq. (31)'s d_min, and a wide one: every parent has a neighbour
      for (const int threads : {1, 2}) {
        CAPTURE(static_cast<int>(variant), d, threads);
        RbpfOptions opt;
        opt.variant = variant;
        opt.num_particles = 8;
        opt.merge_threshold = d;
        opt.threads = threads;
        Rbpf<ConstantVelocity2> fz(z.motion, z.st, z.proc, z.q, z.g, opt);
        Rbpf<ConstantVelocity2> fe(e.motion, e.st, e.proc, e.q, e.g, opt);
        for (std::size_t k = 0; k < 3; ++k) {
          fz.step(z.ys[k], z.os[k]);
          fe.step(e.ys[k], e.os[k]);
          for (int i = 0; i < fz.num_particles(); ++i) CHECK(std::isfinite(fz.log_weight(i)));
          CHECK(fz.num_particles() <= fe.num_particles());
          CHECK((fz.estimate() - fe.estimate()).cwiseAbs().maxCoeff() < 1e-9);
          CHECK((fz.covariance() - fe.covariance()).cwiseAbs().maxCoeff() < 1e-9);
          CHECK((fz.situation_probabilities() - fe.situation_probabilities()).cwiseAbs().maxCoeff() < 1e-12);
        }
      }
}

TEST_CASE(
    "classical RBPF with merging: estimate, covariance and situation probabilities are the mixture "
    "of the merged children (eqs. 27-30)",
    "[rbpf]") {
  // M = 64 keeps every child (4 per particle over three steps), so after a step the particles are exactly
  // the merged children; a wide merge threshold makes the merge move weight (checked below).
  const Tiny tc;
  for (int threads : {1, 2}) {
    RbpfOptions opt;
    opt.variant = RbpfVariant::kClassical;
    opt.num_particles = 64;
    opt.merge_threshold = 8.0;
    opt.threads = threads;
    Rbpf<ConstantVelocity2> f(tc.motion, tc.st, tc.proc, tc.q, tc.g, opt);
    int merged = 0;
    for (int k = 0; k < 3; ++k) {
      merged += f.step(tc.ys[static_cast<std::size_t>(k)], tc.os[static_cast<std::size_t>(k)]).merged;
      const VecX w = f.weights();
      Vec<4> est = Vec<4>::Zero();
      for (int i = 0; i < f.num_particles(); ++i) est += w(i) * f.particle_mean(i);  // eq. (28)
      Mat<4, 4> cov = Mat<4, 4>::Zero();
      MatX prob = MatX::Zero(2, 2);
      for (int i = 0; i < f.num_particles(); ++i) {
        const Vec<4> d = f.particle_mean(i) - est;
        cov += w(i) * (f.particle_cov(i) + d * d.transpose());  // eq. (27)
        const VecXi s = f.particle_situation(i);
        for (int b = 0; b < 2; ++b) prob(b, s(b)) += w(i);
      }
      CHECK((f.estimate() - est).cwiseAbs().maxCoeff() < 1e-9);
      CHECK((f.covariance() - cov).cwiseAbs().maxCoeff() < 1e-9 * cov.cwiseAbs().maxCoeff());
      CHECK((f.situation_probabilities() - prob).cwiseAbs().maxCoeff() < 1e-12);
    }
    CHECK(merged > 0);
  }
}

TEST_CASE("bounded enumeration in the filter: each particle's best children by prior x quality",
          "[rbpf][offspring]") {
  // max_offspring = 2 < N_z^B = 4: every particle keeps the 2 children with the largest
  // log P(s_t | s_t-1) + log p(o_t | s_t) (the documented bound), then the UKF weights (eq. 25) and the
  // prune to M = 2; checked against a brute force over the same rule
  const Tiny tc;
  const VecX pi = tc.proc.model(0).initial();
  auto score = [&](const std::vector<VecXi>& h, const VecXi& c) {
    const std::size_t k = h.size();
    double sc = 0.0;
    for (int b = 0; b < 2; ++b) {
      const double pr = k == 0 ? (pi.transpose() * tc.T)(c(b)) : tc.T(h.back()(b), c(b));
      sc += std::log(pr) + tc.q.log_likelihood(tc.os[k](b), c(b));
    }
    return sc;
  };
  for (auto variant : {RbpfVariant::kClassical, RbpfVariant::kReordered}) {
    RbpfOptions opt;
    opt.variant = variant;
    opt.num_particles = 2;
    opt.max_offspring = 2;
    opt.merge = false;
    Rbpf<ConstantVelocity2> f(tc.motion, tc.st, tc.proc, tc.q, tc.g, opt);
    CHECK(f.children_per_particle() == 2);
    std::vector<std::vector<VecXi>> kept{{}};
    for (int k = 0; k < 3; ++k) {
      const RbpfStepInfo info =
          f.step(tc.ys[static_cast<std::size_t>(k)], tc.os[static_cast<std::size_t>(k)]);
      std::vector<std::pair<double, std::vector<VecXi>>> cand;
      for (auto& h : kept) {
        std::vector<std::pair<double, int>> by;
        for (int c = 0; c < 4; ++c) by.emplace_back(score(h, sv(c)), c);
        std::sort(by.begin(), by.end(), [](auto& a, auto& b) { return a.first > b.first; });
        for (int j = 0; j < 2; ++j) {
          auto h2 = h;
          h2.push_back(sv(by[static_cast<std::size_t>(j)].second));
          cand.emplace_back(tc.history_logw(h2, nullptr), h2);
        }
      }
      CHECK(info.offspring == static_cast<int>(2 * kept.size()));
      // classical: a UKF per child; reordered (Table V): only for the M kept
      CHECK(info.ukf_runs == (variant == RbpfVariant::kClassical ? static_cast<int>(cand.size()) : 2));
      if (variant == RbpfVariant::kReordered) break;  // its selection uses the predicted weights (eq. 32)
      kept = check_pruned_to_two(f, cand);
    }
  }
}

TEST_CASE("classical RBPF, augmented noise (Table III): weights equal a brute force over UkfAugmented",
          "[rbpf]") {
  const Tiny tc(true);  // Rayleigh NLOS: median != mean, so the two noise forms give different weights
  RbpfOptions opt;
  opt.variant = RbpfVariant::kClassical;
  opt.num_particles = 64;
  opt.merge = false;
  opt.noise_form = NoiseForm::kAugmented;
  Rbpf<ConstantVelocity2> f(tc.motion, tc.st, tc.proc, tc.q, tc.g, opt);
  RbpfOptions add = opt;
  add.noise_form = NoiseForm::kAdditive;
  Rbpf<ConstantVelocity2> fa(tc.motion, tc.st, tc.proc, tc.q, tc.g, add);
  for (int k = 0; k < 3; ++k) {
    f.step(tc.ys[static_cast<std::size_t>(k)], tc.os[static_cast<std::size_t>(k)]);
    fa.step(tc.ys[static_cast<std::size_t>(k)], tc.os[static_cast<std::size_t>(k)]);
  }
  REQUIRE(f.num_particles() == 64);
  std::vector<double> lw;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int c = 0; c < 4; ++c) lw.push_back(tc.history_logw<UkfAugmented>({sv(a), sv(b), sv(c)}, nullptr));
  const double z = log_sum_exp(Eigen::Map<VecX>(lw.data(), 64));
  std::vector<double> got, want, other;
  for (int i = 0; i < 64; ++i) {
    got.push_back(f.log_weight(i));
    other.push_back(fa.log_weight(i));
  }
  for (double v : lw) want.push_back(v - z);
  std::sort(got.begin(), got.end());
  std::sort(want.begin(), want.end());
  std::sort(other.begin(), other.end());
  double gap = 0.0;
  for (int i = 0; i < 64; ++i) {
    const auto u = static_cast<std::size_t>(i);
    CHECK_THAT(got[u], WithinAbs(want[u], 1e-6));
    gap = std::max(gap, std::abs(other[u] - want[u]));
  }
  CHECK(gap > 1e-2);  // the additive form is a different filter here: the test can tell them apart
}

TEST_CASE("UKF kernel, augmented form: equals UkfAugmented's predict + update, options are checked",
          "[rbpf]") {
  const Tiny tc(true);
  UkfKernel<ConstantVelocity2> ker(tc.st, SigmaScheme::scaled(), NoiseForm::kAugmented);
  UkfAugmented<ConstantVelocity2> ref(tc.motion, tc.st, tc.g);
  for (int c = 0; c < 4; ++c) {
    const VecXi s = sv(c);
    UkfAugmented<ConstantVelocity2> r = ref;
    const StepResult want = r.step(tc.ys[0], s);
    REQUIRE(ker.prepare(tc.motion, tc.st, tc.g.mean, tc.g.cov, 0.5) == CholeskyStatus::kOk);
    Vec<4> x;
    Mat<4, 4> P;
    StepResult got;
    REQUIRE(ker.finish(s, tc.ys[0], x, P, got));
    CHECK_THAT(got.log_likelihood, WithinAbs(want.log_likelihood, 1e-10));
    CHECK((x - r.mean()).cwiseAbs().maxCoeff() < 1e-10);
    CHECK((P - r.cov()).cwiseAbs().maxCoeff() < 1e-10);
  }
  // Two-way ranging (Grisales eqs. 17, 20): non-additive, state-dependent noise, 5 inputs per exchange.
  const TwoWayClock motion(1e-3, 1e-11, 1e-11, 0.1);
  MatX anchors(2, 2);
  anchors << 100, 0, 0, 100;
  MeasurementStack tw(TwoWayClock::layout(), anchors, 2);
  for (int b = 0; b < 2; ++b) tw.add_twr(b, b, 5e-6, 1e-6, 0.2e-9, {std::nullopt, nn::Normal(8.5e-9, 2e-9)});
  Gaussian<6> g;
  g.mean << 1 - 1e-5, 500e-9, 3, -2, 0.1, 0;
  g.cov = Vec<6>(1e-12, 1e-14, 0.01, 0.01, 1, 1).asDiagonal();
  VecX y(4);
  tw.predict(g.mean, motion.dt(), y);
  y += Vec<4>(2e-9, 3e-9, -1e-9, 4e-9);
  UkfKernel<TwoWayClock> kt(tw, SigmaScheme::scaled(1.0, 2.0, 0.0), NoiseForm::kAugmented);
  for (int c = 0; c < 4; ++c) {
    const VecXi s = sv(c);
    UkfAugmented<TwoWayClock> r(motion, tw, g, SigmaScheme::scaled(1.0, 2.0, 0.0));
    const StepResult want = r.step(y, s);
    REQUIRE(kt.prepare(motion, tw, g.mean, g.cov, motion.dt()) == CholeskyStatus::kOk);
    Vec<6> x;
    Mat<6, 6> P;
    StepResult got;
    REQUIRE(kt.finish(s, y, x, P, got));
    CHECK_THAT(got.log_likelihood, WithinRel(want.log_likelihood, 1e-9));
    CHECK(((x - r.mean()).array().abs() <= 1e-9 * (1.0 + r.mean().array().abs())).all());
    CHECK(((P - r.cov()).array().abs() <= 1e-9 * r.cov().cwiseAbs().maxCoeff()).all());
  }
  RbpfOptions bad;
  bad.noise_form = static_cast<NoiseForm>(7);
  CHECK_THROWS_WITH(Rbpf<ConstantVelocity2>(tc.motion, tc.st, tc.proc, tc.q, tc.g, bad),
                    "options.noise_form: unknown NoiseForm");
}

TEST_CASE("reordered RBPF: weights of eqs. 32-33 and merge of identical parents", "[rbpf]") {
  const Tiny tc;
  RbpfOptions opt;
  opt.variant = RbpfVariant::kReordered;
  opt.num_particles = 3;
  opt.merge = false;
  Rbpf<ConstantVelocity2> f(tc.motion, tc.st, tc.proc, tc.q, tc.g, opt);
  f.step(tc.ys[0], tc.os[0]);
  // step 1: one parent, children ranked by prior x quality (eq. 32), top 3 run a UKF, weights eq. (33)
  std::vector<std::pair<double, int>> pre;
  for (int c = 0; c < 4; ++c) {
    double lw = 0.0;
    const VecX pi = tc.proc.model(0).initial();
    for (int b = 0; b < 2; ++b)
      lw += std::log((pi.transpose() * tc.T)(sv(c)(b))) + tc.q.log_likelihood(tc.os[0](b), sv(c)(b));
    pre.emplace_back(lw, c);
  }
  std::sort(pre.begin(), pre.end(), std::greater<>());
  std::vector<double> full;
  for (int i = 0; i < 3; ++i)
    full.push_back(tc.history_logw({sv(pre[static_cast<std::size_t>(i)].second)}, nullptr));
  const double z = log_sum_exp(Eigen::Map<VecX>(full.data(), 3));
  REQUIRE(f.num_particles() == 3);
  std::map<std::uint64_t, double> got;
  for (int i = 0; i < 3; ++i) got[encode_situation(f.particle_situation(i), 2)] = f.log_weight(i);
  for (int i = 0; i < 3; ++i)
    CHECK_THAT(got.at(encode_situation(sv(pre[static_cast<std::size_t>(i)].second), 2)),
               WithinAbs(full[static_cast<std::size_t>(i)] - z, 1e-9));
  // merge: with a huge d_min all children of equal situation collapse, so at most N_z^B = 4 particles survive
  RbpfOptions mo = opt;
  mo.merge = true;
  mo.merge_threshold = 1e9;
  mo.num_particles = 16;
  Rbpf<ConstantVelocity2> g(tc.motion, tc.st, tc.proc, tc.q, tc.g, mo);
  for (int k = 0; k < 3; ++k) {
    const RbpfStepInfo info = g.step(tc.ys[static_cast<std::size_t>(k)], tc.os[static_cast<std::size_t>(k)]);
    CHECK(g.num_particles() <= 4);
    if (k > 0) CHECK(info.merged > 0);
  }
  CHECK_THAT(g.weights().sum(), WithinAbs(1.0, 1e-12));
  CHECK_THAT(g.situation_probabilities().row(0).sum(), WithinAbs(1.0, 1e-12));
}

namespace {
struct H2Like {
  ConstantVelocityClock2 motion{0.01, 1.0, 1e-2};
  MeasurementStack st;
  si::SightProcess proc{si::SightModel::speed_dependent(10, 10, 0.01), 6};
  si::QualityModel q{{nn::Beta(4, 1.5), nn::Beta(1.5, 4)}};
  Gaussian<6> g;
  H2Like() : st(ConstantVelocityClock2::layout(), anchors(), 2) {
    for (int b = 0; b < 6; ++b)
      st.add_rtoa(b, {nn::Normal(0, std::sqrt(10.0)), nn::Rayleigh::from_variance(5000)});
    g.mean << 0, 0, 0, 0, 0, 0;
    g.cov = Vec<6>(25, 25, 10, 1, 1, 10).asDiagonal();
  }
  static MatX anchors() {
    MatX a(6, 2);
    for (int b = 0; b < 6; ++b) {
      a(b, 0) = 3000 * std::cos(b * kPi / 3);
      a(b, 1) = 3000 * std::sin(b * kPi / 3);
    }
    return a;
  }
  /// Simulated track: truth, y, o.
  void simulate(int steps, std::uint64_t seed, std::vector<VecX>& y, std::vector<VecX>& o,
                std::vector<Vec<6>>& truth) const {
    Rng rng(seed);
    Vec<6> x = Vec<6>::Zero();
    x(3) = 1.0;
    VecXi s = proc.sample_initial(rng);
    for (int k = 1; k <= steps; ++k) {
      x = motion.F() * x;
      x(3) += std::sqrt(0.01) * rng.normal();
      x(4) += std::sqrt(0.01) * rng.normal();
      VecX w(6);
      si::transversal_speeds(x.head<2>(), x.segment<2>(3), st.anchors(), w);
      s = proc.sample_next(s, k, w, rng);
      VecX yk(6);
      st.predict(x, 0.0, yk);
      for (int b = 0; b < 6; ++b) yk(b) += st.noise(b, s(b)).sample(rng);
      y.push_back(yk);
      o.push_back(q.sample(s, rng));
      truth.push_back(x);
    }
  }
};
}  // namespace

TEST_CASE("RBPF on an H2-like track: 1 and 2 threads agree, estimate tracks", "[rbpf]") {
  // The prior mean is put 10 m off the track's start (2 sigma of the prior), so the tracking bound below
  // fails for a filter that stays at its prior: the track moves 0.44 m in its 2 s, so from a prior mean
  // on its start any bound above 0.5 m passed for the prior mean alone.
  H2Like h;
  h.g.mean.head<2>() << 6.0, -8.0;
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(200, 7, y, o, truth);
  for (auto variant : {RbpfVariant::kReordered, RbpfVariant::kClassical}) {
    RbpfOptions opt;
    opt.variant = variant;
    opt.num_particles = variant == RbpfVariant::kReordered ? 64 : 2;  // 64: the pool is used (kMinParallel)
    Rbpf<ConstantVelocityClock2> f1(h.motion, h.st, h.proc, h.q, h.g, opt);
    opt.threads = 2;
    Rbpf<ConstantVelocityClock2> f2(h.motion, h.st, h.proc, h.q, h.g, opt);
    opt.threads = 3;  // the shared cut of the reordered enumeration takes the minimum over the others
    Rbpf<ConstantVelocityClock2> f3(h.motion, h.st, h.proc, h.q, h.g, opt);
    long merged1 = 0, merged2 = 0, same_steps = 0;
    for (std::size_t k = 0; k < y.size(); ++k) {
      const auto i1 = f1.step(y[k], o[k]);
      const auto i2 = f2.step(y[k], o[k]);
      const auto i3 = f3.step(y[k], o[k]);
      CHECK(i1.failures == 0);
      merged1 += i1.merged;
      merged2 += i2.merged;
      same_steps += i1.merged == i2.merged && i1.merged == i3.merged &&
                            f1.num_particles() == f2.num_particles() &&
                            f1.num_particles() == f3.num_particles()
                        ? 1
                        : 0;
    }
    // The same particles (situations and weights) whatever the thread count: the global top M is kept.
    auto particles = [](const Rbpf<ConstantVelocityClock2>& f) {
      std::vector<std::pair<long, double>> v;
      for (int i = 0; i < f.num_particles(); ++i) {
        long key = 0;
        const VecXi z = f.particle_situation(i);
        for (int b = static_cast<int>(z.size()) - 1; b >= 0; --b) key = key * 2 + z(b);
        v.push_back({key, f.log_weight(i)});
      }
      std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
      return v;
    };
    const auto p1 = particles(f1);
    for (const auto* g : {&f2, &f3}) {
      const auto p2 = particles(*g);
      REQUIRE(p1.size() == p2.size());
      std::multiset<long> k1, k2;
      for (std::size_t i = 0; i < p1.size(); ++i) {
        k1.insert(p1[i].first);
        k2.insert(p2[i].first);
        CHECK(std::abs(p1[i].second - p2[i].second) < 1e-9);
      }
      CHECK(k1 == k2);
    }
    CHECK((f1.estimate() - f3.estimate()).cwiseAbs().maxCoeff() < 1e-9);
    // The 2-thread merge (split by key over the threads) absorbs the same children as the serial one.
    CHECK(merged1 > 0);
    CHECK(merged1 == merged2);
    CHECK(same_steps == static_cast<long>(y.size()));
    CHECK((f1.estimate() - f2.estimate()).cwiseAbs().maxCoeff() < 1e-9);
    // measured 0.533 m for both variants (the prior mean: 10.3 m); was < 15 m
    CHECK((f1.estimate().head<2>() - truth.back().head<2>()).norm() < 1.5);
    CHECK(is_spd(f1.covariance()));
  }
  CHECK_THROWS_AS(
      Rbpf<ConstantVelocityClock2>(h.motion, h.st, h.proc, h.q, h.g, RbpfOptions{RbpfVariant::kReordered, 0}),
      std::invalid_argument);
}

TEST_CASE("RBPF: the same result bit for bit on 1, 2 and 3 threads", "[rbpf]") {
  // The UKF bank's chunks, and the moment sums of eqs. (27)-(28) taken per chunk, depend on the kept
  // children only (Rbpf::bank_split): no output may depend on the threads or on which thread claimed which
  // chunk. M = 256 cuts the bank into other chunks than M = 128 (bank_split's guided sizes, not its
  // caps: about 7 chunks per side); the augmented noise form cuts them elsewhere (a parent's preparation
  // costs less).
  const H2Like h;
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(120, 11, y, o, truth);
  struct Case {
    RbpfVariant variant;
    int M;
    NoiseForm noise;
  };
  for (const Case c : {Case{RbpfVariant::kReordered, 128, NoiseForm::kAdditive},
                       Case{RbpfVariant::kReordered, 256, NoiseForm::kAugmented},
                       Case{RbpfVariant::kClassical, 2, NoiseForm::kAdditive}}) {
    CAPTURE(c.M, static_cast<int>(c.noise));
    RbpfOptions opt;
    opt.variant = c.variant;
    opt.num_particles = c.M;
    opt.noise_form = c.noise;
    std::vector<std::unique_ptr<Rbpf<ConstantVelocityClock2>>> f;
    for (const int threads : {1, 2, 3}) {
      opt.threads = threads;
      f.push_back(std::make_unique<Rbpf<ConstantVelocityClock2>>(h.motion, h.st, h.proc, h.q, h.g, opt));
    }
    long differing = 0, compared = 0;
    for (std::size_t k = 0; k < y.size(); ++k) {
      for (auto& g : f) g->step(y[k], o[k]);
      for (std::size_t j = 1; j < f.size(); ++j) {
        const auto& a = *f[0];
        const auto& b = *f[j];
        bool same = a.estimate() == b.estimate() && a.covariance() == b.covariance() &&
                    a.situation_probabilities() == b.situation_probabilities() &&
                    a.num_particles() == b.num_particles();
        for (int i = 0; same && i < a.num_particles(); ++i)
          same = a.log_weight(i) == b.log_weight(i) && a.particle_mean(i) == b.particle_mean(i) &&
                 a.particle_cov(i) == b.particle_cov(i) && a.particle_situation(i) == b.particle_situation(i);
        differing += same ? 0 : 1;
        ++compared;
      }
    }
    CHECK(compared == 2 * static_cast<long>(y.size()));
    CHECK(differing == 0);
    CHECK(f[0]->num_particles() == c.M);
  }
}

namespace {
/// Everything two filters report, equal bit for bit.
template <class F>
bool same_filter(const F& a, const F& b) {
  bool same = a.estimate() == b.estimate() && a.covariance() == b.covariance() &&
              a.situation_probabilities() == b.situation_probabilities() &&
              a.num_particles() == b.num_particles() && a.time() == b.time() &&
              a.step_index() == b.step_index();
  for (int i = 0; same && i < a.num_particles(); ++i)
    same = a.log_weight(i) == b.log_weight(i) && a.particle_mean(i) == b.particle_mean(i) &&
           a.particle_cov(i) == b.particle_cov(i) && a.particle_situation(i) == b.particle_situation(i);
  return same;
}
}  // namespace

TEST_CASE("RBPF save/restore: a filter set to another's snapshot steps on as that one, bit for bit",
          "[rbpf]") {
  const H2Like h;
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(60, 13, y, o, truth);
  Gaussian<6> elsewhere = h.g;
  elsewhere.mean.array() += 3.0;
  struct Case {
    RbpfVariant variant;
    int M, threads_a, threads_b;
    NoiseForm noise;
  };
  for (const Case c : {Case{RbpfVariant::kReordered, 128, 2, 1, NoiseForm::kAdditive},
                       Case{RbpfVariant::kReordered, 16, 1, 2, NoiseForm::kAugmented},
                       Case{RbpfVariant::kClassical, 2, 2, 1, NoiseForm::kAdditive}}) {
    CAPTURE(c.M, static_cast<int>(c.variant));
    RbpfOptions opt;
    opt.variant = c.variant;
    opt.num_particles = c.M;
    opt.noise_form = c.noise;
    opt.threads = c.threads_a;
    Rbpf<ConstantVelocityClock2> a(h.motion, h.st, h.proc, h.q, h.g, opt);
    opt.threads = c.threads_b;  // the result does not depend on the threads
    Rbpf<ConstantVelocityClock2> b(h.motion, h.st, h.proc, h.q, elsewhere, opt);
    // from the start (step 0: the next step draws from the initial sight) and mid-track
    b.restore(a.save());
    CHECK(same_filter(a, b));
    for (std::size_t k = 0; k < 30; ++k) a.step(y[k], o[k]);
    const RbpfSnapshot s = a.save();
    CHECK(s.step == 30);
    CHECK(s.situations.rows() == a.num_particles());
    b.restore(s);
    REQUIRE(same_filter(a, b));
    long differing = 0;
    for (std::size_t k = 30; k < y.size(); ++k) {
      a.step(y[k], o[k]);
      b.step(y[k], o[k]);
      differing += same_filter(a, b) ? 0 : 1;
    }
    CHECK(differing == 0);
  }
}

TEST_CASE("RBPF restore: a bad snapshot is refused, naming the field, and changes nothing", "[rbpf]") {
  const H2Like h;
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(10, 3, y, o, truth);
  RbpfOptions opt;
  opt.num_particles = 8;
  Rbpf<ConstantVelocityClock2> f(h.motion, h.st, h.proc, h.q, h.g, opt);
  for (std::size_t k = 0; k < y.size(); ++k) f.step(y[k], o[k]);
  const RbpfSnapshot good = f.save();
  REQUIRE(good.situations.rows() == 8);
  const auto refused = [&](const std::function<void(RbpfSnapshot&)>& edit) {
    RbpfSnapshot s = good;
    edit(s);
    try {
      f.restore(s);
    } catch (const std::invalid_argument& e) {
      CHECK(f.save().means == good.means);  // unchanged
      CHECK(f.step_index() == good.step);
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  using Catch::Matchers::StartsWith;
  CHECK(refused([](RbpfSnapshot& s) { s.situations.resize(0, 6); }) ==
        "snapshot.situations: expected 1 to 8 particles (rows), got 0");
  CHECK(refused([](RbpfSnapshot& s) { s.situations.conservativeResize(9, Eigen::NoChange); }) ==
        "snapshot.situations: expected 1 to 8 particles (rows), got 9");
  CHECK_THAT(refused([](RbpfSnapshot& s) { s.situations.conservativeResize(Eigen::NoChange, 5); }),
             StartsWith("snapshot.situations: expected shape (8, 6)"));
  CHECK(refused([](RbpfSnapshot& s) { s.situations(2, 1) = 2; }) ==
        "snapshot.situations: expected condition indices 0 to 1");
  CHECK_THAT(refused([](RbpfSnapshot& s) { s.means(0, 0) = std::nan(""); }), StartsWith("snapshot.means"));
  CHECK(refused([](RbpfSnapshot& s) { s.covs.pop_back(); }) ==
        "snapshot.covs: expected 8 covariances, got 7");
  CHECK(refused([](RbpfSnapshot& s) { s.covs[3](0, 1) += 1.0; }) ==
        "snapshot.covs[3]: expected a symmetric positive definite matrix");
  Eigen::Index heaviest = 0;
  good.log_weights.maxCoeff(&heaviest);
  CHECK_THAT(
      refused([&](RbpfSnapshot& s) { s.log_weights[heaviest] += 0.5; }),
      StartsWith("snapshot.log_weights: expected normalised log weights (log-sum-exp 0), got log-sum-exp"));
  CHECK(refused([](RbpfSnapshot& s) { s.log_weights[0] = std::nan(""); }) ==
        "snapshot.log_weights: expected finite values or -inf");
  CHECK(refused([](RbpfSnapshot& s) { s.situation_probabilities(0, 0) += 0.1; }) ==
        "snapshot.situation_probabilities: expected probabilities in [0, 1] with rows summing to 1");
  CHECK(refused([](RbpfSnapshot& s) { s.covariance(1, 1) = -1.0; }) ==
        "snapshot.covariance: expected a symmetric positive definite matrix");
  CHECK(refused([](RbpfSnapshot& s) { s.time = std::nan(""); }) ==
        "snapshot.time: expected a finite time (s)");
  CHECK(refused([](RbpfSnapshot& s) { s.step = -1; }) == "snapshot.step: expected >= 0, got -1");
  // a particle ruled out (-inf) is a valid weight
  CHECK(refused([&](RbpfSnapshot& s) {
          s.log_weights[heaviest == 7 ? 6 : 7] = -std::numeric_limits<double>::infinity();
          s.log_weights.array() -= log_sum_exp(s.log_weights);
        }) == "accepted");
}

TEST_CASE("reordered RBPF: a step that throws leaves the filter as it was", "[rbpf]") {
  // A measurement no UKF update can explain (every likelihood underflows) throws NumericalError after the
  // bank ran. The next steps must equal those of a twin that never saw it: the bank's predicted means of
  // the discarded children (kept for the next step's neighbour sweep) must not be used. The failure is
  // put just before a step where the twin merges, so a wrong sweep shows.
  H2Like h;
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(60, 5, y, o, truth);
  for (const int threads : {1, 2}) {
    RbpfOptions opt;
    opt.num_particles = 128;
    opt.threads = threads;
    Rbpf<ConstantVelocityClock2> f(h.motion, h.st, h.proc, h.q, h.g, opt);
    Rbpf<ConstantVelocityClock2> twin(h.motion, h.st, h.proc, h.q, h.g, opt);
    std::vector<long> merged;
    for (std::size_t k = 0; k < y.size(); ++k) merged.push_back(twin.step(y[k], o[k]).merged);
    std::size_t fail = 20;
    while (fail < y.size() && merged[fail] == 0) ++fail;
    REQUIRE(fail < y.size());
    twin.reset(h.g);
    for (std::size_t k = 0; k < y.size(); ++k) {
      if (k == fail) {
        const Vec<6> before = f.estimate();
        CHECK_THROWS_AS(f.step(VecX::Constant(6, 1e300), o[k]), NumericalError);
        CHECK(f.estimate() == before);
      }
      const auto a = f.step(y[k], o[k]);
      const auto b = twin.step(y[k], o[k]);
      CHECK(a.merged == b.merged);
      CHECK(b.merged == merged[k]);
      CHECK(f.estimate() == twin.estimate());
    }
  }
}

TEST_CASE("an overflowed state: NumericalError, the filter unchanged, no random draw spent", "[rbpf][pf]") {
  // Finite, so the filters take it, but eq. (10)'s transversal speed overflows to NaN. That was a
  // std::invalid_argument naming an internal "w" or "speeds"; the joint PF's generic sight path threw it
  // from inside its pass, after the generators had drawn.
  H2Like h;
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(3, 2, y, o, truth);
  Gaussian<6> huge = h.g;
  huge.mean << 1e160, 1e160, 0, 1e160, 1e160, 0;
  for (const int threads : {1, 2}) {
    RbpfOptions opt;
    opt.num_particles = 16;
    opt.threads = threads;
    Rbpf<ConstantVelocityClock2> f(h.motion, h.st, h.proc, h.q, huge, opt);
    CHECK_THROWS_AS(f.step(y[0], o[0]), NumericalError);
    CHECK_THROWS_WITH(f.step(y[0], o[0]),
                      Catch::Matchers::StartsWith("Rbpf.step: the transversal speed (eq. 10)"));
    CHECK(f.step_index() == 0);
    CHECK(f.estimate() == huge.mean);
    // generic sight path: one chain is fixed
    std::vector<si::SightModel> models(5, si::SightModel::speed_dependent(10, 10, 0.01));
    MatX T(2, 2);
    T << 0.99, 0.01, 0.02, 0.98;
    models.push_back(si::SightModel::fixed(T));
    PfOptions po;
    po.num_particles = 500;
    po.threads = threads;
    ParticleFilter<ConstantVelocityClock2> pf(h.motion, h.st, si::SightProcess(models), h.q, huge, po);
    ParticleFilter<ConstantVelocityClock2> twin(h.motion, h.st, si::SightProcess(models), h.q, huge, po);
    CHECK_THROWS_AS(pf.step(y[0], o[0]), NumericalError);  // every particle: zero likelihood
    pf.reset(h.g);
    twin.reset(h.g);
    for (std::size_t k = 0; k < y.size(); ++k) {
      pf.step(y[k], o[k]);
      twin.step(y[k], o[k]);
      CHECK(pf.estimate() == twin.estimate());
    }
  }
  Iukf<ConstantVelocityClock2> iukf(h.motion, h.st, huge, si::ForwardFilter(h.proc, h.q));
  CHECK_THROWS_AS(iukf.step_quality(y[0], o[0]), NumericalError);
  CHECK_THROWS_WITH(iukf.step_quality(y[0], o[0]),
                    Catch::Matchers::StartsWith("Iukf.step: the transversal speed (eq. 10)"));
  CHECK(iukf.mean() == huge.mean);
  CHECK(iukf.time() == 0.0);
}

TEST_CASE("reordered RBPF: children tied at the cut are kept by index alike on 1, 2 and 3 threads",
          "[rbpf]") {
  // Uninformative sight (every transition 1/2) and quality (one distribution for both conditions): all the
  // children of a parent have exactly the same prior weight, so the M-th weight is shared by many children
  // and their index decides which are kept. Every thread count keeps the same ones, in the same order.
  H2Like h;
  h.proc = si::SightProcess{si::SightModel::fixed(MatX::Constant(2, 2, 0.5)), 6};
  h.q = si::QualityModel{{nn::Beta(2, 2), nn::Beta(2, 2)}};
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(30, 11, y, o, truth);
  RbpfOptions opt;
  opt.num_particles = 64;  // the pool is used (kMinParallel)
  Rbpf<ConstantVelocityClock2> f1(h.motion, h.st, h.proc, h.q, h.g, opt);
  opt.threads = 2;
  Rbpf<ConstantVelocityClock2> f2(h.motion, h.st, h.proc, h.q, h.g, opt);
  opt.threads = 3;
  Rbpf<ConstantVelocityClock2> f3(h.motion, h.st, h.proc, h.q, h.g, opt);
  long same = 0, compared = 0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    const auto i1 = f1.step(y[k], o[k]);
    for (auto* g : {&f2, &f3}) {
      const auto ig = g->step(y[k], o[k]);
      REQUIRE(g->num_particles() == f1.num_particles());
      CHECK(ig.merged == i1.merged);
      for (int i = 0; i < f1.num_particles(); ++i) {
        ++compared;
        same += f1.particle_situation(i) == g->particle_situation(i) &&
                        std::abs(f1.log_weight(i) - g->log_weight(i)) < 1e-9
                    ? 1
                    : 0;
      }
    }
  }
  CHECK(f1.num_particles() == 64);
  CHECK(same == compared);
  CHECK((f1.estimate() - f3.estimate()).cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("thread pool runs every index once and forwards exceptions", "[rbpf]") {
  ThreadPool pool(2);
  std::vector<int> hit(1000, 0);
  for (int rep = 0; rep < 50; ++rep)
    pool.parallel_for(1000, [&](int b, int e, int) {
      for (int i = b; i < e; ++i) ++hit[static_cast<std::size_t>(i)];
    });
  CHECK(std::all_of(hit.begin(), hit.end(), [](int v) { return v == 50; }));
  CHECK_THROWS_AS(pool.parallel_for(10,
                                    [](int b, int, int) {
                                      if (b > 0) throw std::runtime_error("boom");
                                    }),
                  std::runtime_error);
}

TEST_CASE("thread pool hands off between spinning and sleeping threads", "[rbpf]") {
  // Idle gaps and chunk times from 0 to 2 ms straddle the spin (about 0.5 ms here) and the blocking waits,
  // so the workers and the caller take every path: spinning, asleep on the condition variables, and going
  // to sleep just as the other side arrives. A lost wake-up would hang the test.
  ThreadPool pool(3);
  std::vector<int> hit(3, 0);
  for (int rep = 0; rep < 300; ++rep) {
    const auto gap = std::chrono::microseconds((rep * 37) % 2000);
    if (rep % 3 == 0) std::this_thread::sleep_for(gap);  // the workers may fall asleep
    pool.parallel_for(3, [&](int b, int, int t) {
      if (rep % 3 == 1 && t > 0) std::this_thread::sleep_for(gap);   // the caller may fall asleep
      if (rep % 3 == 2 && t == 0) std::this_thread::sleep_for(gap);  // the workers wait for the next job
      ++hit[static_cast<std::size_t>(b)];
    });
  }
  CHECK(hit == std::vector<int>{300, 300, 300});
  // An exception from a worker reaches a caller that went to sleep waiting for it.
  CHECK_THROWS_WITH(pool.parallel_for(3,
                                      [](int b, int, int) {
                                        if (b == 2) {
                                          std::this_thread::sleep_for(std::chrono::milliseconds(20));
                                          throw std::runtime_error("late boom");
                                        }
                                      }),
                    "late boom");
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  int after = 0;
  pool.parallel_for(3, [&](int, int, int t) {
    if (t == 0) after = 1;
  });
  CHECK(after == 1);
}

TEST_CASE("systematic resampling is unbiased", "[rbpf][pf]") {
  VecX w(5);
  w << 0.05, 0.4, 0.1, 0.3, 0.15;
  const int M = 7;
  std::vector<double> counts(5, 0.0);
  std::vector<int> out(M);
  Rng rng(9);
  const int reps = 200000;
  for (int r = 0; r < reps; ++r) {
    systematic_resample(w, 5, M, rng.uniform(), out.data());
    for (int j : out) counts[static_cast<std::size_t>(j)] += 1.0;
  }
  for (int i = 0; i < 5; ++i)
    CHECK_THAT(counts[static_cast<std::size_t>(i)] / reps, WithinAbs(M * w(i), 0.01));
  // each particle is copied floor(M w) or ceil(M w) times
  systematic_resample(w, 5, M, 0.5, out.data());
  for (int i = 0; i < 5; ++i) {
    const auto c = std::count(out.begin(), out.end(), i);
    CHECK(c >= static_cast<long>(std::floor(M * w(i))));
    CHECK(c <= static_cast<long>(std::ceil(M * w(i))));
  }
}

TEST_CASE("the PF's chunked systematic resampling: every pointer once, unbiased, equal to one serial pass",
          "[rbpf][pf]") {
  // ParticleFilter::resample runs systematic_resample_chunk on every thread's chunk of the particles
  const int n = 40;
  Rng rng(21);
  VecX w(n);
  for (int i = 0; i < n; ++i) w(i) = (i % 7 == 3) ? 0.0 : 3.7 * rng.uniform();  // unnormalised, some zero
  w(n - 1) = 0.0;                                                               // a zero at the end
  const double total = w.sum();
  for (int M : {1, 7, 40, 123}) {
    std::vector<int> serial(static_cast<std::size_t>(M));
    for (int T : {1, 2, 3, 5}) {
      std::vector<double> mean(n, 0.0);
      const int K = 2000;  // u0 on a fine grid: the mean count is M w_i / total up to 1/K
      for (int kk = 0; kk < K; ++kk) {
        const double u0 = (kk + 0.5) / K;
        systematic_resample_chunk(w, 0, n, 0.0, total, total, M, u0, 0, 1, serial.data());
        std::vector<int> out(static_cast<std::size_t>(M), -1);
        double c0 = 0.0;
        int next = 0;
        for (int t = 0; t < T; ++t) {
          const int b = n * t / T, e = n * (t + 1) / T;
          const double c1 = c0 + w.segment(b, e - b).sum();
          const auto [jb, je] = systematic_resample_chunk(w, b, e, c0, c1, total, M, u0, t, T, out.data());
          if (jb < je) {
            CHECK(jb == next);  // the chunks' pointer ranges partition [0, M) in order
            next = je;
          }
          for (int j = jb; j < je; ++j)
            CHECK((out[static_cast<std::size_t>(j)] >= b && out[static_cast<std::size_t>(j)] < e));
          c0 = c1;
        }
        CHECK(next == M);
        CHECK(out == serial);
        for (int j : out) mean[static_cast<std::size_t>(j)] += 1.0 / K;
      }
      for (int i = 0; i < n; ++i) {
        INFO("M " << M << " T " << T << " i " << i);
        CHECK_THAT(mean[static_cast<std::size_t>(i)], WithinAbs(M * w(i) / total, 1.0 / K + 1e-12));
        if (w(i) == 0.0) CHECK(mean[static_cast<std::size_t>(i)] == 0.0);
      }
    }
  }
}

TEST_CASE("joint PF tracks the H2-like track, merge-select keeps M particles", "[rbpf][pf]") {
  // prior mean 10 m off the track's start, as in the RBPF's tracking test
  H2Like h;
  h.g.mean.head<2>() << 6.0, -8.0;
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(100, 3, y, o, truth);
  for (auto rs : {PfResampling::kSystematic, PfResampling::kMergeSelect}) {
    PfOptions opt;
    opt.num_particles = 20000;
    opt.resampling = rs;
    opt.threads = 2;
    opt.seed = 4;
    ParticleFilter<ConstantVelocityClock2> pf(h.motion, h.st, h.proc, h.q, h.g, opt);
    for (std::size_t k = 0; k < y.size(); ++k) {
      const PfStepInfo info = pf.step(y[k], o[k]);
      CHECK(std::isfinite(info.log_likelihood));
    }
    // measured 0.94 m (systematic) and 1.00 m (merge-select); the prior mean: 9.3 m; was < 15 m
    CHECK((pf.estimate().head<2>() - truth.back().head<2>()).norm() < 2.5);
    CHECK_THAT(pf.situation_probabilities().row(0).sum(), WithinAbs(1.0, 1e-9));
    CHECK(pf.particles().cols() == 20000);
  }
}

TEST_CASE("Rbpf and ParticleFilter are movable (estimators own them by value)", "[rbpf]") {
  const H2Like h;
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(20, 5, y, o, truth);
  RbpfOptions opt;
  opt.threads = 2;
  Rbpf<ConstantVelocityClock2> a(h.motion, h.st, h.proc, h.q, h.g, opt);
  Rbpf<ConstantVelocityClock2> ref(h.motion, h.st, h.proc, h.q, h.g, opt);
  for (int k = 0; k < 10; ++k) {
    a.step(y[static_cast<std::size_t>(k)], o[static_cast<std::size_t>(k)]);
    ref.step(y[static_cast<std::size_t>(k)], o[static_cast<std::size_t>(k)]);
  }
  Rbpf<ConstantVelocityClock2> b(std::move(a));
  for (int k = 10; k < 15; ++k) {
    b.step(y[static_cast<std::size_t>(k)], o[static_cast<std::size_t>(k)]);
    ref.step(y[static_cast<std::size_t>(k)], o[static_cast<std::size_t>(k)]);
  }
  // Move assignment over a filter that has stepped (its pool and scratch go; the moved-from one is empty).
  Rbpf<ConstantVelocityClock2> c(h.motion, h.st, h.proc, h.q, h.g, opt);
  c.step(y[0], o[0]);
  c = std::move(b);
  for (int k = 15; k < 20; ++k) {
    c.step(y[static_cast<std::size_t>(k)], o[static_cast<std::size_t>(k)]);
    ref.step(y[static_cast<std::size_t>(k)], o[static_cast<std::size_t>(k)]);
  }
  CHECK((c.estimate() - ref.estimate()).cwiseAbs().maxCoeff() < 1e-12);
  PfOptions po;
  po.num_particles = 1000;
  ParticleFilter<ConstantVelocityClock2> p(h.motion, h.st, h.proc, h.q, h.g, po);
  ParticleFilter<ConstantVelocityClock2> p2(std::move(p));
  CHECK(std::isfinite(p2.step(y[0], o[0]).log_likelihood));
}

TEST_CASE("joint PF: closed-form Normal/Rayleigh likelihood equals the generic one", "[rbpf][pf]") {
  // same seed, one stack with Normal/Rayleigh (fast path) and one with an equal AsymmetricNormal LOS row
  // (generic path): the weights after one step must agree.
  const H2Like h;
  MeasurementStack generic(ConstantVelocityClock2::layout(), H2Like::anchors(), 2);
  for (int b = 0; b < 6; ++b)
    generic.add_rtoa(
        b, {nn::AsymmetricNormal(0.0, std::sqrt(10.0), std::sqrt(10.0)), nn::Rayleigh::from_variance(5000)});
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(3, 8, y, o, truth);
  PfOptions po;
  po.num_particles = 500;
  po.ess_threshold = 0.0;
  ParticleFilter<ConstantVelocityClock2> fa(h.motion, h.st, h.proc, h.q, h.g, po);
  ParticleFilter<ConstantVelocityClock2> fb(h.motion, generic, h.proc, h.q, h.g, po);
  for (int k = 0; k < 3; ++k) {
    const double la = fa.step(y[static_cast<std::size_t>(k)], o[static_cast<std::size_t>(k)]).log_likelihood;
    const double lb = fb.step(y[static_cast<std::size_t>(k)], o[static_cast<std::size_t>(k)]).log_likelihood;
    CHECK_THAT(la, WithinAbs(lb, 1e-8));
  }
  int mismatches = 0;
  for (int i = 0; i < 500; ++i) {
    const double a = fa.log_weights()(i), b = fb.log_weights()(i);
    if (!((a == kNegInf && b == kNegInf) || std::abs(a - b) < 1e-8)) ++mismatches;  // -inf: Rayleigh support
  }
  CHECK(mismatches == 0);
}

#ifndef NLOSLOC_NATIVE_TESTS  // the merge references: in nlosloc_tests only (tests/CMakeLists.txt)
namespace {
/// A child of the brute-force merge: situation key, log weight, the point whose distance eq. (29) measures
/// (classical: the updated mean; reordered: the parent's predicted mean F x_p; replaced by the updated
/// mean once kept) and its parent (-1 when unknown).
struct BfChild {
  std::uint64_t key;
  double logw;
  VecX point;
  int parent;
};
/// The distance rule of eq. (29), ||x_a - x_b|| < d_min, and mutations of it that a test must reject.
enum class BfRule { kNorm, kNormOrEqual, kSquaredNorm, kLeadOnly };
bool bf_close(const VecX& a, const VecX& b, double d, BfRule rule) {
  switch (rule) {
    case BfRule::kNorm: return (a - b).norm() < d;
    case BfRule::kNormOrEqual: return (a - b).norm() <= d;
    case BfRule::kSquaredNorm: return (a - b).squaredNorm() < d;
    case BfRule::kLeadOnly: return (a - b).head<2>().norm() < d;
  }
  return false;
}
double bf_log_add(double a, double b) {
  const double m = std::max(a, b);
  return m == kNegInf ? m : m + std::log(std::exp(a - m) + std::exp(b - m));
}
/// The greedy merge of merge.hpp's header written out plainly: within each situation key, the children in
/// decreasing weight (as at the start; ties to the lower position in v); each one not yet absorbed absorbs
/// every later one not yet absorbed within d (eq. 30: w_a <- w_a + w_b, w_b <- 0). Returns the number
/// absorbed.
int bf_merge(std::vector<BfChild>& v, double d, BfRule rule) {
  std::map<std::uint64_t, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i].logw > kNegInf) groups[v[i].key].push_back(i);
  int absorbed = 0;
  for (auto& kv : groups) {
    std::vector<std::size_t>& g = kv.second;
    std::stable_sort(g.begin(), g.end(), [&](std::size_t a, std::size_t b) { return v[a].logw > v[b].logw; });
    for (std::size_t i = 0; i < g.size(); ++i) {
      BfChild& a = v[g[i]];
      if (a.logw == kNegInf) continue;
      for (std::size_t j = i + 1; j < g.size(); ++j) {
        BfChild& b = v[g[j]];
        if (b.logw == kNegInf || !bf_close(a.point, b.point, d, rule)) continue;
        a.logw = bf_log_add(a.logw, b.logw);
        b.logw = kNegInf;
        ++absorbed;
      }
    }
  }
  return absorbed;
}
/// The (at most) M heaviest children of non-zero weight, heaviest first (ties to the lower position).
std::vector<BfChild> bf_top(const std::vector<BfChild>& v, int M) {
  std::vector<BfChild> s;
  for (const BfChild& c : v)
    if (c.logw > kNegInf) s.push_back(c);
  std::stable_sort(s.begin(), s.end(), [](const BfChild& a, const BfChild& b) { return a.logw > b.logw; });
  if (s.size() > static_cast<std::size_t>(M)) s.resize(static_cast<std::size_t>(M));
  return s;
}
/// Log weights normalised over the children.
void bf_normalise(std::vector<BfChild>& v) {
  double z = kNegInf;
  for (const BfChild& c : v) z = bf_log_add(z, c.logw);
  for (BfChild& c : v) c.logw -= z;
}
/// Merged with `rule` instead of eq. (29), the M kept children (parent, key, weight to 1e-9) differ.
bool bf_rule_matters(const std::vector<BfChild>& children, double d, BfRule rule, int M) {
  std::vector<BfChild> a = children, b = children;
  const int na = bf_merge(a, d, BfRule::kNorm), nb = bf_merge(b, d, rule);
  if (na != nb) return true;
  const auto ta = bf_top(a, M), tb = bf_top(b, M);
  if (ta.size() != tb.size()) return true;
  for (std::size_t i = 0; i < ta.size(); ++i)
    if (ta[i].key != tb[i].key || ta[i].parent != tb[i].parent || std::abs(ta[i].logw - tb[i].logw) > 1e-9 ||
        ta[i].point != tb[i].point)
      return true;
  return false;
}

/// The reordered RBPF's step k >= 2 from f's current particles, by brute force (Table V): every child
/// (parent p, situation s) with its eq. (32) weight log w_p + log P(s | s_p) + log p(o | s), the
/// transition taken at the parent's mean (speeds of eq. 10); the greedy merge on the parents' predicted
/// means F x_p (eq. 29 with `rule`); the M heaviest; then each kept child's UKF update (the Ukf filter
/// from the parent's belief) and eq. (33)'s weights, normalised. Kept children come back with their
/// updated means as points; `absorbed` is the merge's count.
template <class Motion>
std::vector<BfChild> bf_reordered_step(const Rbpf<Motion>& f, const si::SightProcess& proc,
                                       const si::QualityModel& q, const VecX& y, const VecX& o, long k,
                                       double d, BfRule rule, int& absorbed,
                                       std::vector<BfChild>* all_children = nullptr) {
  const int B = f.num_anchors(), nz = f.num_conditions();
  const auto& L = f.measurements().layout();
  std::uint64_t per = 1;
  for (int b = 0; b < B; ++b) per *= static_cast<std::uint64_t>(nz);
  std::vector<BfChild> children;
  VecX speeds = VecX::Zero(B);
  VecXi s(B);
  for (int p = 0; p < f.num_particles(); ++p) {
    const auto& x = f.particle_mean(p);
    if (proc.speed_dependent())
      si::transversal_speeds(x.segment(L.position, L.space_dim), x.segment(L.velocity, L.space_dim),
                             f.measurements().anchors(), speeds);
    const VecX xp = f.motion().F() * x;
    const VecXi from = f.particle_situation(p);
    for (std::uint64_t key = 0; key < per; ++key) {
      decode_situation(key, nz, s);
      const double lw = f.log_weight(p) + proc.log_transition(from, s, k, speeds) + q.log_likelihood(o, s);
      children.push_back({key, lw, xp, p});
    }
  }
  if (all_children) *all_children = children;
  absorbed = bf_merge(children, d, rule);
  std::vector<BfChild> kept = bf_top(children, f.options().num_particles);
  for (BfChild& c : kept) {
    const auto pp = c.parent;
    Ukf<Motion, MeasurementStack> u(f.motion(), f.measurements(), {f.particle_mean(pp), f.particle_cov(pp)},
                                    f.options().scheme, f.time());
    decode_situation(c.key, nz, s);
    c.logw += u.step(y, s).log_likelihood;  // eq. (33)
    c.point = u.mean();
  }
  bf_normalise(kept);
  return kept;
}

/// f's particles are `want`'s children: each matched by situation and updated mean (to rel. 1e-6), with
/// its log weight to 1e-6 (the scaled UT's summation order shows at 1e-7, as above).
template <class Motion>
void check_particles_are(const Rbpf<Motion>& f, const std::vector<BfChild>& want) {
  REQUIRE(f.num_particles() == static_cast<int>(want.size()));
  std::vector<char> used(want.size(), 0);
  for (int i = 0; i < f.num_particles(); ++i) {
    const std::uint64_t key = encode_situation(f.particle_situation(i), f.num_conditions());
    const VecX x = f.particle_mean(i);
    std::size_t j = 0;
    for (; j < want.size(); ++j)
      if (!used[j] && want[j].key == key &&
          ((want[j].point - x).array().abs() <= 1e-6 * (1.0 + x.array().abs())).all())
        break;
    INFO("particle " << i << " key " << key);
    REQUIRE(j < want.size());
    used[j] = 1;
    CHECK_THAT(f.log_weight(i), WithinAbs(want[j].logw, 1e-6));
  }
}
}  // namespace

TEST_CASE("classical RBPF merge equals a brute-force greedy merge of its children (eqs. 29-30)",
          "[rbpf][merge]") {
  // A twin without merge and M = 16 keeps all 16 children of step 2 (4 parents x N_z^B = 4): their exact
  // updated means and normalised weights. The merging filter (M = 6, so it also prunes) must keep the
  // children of the plain greedy merge of merge.hpp on them with ||x_a - x_b|| < d_min, in decreasing
  // weight, with the same weights, and report as many absorbed. Each threshold is one where a plausible
  // slip in the distance gives another result (checked first, so the case cannot pass vacuously): the
  // squared norm (pairs between sqrt(2) and 2 m), the position only (a pair 6.54 m apart in position,
  // 6.62 m in the whole state), <= for < (a pair exactly d_min apart).
  const Tiny tc;
  RbpfOptions ro;
  ro.variant = RbpfVariant::kClassical;
  ro.num_particles = 16;
  ro.merge = false;
  Rbpf<ConstantVelocity2> ref(tc.motion, tc.st, tc.proc, tc.q, tc.g, ro);
  ref.step(tc.ys[0], tc.os[0]);
  ref.step(tc.ys[1], tc.os[1]);
  REQUIRE(ref.num_particles() == 16);
  std::vector<BfChild> children;
  for (int i = 0; i < 16; ++i)
    children.push_back(
        {encode_situation(ref.particle_situation(i), 2), ref.log_weight(i), VecX(ref.particle_mean(i)), -1});
  // the heaviest child and the next heaviest of its situation (particles come heaviest first)
  std::size_t second = 1;
  while (children[second].key != children[0].key) ++second;
  const double d_exact = (children[0].point - children[second].point).norm();
  struct Case {
    double d;
    BfRule mutant;
  };
  const int M = 6;
  for (const Case c : {Case{2.0, BfRule::kSquaredNorm}, Case{6.58, BfRule::kLeadOnly},
                       Case{d_exact, BfRule::kNormOrEqual}}) {
    CAPTURE(c.d, static_cast<int>(c.mutant));
    REQUIRE(bf_rule_matters(children, c.d, c.mutant, M));
    std::vector<BfChild> merged = children;
    const int absorbed = bf_merge(merged, c.d, BfRule::kNorm);
    std::vector<BfChild> kept = bf_top(merged, M);
    bf_normalise(kept);
    RbpfOptions opt = ro;
    opt.merge = true;
    opt.merge_threshold = c.d;
    opt.num_particles = M;
    Rbpf<ConstantVelocity2> f(tc.motion, tc.st, tc.proc, tc.q, tc.g, opt);
    CHECK(f.step(tc.ys[0], tc.os[0]).merged == 0);  // one parent: its children's situations all differ
    const RbpfStepInfo info = f.step(tc.ys[1], tc.os[1]);
    CHECK(info.merge_threshold == c.d);
    CHECK(info.merged == absorbed);
    REQUIRE(f.num_particles() == static_cast<int>(kept.size()));
    for (int i = 0; i < f.num_particles(); ++i) {
      const auto u = static_cast<std::size_t>(i);
      CHECK(encode_situation(f.particle_situation(i), 2) == kept[u].key);
      CHECK(VecX(f.particle_mean(i)) == kept[u].point);  // the absorbing child keeps its own mean (eq. 30)
      CHECK_THAT(f.log_weight(i), WithinAbs(kept[u].logw, 1e-12));
    }
    // eq. (28) over every child after the merge (before the prune)
    Vec<4> est = Vec<4>::Zero();
    for (const BfChild& ch : merged)
      if (ch.logw > kNegInf) est += std::exp(ch.logw) * ch.point;
    CHECK((f.estimate() - est).cwiseAbs().maxCoeff() < 1e-9);
  }
}

TEST_CASE("reordered RBPF merge equals a brute-force greedy merge of the predicted children (eqs. 29-33)",
          "[rbpf][merge]") {
  // Table V: the children (parent, situation) are merged on their eq. (32) weights and their parents'
  // predicted means F x_p, the M = 6 heaviest kept, then updated. Each step's particles must be the
  // brute force's (bf_reordered_step), and the absorbed count its count. Thresholds as in the classical
  // case: 3 m (parents 2.44 m apart merge, none under the squared norm), 3.4696 m (parents 3.4693 m apart
  // in position but 3.4699 m in the whole state), and the exact distance of a pair of parents (<= for <).
  const Tiny tc;
  RbpfOptions opt;
  opt.variant = RbpfVariant::kReordered;
  opt.num_particles = 6;
  Rbpf<ConstantVelocity2> first(tc.motion, tc.st, tc.proc, tc.q, tc.g, opt);
  first.step(tc.ys[0], tc.os[0]);  // one parent: no merge; the 4 children are step 2's parents
  REQUIRE(first.num_particles() == 4);
  // a pair of parents whose squared distance s has sqrt(s)^2 == s: d_min = sqrt(s) is then exactly their
  // distance both ways (||.|| < d and ||.||^2 < d^2 agree)
  double d_exact = -1.0;
  for (int a = 0; a < 4 && d_exact < 0.0; ++a)
    for (int b = a + 1; b < 4 && d_exact < 0.0; ++b) {
      const Vec<4> xa = tc.motion.F() * first.particle_mean(a), xb = tc.motion.F() * first.particle_mean(b);
      const double s = (xa - xb).squaredNorm(), r = std::sqrt(s);
      if (r * r == s) d_exact = r;
    }
  REQUIRE(d_exact > 0.0);
  struct Case {
    double d;
    BfRule mutant;
  };
  for (const Case c : {Case{3.0, BfRule::kSquaredNorm}, Case{3.4696, BfRule::kLeadOnly},
                       Case{d_exact, BfRule::kNormOrEqual}}) {
    CAPTURE(c.d, static_cast<int>(c.mutant));
    opt.merge_threshold = c.d;
    Rbpf<ConstantVelocity2> f(tc.motion, tc.st, tc.proc, tc.q, tc.g, opt);
    f.step(tc.ys[0], tc.os[0]);
    int total = 0;
    for (long k = 2; k <= 3; ++k) {
      const auto u = static_cast<std::size_t>(k - 1);
      int absorbed = 0;
      std::vector<BfChild> all;
      const std::vector<BfChild> want =
          bf_reordered_step(f, tc.proc, tc.q, tc.ys[u], tc.os[u], k, c.d, BfRule::kNorm, absorbed, &all);
      if (k == 2) REQUIRE(bf_rule_matters(all, c.d, c.mutant, opt.num_particles));
      const RbpfStepInfo info = f.step(tc.ys[u], tc.os[u]);
      CHECK(info.merge_threshold == c.d);
      CHECK(info.merged == absorbed);
      check_particles_are(f, want);
      total += absorbed;
    }
    CHECK(total > 0);
  }
}

TEST_CASE("reordered RBPF on an H2-like track: every step's merge at eq. 31's d_min equals the brute force",
          "[rbpf][merge]") {
  // M = 64 parents (the sweep's grid holds several cells), 64 situations each, speed-dependent sight;
  // d_min of eq. (31) from the last mixture covariance, below 1 m, so the squared norm would merge pairs
  // between d_min and sqrt(d_min) (counted: the run must contain such steps). 1 and 2 threads (the merge
  // then splits the keys over the threads).
  const H2Like h;
  std::vector<VecX> y, o;
  std::vector<Vec<6>> truth;
  h.simulate(25, 7, y, o, truth);
  for (const int threads : {1, 2}) {
    CAPTURE(threads);
    RbpfOptions opt;
    opt.num_particles = 64;
    opt.threads = threads;
    Rbpf<ConstantVelocityClock2> f(h.motion, h.st, h.proc, h.q, h.g, opt);
    f.step(y[0], o[0]);
    int total = 0, telling = 0;
    const auto& L = h.st.layout();
    for (std::size_t u = 1; u < y.size(); ++u) {
      const long k = static_cast<long>(u) + 1;
      const double d = f.covariance().diagonal().segment(L.position, L.space_dim).sum() / (10.0 * 64);
      int absorbed = 0;
      std::vector<BfChild> all;
      const std::vector<BfChild> want =
          bf_reordered_step(f, h.proc, h.q, y[u], o[u], k, d, BfRule::kNorm, absorbed, &all);
      telling += bf_rule_matters(all, d, BfRule::kSquaredNorm, 64) ? 1 : 0;
      const RbpfStepInfo info = f.step(y[u], o[u]);
      CHECK_THAT(info.merge_threshold, WithinRel(d, 1e-14));  // eq. (31)
      CHECK(info.merged == absorbed);
      check_particles_are(f, want);
      total += absorbed;
    }
    CHECK(total > 0);
    CHECK(telling > 0);
  }
}
#endif  // NLOSLOC_NATIVE_TESTS
