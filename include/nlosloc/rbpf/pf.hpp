#pragma once
/// \file pf.hpp
/// Joint particle filter over (x, s), the "PF" of Huerta et al. 2009 Sec. VI-B: bootstrap proposal (x from
/// the motion model, eq. 4; s from the sight chains, eqs. 9, 15-18), weights by the exact measurement noise
/// densities p(y | x, s) (Table VIII/X, non-Gaussian allowed) times the quality likelihood p(o | s), then
/// either systematic resampling (when the effective sample size falls below a threshold) or the paper's
/// merge-and-select adapted to sampled particles.
///
/// Layout: structure of arrays (state component d of particle i at x[d * M + i], anchor b's condition at
/// s[b * M + i]), double buffers (the pass writes the moved states to the second one), all allocated at
/// construction: step() does not allocate (the optional merge groups in preallocated buffers). A
/// resampling only writes the ancestors; the next pass gathers them block by block (one pass over the
/// states less per step; particles() and situations() read through them meanwhile).
///
/// Speed (issue #3): one pass over the particles per step, in blocks on the thread pool, with bulk random
/// numbers (BatchRng), a square-root- and division-free sight switching test, SIMD packets (Eigen's
/// packet functions) for ranges, log densities, log and exp, and the weighted mean, covariance, situation
/// probabilities and ESS accumulated in the same pass; the normalisation of the log weights is deferred to
/// the next pass.
/// In a portable x86-64 build the pass also has an AVX2 build, chosen at run time (see detail::P4): the
/// same result bit for bit, 1.2x to 1.3x faster at 1e6 particles on H2 (BM_Pf).
///
/// Merge-select for sampled particles (the paper applies the RBPF's rule, eqs. 29-30, to its 1e6-particle
/// PF without details): particles are bucketed by situation vector and by the cell floor(x / w) of a state
/// grid (w: the last step's d_min, so the weighting pass computes the keys while the states are in cache),
/// and inside a bucket the greedy merge of merge.hpp moves weight from lighter to heavier particles within
/// this step's d_min (pairs split by a cell boundary are not merged: a documented approximation that keeps
/// the cost linear); the merged set is then brought back to M particles by systematic resampling.
///
/// Row types: every row whose noise is one distribution selected by its own anchor (TOA, RTOA, AOA, AOA
/// phase, linear). TDOA (difference of two noises) and two-way ranging rows are rejected: their densities
/// have no closed form here.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/core/logsumexp.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/filters/common.hpp"
#include "nlosloc/models/measurement.hpp"
#include "nlosloc/rbpf/merge.hpp"
#include "nlosloc/rbpf/offspring.hpp"
#include "nlosloc/rbpf/snapshot_check.hpp"
#include "nlosloc/rbpf/thread_pool.hpp"
#include "nlosloc/situation/forward.hpp"
#include "nlosloc/situation/markov.hpp"
#include "nlosloc/situation/quality.hpp"

namespace nlosloc::rbpf {

/// Selection step of the joint PF.
enum class PfResampling {
  kSystematic = 0,  ///< systematic resampling when ESS < ess_threshold * M
  kMergeSelect = 1  ///< merge (eqs. 29-30, bucketed) then systematic resampling back to M, every step
};

/// Settings of ParticleFilter.
struct PfOptions {
  int num_particles = 10000;  ///< M >= 1
  PfResampling resampling = PfResampling::kSystematic;
  double ess_threshold = 0.5;     ///< in [0, 1]; 1 resamples every step, 0 never
  double merge_threshold = -1.0;  ///< d_min of kMergeSelect; negative: eq. (31) from the position variance
  int threads = 1;                ///< threads (pool created once); results depend on the thread count
  std::uint64_t seed = 0;         ///< seed of the per-thread generators (stream = thread index)
};

/// What one PF step reports.
struct PfStepInfo {
  double log_likelihood = 0.0;  ///< log mean of the incremental weights: estimate of log p(y_t, o_t | past)
  double ess = 0.0;             ///< effective sample size after weighting, before resampling
  bool resampled = false;
  int merged = 0;
};

/// What a ParticleFilter carries from one step to the next (ParticleFilter::save / restore): a checkpoint
/// of a long track, and what pickling stores from Python. M particles, B anchors, N_z conditions, n state
/// entries, T threads.
struct PfSnapshot {
  MatX particles;                  ///< n x M states (as particles())
  Eigen::MatrixXi situations;      ///< B x M condition indices, 0 .. N_z - 1 (0 = LOS; as situations())
  VecX log_weights;                ///< M normalised log weights (their log-sum-exp is 0)
  MatX situation_probabilities;    ///< B x N_z, rows summing to 1
  VecX estimate;                   ///< weighted mean after the last weighting
  MatX covariance;                 ///< weighted covariance after the last weighting (n x n, PSD)
  double position_variance = 0.0;  ///< its position variance as the step computed it (eq. 31's d_min)
  std::vector<std::uint64_t> generators;  ///< the T threads' random generators, kGeneratorWords each
  double time = 0.0;                      ///< (s)
  long step = 0;                          ///< steps since the reset
  /// Words per thread in `generators`: its Rng (resampling draws), then its BatchRng (the pass's draws).
  static constexpr int kGeneratorWords = Rng::kStateWords + BatchRng::kStateWords;
};

/// Chunk t of T of systematic resampling (Kitagawa 1996; Douc et al. 2005) over unnormalised weights w:
/// the chunk holds items [b, e) and its cumulative weight before b is c0, after it c1 (of `total`). The
/// pointers are (j + u0) total / M, j = 0..M-1, for one uniform u0 in (0, 1); this writes the ancestors
/// out[j] of the pointers that fall in the chunk's share (c0, c1] and returns their range [jb, je). The
/// chunks of a partition give exactly the pointers of one serial pass, each once. Unbiased:
/// E[copies of i] = M w_i / total.
template <class W>
std::pair<int, int> systematic_resample_chunk(const W& w, int b, int e, double c0, double c1, double total,
                                              int M, double u0, int t, int T, int* out) {
  const double scale = static_cast<double>(M) / total;
  // first pointer of a boundary at cumulative weight c: #{j : (j + u0) / scale <= c}; the outer
  // boundaries are exact (rounding must not lose or repeat a pointer)
  auto first = [&](double c, int tb) {
    if (tb == 0) return 0;
    if (tb == T) return M;
    const double f = std::floor(c * scale - u0) + 1.0;
    return static_cast<int>(std::min<double>(M, std::max(0.0, f)));
  };
  const int jb = first(c0, t), je = first(c1, t + 1);
  if (jb >= je || b >= e) return {jb, jb};
  int i = b;
  double c = c0 + w(i);
  for (int j = jb; j < je; ++j) {
    const double u = (static_cast<double>(j) + u0) / scale;
    while (u > c && i < e - 1) c += w(++i);
    out[j] = i;
  }
  return {jb, je};
}

/// Systematic resampling: writes M ancestor indices for normalised weights w (size n) using one uniform
/// u0 in (0, 1): the j-th pointer is (j + u0) / M. Unbiased: E[copies of i] = M w_i. (One chunk of
/// systematic_resample_chunk.)
template <class W>
void systematic_resample(const W& w, int n, int M, double u0, int* out) {
  systematic_resample_chunk(w, 0, n, 0.0, 1.0, 1.0, M, u0, 0, 1, out);
}

namespace detail {
/// SIMD packet of doubles of the build, Eigen's widest for the instruction set the translation unit is
/// compiled for: Packet2d with SSE2 (x86-64's baseline) or NEON, Packet4d with AVX, Packet8d with AVX-512
/// (-march=native on such a CPU: CMake option NLOSLOC_NATIVE), plain double when Eigen does not vectorise.
/// The joint PF's inner loops are written once on Eigen's packet functions and run on packets, with the
/// same template on double for the tails.
using PfPacket = Eigen::internal::packet_traits<double>::type;
inline constexpr int kPfLanes = static_cast<int>(sizeof(PfPacket) / sizeof(double));

#if defined(__GNUC__) || defined(__clang__)
/// Four doubles and four 64-bit integers as GCC/Clang vectors (P4, the vector bucket keys, exp4).
typedef double V4d __attribute__((vector_size(32)));
typedef std::int64_t V4i __attribute__((vector_size(32)));
#endif

// Run-time AVX2 in an x86-64 build without AVX (the portable default): where the CPU has AVX2, the PF's
// pass (move, weights, moments, bucket keys) runs in a function compiled for AVX2 (GCC/Clang target
// attribute), its weighting on 4-double packets (P4) with the same operations in the same order as on
// Eigen's Packet2d: exp by Eigen's algorithm on four lanes, log and sqrt on Packet2d halves, sums taken
// half by half in the 2-lane order. So a step's result is the same bit for bit on either path.
// NLOSLOC_NO_AVX2 (set and not "0") in the environment when a filter is built keeps it on the portable path.
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__) && defined(EIGEN_VECTORIZE_SSE2) && \
    !defined(EIGEN_VECTORIZE_AVX)
#define NLOSLOC_PF_AVX2_DISPATCH 1
/// Four doubles (a GCC/Clang vector: the compiler lowers its operations to the AVX2 function that inlines
/// them). Masks are its bit patterns, as Eigen's.
struct P4 {
  using V = V4d;
  using I = V4i;
  V v;
  P4() = default;
  explicit P4(const V& x) : v(x) {}
  // Not trivially copyable: returned through memory whatever the target (no AVX return ABI to warn about
  // with -Wpsabi in the default build); inlined into the AVX2 pass, it stays in registers.
  P4(const P4& o) : v(o.v) {}
  P4& operator=(const P4& o) {
    v = o.v;
    return *this;
  }
};
inline bool cpu_has_avx2() { return nlosloc::detail::cpu_has_avx2(); }
#define NLOSLOC_PF_INLINE __attribute__((always_inline)) inline
#define NLOSLOC_PF_LAMBDA_INLINE __attribute__((always_inline))
#else
struct P4 {};  // no run-time dispatch in this build
inline bool cpu_has_avx2() { return false; }
#define NLOSLOC_PF_INLINE inline
#define NLOSLOC_PF_LAMBDA_INLINE
#endif
template <class P>
inline constexpr bool kIsP4 = std::is_same_v<P, P4>;
/// Generic lambdas take a null P* for their packet type P (no packet by value: see -Wpsabi, and no class
/// template of Eigen's attributed packet types: -Wignored-attributes).
template <class P>
P packet_of(P*);  // declared only: decltype(packet_of(tag)) is the packet type of a tag (P*)nullptr

/// floor(q) as a cell number, without a libm call; |q| beyond 2^62 (a cell far outside any track) and NaN
/// are clamped, which only merges buckets (the merge's distance test decides).
inline std::uint64_t pf_cell_index(double q) {
  constexpr double kMax = 4.611686018427387904e18;  // 2^62
  if (!(q < kMax)) q = kMax;
  if (!(q > -kMax)) q = -kMax;
  auto f = static_cast<std::int64_t>(q);  // truncation toward zero
  f -= static_cast<std::int64_t>(q < static_cast<double>(f));
  return static_cast<std::uint64_t>(f);
}

inline constexpr std::uint64_t kPfKeyMul[8] = {
    0x9E3779B97F4A7C15ULL, 0xC2B2AE3D27D4EB4FULL, 0x165667B19E3779F9ULL, 0xD6E8FEB86659FD93ULL,
    0xFF51AFD7ED558CCDULL, 0xC4CEB9FE1A85EC53ULL, 0x94D049BB133111EBULL, 0xBF58476D1CE4E5B9ULL};

/// Bucket key of particle j of a block: a hash of its situation vector (s[b * ss + j], b < B) and of the grid
/// cell floor(x / w) of its state (x[e * xs + j], e < N; inv_cell = 1 / w), folded to 32 bits, with
/// independent products (no serial multiply chain). A collision only puts two buckets in one group: the
/// merge still checks eq. (29).
template <int N>
std::uint32_t pf_bucket_key(const std::uint8_t* s, std::size_t ss, int B, const double* x, std::size_t xs,
                            double inv_cell, int j) {
  std::uint64_t sv = 0;
  for (int b = 0; b < B; ++b)
    sv = sv * 257 + s[static_cast<std::size_t>(b) * ss + static_cast<std::size_t>(j)];
  std::uint64_t h = (sv + 1) * kPfKeyMul[7];
  for (int e = 0; e < N; ++e)
    h ^= pf_cell_index(x[static_cast<std::size_t>(e) * xs + static_cast<std::size_t>(j)] * inv_cell) *
         kPfKeyMul[e % 7];
  h ^= h >> 31;
  h *= kPfKeyMul[0];
  return static_cast<std::uint32_t>(h >> 32);
}

#if defined(__GNUC__) || defined(__clang__)
inline constexpr double kRoundMagic = 6755399441055744.0;  // 1.5 * 2^52: q + it rounds q to an integer
/// f = floor(q) on each lane with |q| < 2^51: rounded through 1.5 * 2^52, less 1 where that went up (no
/// libm call, no conversion). Results by reference: no AVX vector returned by value (-Wpsabi).
NLOSLOC_PF_INLINE void floor4(const V4d& q, V4d& f) {
  const V4d magic = {kRoundMagic, kRoundMagic, kRoundMagic, kRoundMagic}, one = {1.0, 1.0, 1.0, 1.0};
  const V4d r = (q + magic) - magic;
  f = r - (V4d)((V4i)(r > q) & (V4i)one);
}
/// i = the integers of integral lanes r (|r| < 2^51), from the bits of r + 1.5 * 2^52 (two's complement).
NLOSLOC_PF_INLINE void int4(const V4d& r, V4i& i) {
  const V4d magic = {kRoundMagic, kRoundMagic, kRoundMagic, kRoundMagic}, rm = r + magic;
  V4i magic_bits;
  std::memcpy(&i, &rm, sizeof i);
  std::memcpy(&magic_bits, &magic, sizeof magic_bits);
  i -= magic_bits;
}
#endif

/// pf_bucket_key of particles 0..n-1 into out, four at a time on vectors (the same keys, bit for bit): the
/// floor by rounding through 1.5 * 2^52 and its integer read from the bits, where every |x / w| of the four
/// is below 2^51 (else, and for the tail, pf_bucket_key).
template <int N>
NLOSLOC_PF_INLINE void pf_bucket_keys(const std::uint8_t* s, std::size_t ss, int B, const double* x,
                                      std::size_t xs, double inv_cell, int n, std::uint32_t* out) {
#if defined(__GNUC__) || defined(__clang__)
  typedef std::uint64_t U __attribute__((vector_size(32)));
  constexpr double kLimit = 2251799813685248.0;  // 2^51
  const V4d lim = {kLimit, kLimit, kLimit, kLimit}, inv = {inv_cell, inv_cell, inv_cell, inv_cell};
  int j = 0;
  for (; j + 4 <= n; j += 4) {
    U sv = {0, 0, 0, 0};
    for (int b = 0; b < B; ++b) {
      const std::uint8_t* sb = s + static_cast<std::size_t>(b) * ss + static_cast<std::size_t>(j);
      const U v = {sb[0], sb[1], sb[2], sb[3]};
      sv = (sv << 8) + sv + v;  // sv * 257 + s_b
    }
    U h = (sv + 1) * kPfKeyMul[7];
    V4i inside = {-1, -1, -1, -1};
    for (int e = 0; e < N; ++e) {
      V4d q;
      std::memcpy(&q, x + static_cast<std::size_t>(e) * xs + static_cast<std::size_t>(j), sizeof q);
      q *= inv;
      inside &= (q < lim) & (q > -lim);  // false for NaN
      V4d fq;
      V4i f;
      floor4(q, fq);
      int4(fq, f);
      h ^= (U)f * kPfKeyMul[e % 7];  // the integer floor(q), two's complement
    }
    h ^= h >> 31;
    h *= kPfKeyMul[0];
    if ((inside[0] & inside[1] & inside[2] & inside[3]) != 0) {
      for (int l = 0; l < 4; ++l) out[j + l] = static_cast<std::uint32_t>(h[l] >> 32);
    } else {
      for (int l = 0; l < 4; ++l) out[j + l] = pf_bucket_key<N>(s, ss, B, x, xs, inv_cell, j + l);
    }
  }
#else
  int j = 0;
#endif
  for (; j < n; ++j) out[j] = pf_bucket_key<N>(s, ss, B, x, xs, inv_cell, j);
}

/// The packet operations of the weighting loop on Eigen's packets and doubles (Eigen's functions) and on P4
/// (vector operators, with Eigen's operation and operand order: pmax(a, b) is b where b > a, else a).
namespace pk {
namespace ei = Eigen::internal;
#ifdef NLOSLOC_PF_AVX2_DISPATCH
NLOSLOC_PF_INLINE PfPacket lo(const P4& a) { return PfPacket{a.v[0], a.v[1]}; }
NLOSLOC_PF_INLINE PfPacket hi(const P4& a) { return PfPacket{a.v[2], a.v[3]}; }
NLOSLOC_PF_INLINE P4 join(const PfPacket& l, const PfPacket& h) { return P4(P4::V{l[0], l[1], h[0], h[1]}); }
#endif
template <class P>
NLOSLOC_PF_INLINE P load(const double* p) {
  if constexpr (kIsP4<P>) {
    P r;
    std::memcpy(&r.v, p, sizeof r.v);
    return r;
  } else {
    return ei::ploadu<P>(p);
  }
}
template <class P>
NLOSLOC_PF_INLINE void store(double* p, const P& a) {
  if constexpr (kIsP4<P>)
    std::memcpy(p, &a.v, sizeof a.v);
  else
    ei::pstoreu(p, a);
}
template <class P>
NLOSLOC_PF_INLINE P set1(double v) {
  if constexpr (kIsP4<P>)
    return P{typename P::V{v, v, v, v}};
  else
    return ei::pset1<P>(v);
}
template <class P>
NLOSLOC_PF_INLINE P add(const P& a, const P& b) {
  if constexpr (kIsP4<P>)
    return P{a.v + b.v};
  else
    return ei::padd(a, b);
}
template <class P>
NLOSLOC_PF_INLINE P sub(const P& a, const P& b) {
  if constexpr (kIsP4<P>)
    return P{a.v - b.v};
  else
    return ei::psub(a, b);
}
template <class P>
NLOSLOC_PF_INLINE P mul(const P& a, const P& b) {
  if constexpr (kIsP4<P>)
    return P{a.v * b.v};
  else
    return ei::pmul(a, b);
}
template <class P>
NLOSLOC_PF_INLINE P lt(const P& a, const P& b) {  // a < b: all ones where true (false for NaN)
  if constexpr (kIsP4<P>)
    return P{(typename P::V)(a.v < b.v)};
  else
    return ei::pcmp_lt(a, b);
}
template <class P>
NLOSLOC_PF_INLINE P select(const P& m, const P& a, const P& b) {  // a where the mask m is set, else b
  if constexpr (kIsP4<P>) {
    using I = typename P::I;
    const I mi = (I)m.v;
    return P{(typename P::V)((mi & (I)a.v) | (~mi & (I)b.v))};
  } else {
    return ei::pselect(m, a, b);
  }
}
template <class P>
NLOSLOC_PF_INLINE P max(const P& a, const P& b) {
  if constexpr (kIsP4<P>)
    return select(lt(a, b), b, a);
  else
    return ei::pmax(a, b);
}
#ifdef NLOSLOC_PF_AVX2_DISPATCH
#define NLOSLOC_PF_HALVES(fn, a) join(fn(lo(a)), fn(hi(a)))
#else
#define NLOSLOC_PF_HALVES(fn, a) a
#endif
template <class P>
NLOSLOC_PF_INLINE P sqrt(const P& a) {
  if constexpr (kIsP4<P>)
    return NLOSLOC_PF_HALVES(ei::psqrt, a);
  else
    return ei::psqrt(a);
}
template <class P>
NLOSLOC_PF_INLINE P log(const P& a) {
  if constexpr (kIsP4<P>)
    return NLOSLOC_PF_HALVES(ei::plog, a);
  else
    return ei::plog(a);
}
#ifdef NLOSLOC_PF_AVX2_DISPATCH
/// Eigen 3.4's pexp_double as it runs on SSE2's Packet2d (its pmin, pmax and pmadd = add(mul), pfloor
/// through rounding), on four lanes: the same result bit for bit wherever the result is a normal number
/// (a > -708: its ldexp is then exact both ways). The cephes constants are Eigen's.
NLOSLOC_PF_INLINE P4 exp4(const P4& a) {
  using V = P4::V;
  using I = P4::I;
#define NLOSLOC_PF_C4(x) (V{(x), (x), (x), (x)})
#define NLOSLOC_PF_SEL(m, x, y) ((V)(((m) & (I)(x)) | (~(m) & (I)(y))))
  const V hi = NLOSLOC_PF_C4(709.784), lo = NLOSLOC_PF_C4(-709.784);
  V x = NLOSLOC_PF_SEL(hi < a.v, hi, a.v);  // pmin(x, hi)
  x = NLOSLOC_PF_SEL(lo > x, lo, x);        // pmax(., lo)
  // floor(x log2(e) + 1/2) (|.| < 1100)
  V fx;
  floor4(NLOSLOC_PF_C4(1.4426950408889634073599) * x + NLOSLOC_PF_C4(0.5), fx);
  x = x - fx * NLOSLOC_PF_C4(0.693145751953125);
  x = x - fx * NLOSLOC_PF_C4(1.42860682030941723212e-6);
  const V x2 = x * x;
  V px = NLOSLOC_PF_C4(1.26177193074810590878e-4);
  px = px * x2 + NLOSLOC_PF_C4(3.02994407707441961300e-2);
  px = px * x2 + NLOSLOC_PF_C4(9.99999999999999999910e-1);
  px = px * x;
  V qx = NLOSLOC_PF_C4(3.00198505138664455042e-6);
  qx = qx * x2 + NLOSLOC_PF_C4(2.52448340349684104192e-3);
  qx = qx * x2 + NLOSLOC_PF_C4(2.27265548208155028766e-1);
  qx = qx * x2 + NLOSLOC_PF_C4(2.00000000000000000009e0);
  x = px / (qx - px);
  x = NLOSLOC_PF_C4(2.0) * x + NLOSLOC_PF_C4(1.0);
  // x * 2^fx: fx's integer, biased and shifted into an exponent field
  I e;
  int4(fx, e);
  e = (e + 1023) << 52;
  V scale;
  std::memcpy(&scale, &e, sizeof scale);
  const V y = x * scale;
  const I keep = a.v > y;
  return P4(NLOSLOC_PF_SEL(keep, a.v, y));  // pmax(y, a)
#undef NLOSLOC_PF_SEL
#undef NLOSLOC_PF_C4
}
#endif
template <class P>
NLOSLOC_PF_INLINE P exp(const P& a) {  // for P4: exact as Eigen's where the result is normal (see exp4)
  if constexpr (kIsP4<P>)
    return exp4(a);
  else
    return ei::pexp(a);
}
#undef NLOSLOC_PF_HALVES
/// s += v for a sum kept in a 2-lane packet (or a double): a P4 adds its halves in turn, as two packets.
template <class S, class P>
NLOSLOC_PF_INLINE void accumulate(S& s, const P& v) {
  if constexpr (kIsP4<P>)
    s = ei::padd(ei::padd(s, lo(v)), hi(v));
  else
    s = ei::padd(s, v);
}
/// the running maximum of a 2-lane packet (or a double) over v
template <class S, class P>
NLOSLOC_PF_INLINE void max_into(S& s, const P& v) {
  if constexpr (kIsP4<P>)
    s = ei::pmax(ei::pmax(s, lo(v)), hi(v));
  else
    s = ei::pmax(s, v);
}
}  // namespace pk
/// Whether a filter built now uses the AVX2 pass (the build dispatches, the CPU has AVX2, NLOSLOC_NO_AVX2
/// is unset or "0").
inline bool pf_avx2_enabled() {
  if (!cpu_has_avx2()) return false;
  const char* e = std::getenv("NLOSLOC_NO_AVX2");
  return e == nullptr || e[0] == '\0' || (e[0] == '0' && e[1] == '\0');
}
}  // namespace detail

/// Doubles per SIMD packet in ParticleFilter's inner loops for this build (2 on x86-64 without -march
/// flags; 8 with AVX-512). Compile-time: it describes the translation unit that calls it. A portable x86-64
/// build still runs the pass for AVX2 on a CPU that has it (ParticleFilter::uses_avx2()).
constexpr int pf_simd_lanes() { return detail::kPfLanes; }

/// Bootstrap particle filter over (x, s).
///
/// Step structure (one pass over memory, in blocks of kBlock particles per thread): draw the block's
/// uniforms (one per anchor and particle) and normals (rank Q per particle) in bulk (BatchRng), move the
/// sight chains, move the states, weight, and accumulate the weighted moments with a running maximum of the
/// log weights (so the weights are exponentiated once, in the same pass). The normalisation of the log
/// weights is deferred to the next step's pass (log_weights() applies it on demand).
template <class Motion, class Meas = MeasurementStack>
class ParticleFilter {
 public:
  static constexpr int N = Motion::kDim;
  using State = Vec<N>;
  using Cov = Mat<N, N>;
  static constexpr int kBlock = 128;  ///< particles per block of the inner loops (multiple of 4)

  ParticleFilter(const Motion& motion, const Meas& meas, situation::SightProcess sight,
                 situation::QualityModel quality, const Gaussian<N>& initial, const PfOptions& options = {},
                 double t0 = 0.0)
      : motion_(motion),
        meas_(meas),
        sight_(std::move(sight)),
        quality_(std::move(quality)),
        opt_(options),
        pool_(std::make_unique<ThreadPool>(options.threads)) {
    ::nlosloc::detail::check_layout<N>(meas);
    meas.check_ready();
    NLOSLOC_ENSURE(options.num_particles >= 1, "options.num_particles: expected M >= 1");
    NLOSLOC_ENSURE(options.ess_threshold >= 0.0 && options.ess_threshold <= 1.0,
                   "options.ess_threshold: expected a value in [0, 1]");
    NLOSLOC_ENSURE(
        options.resampling == PfResampling::kSystematic || options.resampling == PfResampling::kMergeSelect,
        "options.resampling: unknown PfResampling");
    NLOSLOC_ENSURE(std::isfinite(options.merge_threshold),
                   "options.merge_threshold: expected a finite value");
    NLOSLOC_ENSURE(sight_.num_anchors() == meas.num_anchors(), "sight: expected one chain per anchor");
    NLOSLOC_ENSURE(sight_.num_conditions() == meas.num_conditions() &&
                       quality_.num_conditions() == meas.num_conditions(),
                   "sight, quality: expected as many conditions as the measurements");
    NLOSLOC_ENSURE(meas.num_conditions() <= 255, "measurements: at most 255 conditions");
    NLOSLOC_ENSURE(!sight_.speed_dependent() || meas.layout().velocity >= 0,
                   "sight: a speed-dependent chain needs a velocity in the state layout");
    for (int i = 0; i < meas.rows(); ++i) {
      const RowKind k = meas.row(i).kind;
      NLOSLOC_ENSURE(k != RowKind::kTdoa && k != RowKind::kTwrTau && k != RowKind::kTwrT,
                     "measurements: the joint PF supports TOA, RTOA, AOA and linear rows (row " +
                         std::to_string(i) + " is " + to_string(k) + ")");
    }
    M_ = options.num_particles;
    B_ = meas.num_anchors();
    nz_ = meas.num_conditions();
    const auto M = static_cast<std::size_t>(M_);
    x_.resize(M * N);
    nx_.resize(M * N);
    s_.resize(M * static_cast<std::size_t>(B_));
    ns_.resize(M * static_cast<std::size_t>(B_));
    logw_.resize(M_);
    nlogw_.resize(M_);
    w_.resize(M_);
    nw_.resize(M_);
    anc_.resize(M);
    // Square root of Q (PSD, possibly singular: Huerta eq. 6 has no position noise): Q = G G^T with only the
    // non-zero eigen-directions, so a step draws rank(Q) normals.
    Eigen::SelfAdjointEigenSolver<Cov> es(motion.Q());
    Eigen::Matrix<double, N, Eigen::Dynamic> G(N, 0);
    const double tol = 1e-14 * std::max(1.0, es.eigenvalues().cwiseAbs().maxCoeff());
    for (int j = 0; j < N; ++j)
      if (es.eigenvalues()(j) > tol) {
        G.conservativeResize(Eigen::NoChange, G.cols() + 1);
        G.col(G.cols() - 1) = es.eigenvectors().col(j) * std::sqrt(es.eigenvalues()(j));
      }
    G_ = G;
    nq_ = static_cast<int>(G_.cols());
    // x_t = F x_{t-1} + G n (eq. 4) as the non-zero entries of F and G, row by row (zeros skipped exactly).
    const auto& F = motion.F();
    for (int r = 0; r < N; ++r) {
      fbeg_[r] = static_cast<int>(fent_.size());
      for (int c = 0; c < N; ++c)
        if (F(r, c) != 0.0) fent_.push_back({c, F(r, c)});
      gbeg_[r] = static_cast<int>(gent_.size());
      for (int q = 0; q < nq_; ++q)
        if (G_(r, q) != 0.0) gent_.push_back({q, G_(r, q)});
    }
    fbeg_[N] = static_cast<int>(fent_.size());
    gbeg_[N] = static_cast<int>(gent_.size());
    for (int t = 0; t < pool_->size(); ++t) {
      rng_.emplace_back(options.seed, static_cast<std::uint64_t>(t));
      brng_.emplace_back(rng_.back());
      work_.emplace_back();
      ThreadWork& w = work_.back();
      w.u.resize(static_cast<std::size_t>(B_) * kBlock);
      w.z.resize(static_cast<std::size_t>(std::max(nq_, 1)) * kBlock);
      w.sd.resize(static_cast<std::size_t>(B_) * kBlock);
      w.xg.resize(static_cast<std::size_t>(N) * kBlock);
      w.sg.resize(static_cast<std::size_t>(B_) * kBlock);
      w.sb.resize(static_cast<std::size_t>(B_));
      w.bsc.resize(static_cast<std::size_t>(M / kBlock + 2));
      w.nbsc.resize(static_cast<std::size_t>(M / kBlock + 2));
      w.zrow = VecX::Zero(meas.rows());
      w.T.resize(nz_, nz_);
    }
    k2_ = kSp + B_ * nz_;
    stride_ = k2_ + meas.layout().space_dim;
    cparts_.resize(static_cast<std::size_t>(pool_->size() * kCovStride));
    for (ThreadWork& w : work_) {
      w.lw.resize(kBlock);
      w.pr.resize(kBlock);
      w.sacc.resize(static_cast<std::size_t>(stride_));
    }
    parts_.resize(static_cast<std::size_t>(pool_->size() * stride_));
    csum_.assign(static_cast<std::size_t>(pool_->size()), 0.0);
    cbeg_.assign(static_cast<std::size_t>(pool_->size()), 0);
    cend_.assign(static_cast<std::size_t>(pool_->size()), 0);
    // Rows whose every condition is Normal or Rayleigh get a closed-form log density: the logs of the
    // Rayleigh residuals are summed as the log of one product per particle (one log instead of one per row).
    fastlik_ = true;
    lik_.resize(static_cast<std::size_t>(meas.rows()) * static_cast<std::size_t>(nz_));
    for (int i = 0; i < meas.rows(); ++i)
      for (int z = 0; z < nz_; ++z) {
        const noise::Distribution& d = meas.noise(i, z);
        RowLik& l =
            lik_[static_cast<std::size_t>(i) * static_cast<std::size_t>(nz_) + static_cast<std::size_t>(z)];
        if (d.holds<noise::Normal>()) {
          const auto& n = d.get<noise::Normal>();
          l = {false, n.mean(), 0.5 / n.variance(), -0.5 * std::log(2.0 * kPi * n.variance())};
        } else if (d.holds<noise::Rayleigh>()) {
          const double s2 = d.get<noise::Rayleigh>().scale() * d.get<noise::Rayleigh>().scale();
          l = {true, 0.0, 0.5 / s2, -std::log(s2)};  // log(r / s^2) - r^2 / (2 s^2)
        } else {
          fastlik_ = false;
        }
      }
    // Vectorised weights: two conditions and range rows only (TOA/RTOA, Table I).
    fastrows_ = fastlik_ && nz_ == 2 && B_ <= 64;
    for (int i = 0; i < meas.rows(); ++i) {
      const RowKind k = meas.row(i).kind;
      fastrows_ = fastrows_ && (k == RowKind::kToa || k == RowKind::kRtoa) && meas.row(i).anchor >= 0;
    }
    rows_.resize(static_cast<std::size_t>(meas.rows()));
    lonely_.resize(static_cast<std::size_t>(B_));
    fast2d_ = meas.layout().space_dim == 2 && nz_ == 2 && meas.layout().velocity >= 0;
    for (int b = 0; b < B_; ++b) fast2d_ = fast2d_ && sight_.model(b).speed_dependent();
    if (fast2d_) setup_switch_tests();
    Lq_.resize(B_, nz_);
    cum_.resize(static_cast<std::size_t>(B_) * static_cast<std::size_t>(nz_ * nz_));
    T_.resize(nz_, nz_);
    prob_.resize(B_, nz_);
    y_.resize(meas.rows());
    if (options.resampling == PfResampling::kMergeSelect) {
      mws_.reserve(static_cast<std::size_t>(M), pool_->size());
      mkey_.resize(static_cast<std::size_t>(M));
    }
    reset(initial, t0);
  }

  /// Draws M particles: x ~ N(initial), s_b ~ the chains' priors; equal weights.
  void reset(const Gaussian<N>& initial, double t0 = 0.0) {
    initial.validate("initial");
    NLOSLOC_ENSURE(std::isfinite(t0), "t0: expected a finite time (s)");
    Cov L;
    double jit = 0.0;
    if (nlosloc::detail::factor_state_cov(initial.cov, L, &jit) == CholeskyStatus::kFailed)
      nlosloc::detail::throw_numerical_error("ParticleFilter.reset: initial.cov not positive definite");
    Rng& r = rng_[0];
    r.reseed(opt_.seed, 0);
    for (int i = 0; i < M_; ++i) {
      State u;
      for (int d = 0; d < N; ++d) u(d) = r.normal();
      const State x = initial.mean + L * u;
      for (int d = 0; d < N; ++d) x_[idx(d, i)] = x(d);
      for (int b = 0; b < B_; ++b)
        s_[sidx(b, i)] = static_cast<std::uint8_t>(sight_.model(b).sample_initial(r));
    }
    for (int t = 1; t < pool_->size(); ++t)
      rng_[static_cast<std::size_t>(t)].reseed(opt_.seed, static_cast<std::uint64_t>(t));
    // bulk generators: jumps of each thread's Rng (never overlap it: rng_[0] also draws the resampling u0)
    for (int t = 0; t < pool_->size(); ++t)
      brng_[static_cast<std::size_t>(t)] = BatchRng(rng_[static_cast<std::size_t>(t)]);
    logw_.setConstant(-std::log(static_cast<double>(M_)));
    shift_ = 0.0;
    resampled_ = false;
    t_ = t0;
    k_ = 0;
    summarise();
  }

  /// Everything the next step depends on: the particles (a pending resampling applied), their weights, the
  /// summaries, the random generators, time and step index. restore() of it into a filter built with the
  /// same models and options makes that filter step on exactly as this one, bit for bit.
  PfSnapshot save() const {
    PfSnapshot s;
    s.particles = particles();
    s.situations = situations();
    s.log_weights = log_weights();
    s.situation_probabilities = prob_;
    s.estimate = est_;
    s.covariance = covariance();
    s.position_variance = pos_var_;
    s.generators.resize(static_cast<std::size_t>(pool_->size()) * PfSnapshot::kGeneratorWords);
    for (int t = 0; t < pool_->size(); ++t) {
      std::uint64_t* g = &s.generators[static_cast<std::size_t>(t) * PfSnapshot::kGeneratorWords];
      rng_[static_cast<std::size_t>(t)].save_state(g);
      brng_[static_cast<std::size_t>(t)].save_state(g + Rng::kStateWords);
    }
    s.time = t_;
    s.step = k_;
    return s;
  }

  /// Sets the filter to a snapshot (save() of a filter with the same models and options, or one built by
  /// hand). Checked first, std::invalid_argument naming the field (the filter is then unchanged):
  /// particles n x M, finite; situations B x M in 0 .. N_z - 1; log weights M, finite or -inf, with a
  /// log-sum-exp within 1e-9 of 0; probabilities B x N_z in [0, 1] with rows summing to 1, both within
  /// 1e-9; a finite estimate; a symmetric positive semi-definite covariance; a finite position variance
  /// >= 0; generators of options().threads threads as save() writes them; a finite time; step >= 0.
  void restore(const PfSnapshot& s) {
    namespace nd = ::nlosloc::detail;
    nd::ensure_shape(s.particles, N, M_, "snapshot.particles");
    nd::ensure_finite(s.particles, "snapshot.particles");
    nd::ensure_shape(s.situations, B_, M_, "snapshot.situations");
    NLOSLOC_ENSURE(s.situations.minCoeff() >= 0 && s.situations.maxCoeff() < nz_,
                   "snapshot.situations: expected condition indices 0 to " + std::to_string(nz_ - 1));
    nd::ensure_shape(s.log_weights, M_, 1, "snapshot.log_weights");
    detail::check_snapshot_log_weights(s.log_weights);
    situation::check_probabilities(s.situation_probabilities, B_, nz_, "snapshot.situation_probabilities");
    nd::ensure_shape(s.estimate, N, 1, "snapshot.estimate");
    nd::ensure_finite(s.estimate, "snapshot.estimate");
    nd::ensure_shape(s.covariance, N, N, "snapshot.covariance");
    NLOSLOC_ENSURE(is_spsd(s.covariance),
                   "snapshot.covariance: expected a symmetric positive semi-definite matrix");
    NLOSLOC_ENSURE(std::isfinite(s.position_variance) && s.position_variance >= 0.0,
                   "snapshot.position_variance: expected a finite value >= 0");
    const auto T = static_cast<std::size_t>(pool_->size());
    NLOSLOC_ENSURE(s.generators.size() == T * PfSnapshot::kGeneratorWords,
                   "snapshot.generators: expected " + std::to_string(PfSnapshot::kGeneratorWords) +
                       " words for each of the filter's " + std::to_string(T) + " threads (" +
                       std::to_string(T * PfSnapshot::kGeneratorWords) + "), got " +
                       std::to_string(s.generators.size()));
    // Into copies first: a word no generator has leaves the filter unchanged.
    std::vector<Rng> rng = rng_;
    std::vector<BatchRng> brng = brng_;
    for (std::size_t t = 0; t < T; ++t) {
      const std::uint64_t* g = &s.generators[t * PfSnapshot::kGeneratorWords];
      NLOSLOC_ENSURE(
          rng[t].restore_state(g) && brng[t].restore_state(g + Rng::kStateWords),
          "snapshot.generators: thread " + std::to_string(t) +
              "'s words are no generator state (an all-zero state, or a flag or buffer position out "
              "of range)");
    }
    detail::check_snapshot_clock(s.time, s.step);
    for (int d = 0; d < N; ++d)
      for (int i = 0; i < M_; ++i) x_[idx(d, i)] = s.particles(d, i);
    for (int b = 0; b < B_; ++b)
      for (int i = 0; i < M_; ++i) s_[sidx(b, i)] = static_cast<std::uint8_t>(s.situations(b, i));
    logw_ = s.log_weights;
    shift_ = 0.0;
    resampled_ = false;
    rng_.swap(rng);
    brng_.swap(brng);
    prob_ = s.situation_probabilities;
    est_ = s.estimate;
    est_cov_ = s.covariance;
    cov_ready_ = true;
    pos_var_ = s.position_variance;
    t_ = s.time;
    k_ = s.step;
  }

  /// One step with measurements y (NaN = missing) and quality statistics o (size B, NaN = missing).
  PfStepInfo step(const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o) {
    situation::check_step_inputs(meas_, quality_, y, o, Lq_);
    y_ = y;
    const long k = k_ + 1;
    const double t = t_ + motion_.dt();
    const bool speed = sight_.speed_dependent();
    if (!speed) {
      // Fixed chains: cumulative transition rows per anchor for this step (eq. 16 schedule).
      for (int b = 0; b < B_; ++b) {
        sight_.model(b).transition(k, 0.0, T_);
        for (int m = 0; m < nz_; ++m) {
          double c = 0.0;
          for (int j = 0; j < nz_; ++j) cum_[cidx(b, m, j)] = (c += T_(m, j));
        }
      }
    }
    if (fastrows_) prepare_rows();
    centre_ = est_;
    if (opt_.resampling == PfResampling::kMergeSelect) {
      // Grid of the merge's buckets: eq. (31)'s d_min of the last weighted set (this step's is known only
      // after the pass that computes the keys; the merge itself tests this step's d_min)
      const double d =
          opt_.merge_threshold >= 0.0 ? opt_.merge_threshold : default_merge_threshold(pos_var_, M_);
      inv_cell_ = d > 0.0 && std::isfinite(1.0 / d) ? 1.0 / d : 0.0;
    }
    prior_shift_ = shift_;
    for (int th = 0; th < pool_->size();
         ++th)  // rows of threads with an empty chunk (M < threads) stay empty
      init_acc(&parts_[static_cast<std::size_t>(th * stride_)], 1);
    brng_back_ = brng_;  // the pass draws from the bulk generators only (same sizes: no allocation)
    std::fill(cbeg_.begin(), cbeg_.end(), 0);  // the pass records the threads' ranges (none: empty)
    std::fill(cend_.begin(), cend_.end(), 0);
    // The pass writes the moved states, situations and log weights into nx_, ns_, nlogw_: the particles
    // stay as they were until the step is accepted.
    try {
      pool_->parallel_for(M_, [&](int b0, int e0, int th) {
#ifdef NLOSLOC_PF_AVX2_DISPATCH
        if (avx2_) return propagate_weight_avx2(b0, e0, th, k, t, speed);
#endif
        propagate_weight<Packet>(b0, e0, th, k, t, speed);
      });
    } catch (...) {
      brng_ = brng_back_;  // a rejected step draws nothing: the filter is unchanged, generators included
      throw;
    }
    PfStepInfo info;
    // Incremental weights were added to the normalised log weights: their log-sum-exp is log p(y, o | past).
    const double z = reduce(info.ess);
    if (!std::isfinite(z)) {
      brng_ = brng_back_;
      nlosloc::detail::throw_numerical_error(
          "ParticleFilter.step: every particle has zero likelihood (the filter is unchanged)");
    }
    std::swap(x_, nx_);
    std::swap(s_, ns_);
    std::swap(logw_, nlogw_);
    if (fastrows_) {  // the pass's weights, by block (bsc: the blocks' maxima until resample() scales them)
      std::swap(w_, nw_);
      for (ThreadWork& w : work_) std::swap(w.bsc, w.nbsc);
    }
    resampled_ = false;  // the pass read the last resampling's ancestors
    info.log_likelihood = z;
    shift_ = z;  // logw_ - shift_ are the normalised log weights
    t_ = t;
    k_ = k;
    if (opt_.resampling == PfResampling::kMergeSelect) {
      // The merge compares and adds weights (eq. 30), so it works on the log weights as they are (the
      // normalisation is a shift); it keeps their sum, and resample divides by the actual sum.
      info.merged = merge_cells();
      resample(shift_, fastrows_ && info.merged == 0);
      info.resampled = true;
    } else if (info.ess < opt_.ess_threshold * static_cast<double>(M_)) {
      resample(shift_, fastrows_);
      info.resampled = true;
    }
    return info;
  }

  int num_particles() const { return M_; }
  /// Whether the pass runs its AVX2 build (a portable x86-64 build on a CPU with AVX2, NLOSLOC_NO_AVX2
  /// unset when the filter was built); either way a step's result is the same bit for bit.
  bool uses_avx2() const { return avx2_; }
  /// Weighted mean of the particles (after the last weighting).
  const State& estimate() const { return est_; }
  /// Weighted covariance of the particles after the last weighting (after the merge, in merge-select mode;
  /// before any resampling), computed on first request: one pass over the states.
  const Cov& covariance() const {
    if (!cov_ready_) compute_covariance();
    return est_cov_;
  }
  Gaussian<N> belief() const { return {est_, covariance()}; }
  /// P(s_b = z), B x N_z.
  const MatX& situation_probabilities() const { return prob_; }
  VecXi sight_estimate() const {
    VecXi s(B_);
    for (int b = 0; b < B_; ++b) prob_.row(b).maxCoeff(&s(b));
    return s;
  }
  /// Particle states as an N x M matrix (a copy), situations B x M, normalised log weights.
  MatX particles() const {
    MatX X(N, M_);
    for (int d = 0; d < N; ++d)
      for (int i = 0; i < M_; ++i) X(d, i) = x_[idx(d, ancestor(i))];
    return X;
  }
  Eigen::MatrixXi situations() const {
    Eigen::MatrixXi s(B_, M_);
    for (int b = 0; b < B_; ++b)
      for (int i = 0; i < M_; ++i) s(b, i) = s_[sidx(b, ancestor(i))];
    return s;
  }
  /// Normalised log weights (applies the deferred normalisation of the last step, O(M) once).
  const VecX& log_weights() const {
    normalise_log_weights();
    return logw_;
  }
  double time() const { return t_; }
  /// Steps taken since the last reset.
  long step_index() const { return k_; }
  const PfOptions& options() const { return opt_; }
  const Motion& motion() const { return motion_; }
  const Meas& measurements() const { return meas_; }
  /// The sight chains and quality likelihoods it was built with (what a copy of its set-up needs).
  const situation::SightProcess& sight_process() const { return sight_; }
  const situation::QualityModel& quality() const { return quality_; }
  /// Throws the std::invalid_argument step(y, o) would throw for these inputs, and changes nothing: checks
  /// a batch before its first step (the Python run() does).
  void check_inputs(const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o) const {
    situation::check_step_inputs(meas_, quality_, y, o);
  }

 private:
  using Packet = detail::PfPacket;
  static constexpr int kLanes = detail::kPfLanes;
  static constexpr int kRowLanes = kLanes > 4 ? kLanes : 4;  // a FastRow constant's copies
  static constexpr int kNT = N * (N + 1) / 2;

  struct Entry {
    int col;
    double v;
  };
  struct RowLik {
    bool rayleigh;
    double mu, inv2, c;
  };
  /// One observed range row of this step: noise parameters per condition, Lq folded into c.
  /// Constants are stored broadcast to a packet (k[c][lane]) so the inner loop loads them directly.
  struct FastRow {
    enum { kY, kMu0, kMu1, kInv0, kInv1, kC0, kC1, kRay0, kRay1, kQ0, kQ1, kQ2, kCount };
    int anchor, rtoa;
    // kRay*: all-ones bits when condition z is Rayleigh. Broadcast to the widest packet that reads them (P4
    // on the AVX2 pass).
    alignas(32) double k[kCount][kRowLanes];
    void set(int c, double v) {
      for (double& e : k[c]) e = v;
    }
  };
  /// Coefficients of the switching probability p = (w A + C) / (w S + P) per current condition (dt in A, S).
  struct SwitchCoef {
    double A[2], S[2], P[2], C[2];
  };
  struct ThreadWork {
    std::vector<double> u, z, sd;  // block buffers: uniforms (B x block), normals (rank Q x block), s as 0/1
    std::vector<double> lw, pr;    // block buffers of the fast weights: log density sums, Rayleigh products
    std::vector<double> sacc;      // accumulators of the scalar tails and the generic path
    std::vector<double> xg;        // the block's resampled states (N x block; load_block)
    std::vector<std::uint8_t> sg;  // the block's resampled situations (B x block)
    const double* xb[N] = {};      // the block's state rows: x_ itself, or xg after a resampling
    std::vector<const std::uint8_t*> sb;  // the block's situation rows
    std::vector<double> bsc;              // per block of the thread's range: scale of its weights in w_
    std::vector<double> nbsc;             // the pass's block maxima (swapped into bsc with nw_ into w_)
    int blk = 0;                          // block of the pass (index into bsc)
    VecX zrow;
    MatX T;
  };

  /// Particle i of the current set in x_ / s_: after a resampling its ancestor (the copy is deferred to the
  /// next pass, which gathers each block's ancestors: one pass over the states less per step).
  int ancestor(int i) const { return resampled_ ? anc_[static_cast<std::size_t>(i)] : i; }

  /// Points w.xb / w.sb at particles [i0, i0 + n) of the current set: rows of x_ / s_, or after a resampling
  /// their ancestors gathered into w.xg / w.sg (monotone indices: an almost sequential read).
  void load_block(int i0, int n, ThreadWork& w) const {
    if (!resampled_) {
      for (int d = 0; d < N; ++d) w.xb[d] = &x_[idx(d, i0)];
      for (int b = 0; b < B_; ++b) w.sb[static_cast<std::size_t>(b)] = &s_[sidx(b, i0)];
      return;
    }
    const int* a = &anc_[static_cast<std::size_t>(i0)];
    for (int d = 0; d < N; ++d) {
      double* o = &w.xg[static_cast<std::size_t>(d) * kBlock];
      const double* xd = &x_[idx(d, 0)];
      for (int j = 0; j < n; ++j) o[j] = xd[a[j]];
      w.xb[d] = o;
    }
    for (int b = 0; b < B_; ++b) {
      std::uint8_t* o = &w.sg[static_cast<std::size_t>(b) * kBlock];
      const std::uint8_t* sd = &s_[sidx(b, 0)];
      for (int j = 0; j < n; ++j) o[j] = sd[a[j]];
      w.sb[static_cast<std::size_t>(b)] = o;
    }
  }

  std::size_t idx(int d, int i) const {
    return static_cast<std::size_t>(d) * static_cast<std::size_t>(M_) + static_cast<std::size_t>(i);
  }
  std::size_t sidx(int b, int i) const {
    return static_cast<std::size_t>(b) * static_cast<std::size_t>(M_) + static_cast<std::size_t>(i);
  }
  std::size_t cidx(int b, int m, int j) const {
    return (static_cast<std::size_t>(b) * static_cast<std::size_t>(nz_) + static_cast<std::size_t>(m)) *
               static_cast<std::size_t>(nz_) +
           static_cast<std::size_t>(j);
  }

  /// Speed-dependent two-state chains in 2-D: the switching probability of Huerta eqs. (15), (17), (18) is
  /// (w A + C) / (w S + P) with w = |d x v| / |d| (eq. 10), so u < p is tested without a square root or a
  /// division as c^2 g|g| > h|h| d^2 (c = d x v, g = A - u S, h = u P - C; x|x| is increasing). As w <= |v|,
  /// p <= pbar(|v|) = max over [0, |v|] of (w A_max + C_max) / (w S_min + P_min) (a Moebius map: an end
  /// point), so a particle whose uniforms all exceed pbar keeps its conditions without the per-anchor test.
  void setup_switch_tests() {
    coef_.resize(static_cast<std::size_t>(B_));
    amax_ = cmax_ = 0.0;
    smin_ = pmin_ = std::numeric_limits<double>::infinity();
    for (int b = 0; b < B_; ++b) {
      const situation::SightModel& m = sight_.model(b);
      const double ll = m.mean_los(), ln = m.mean_nlos(), dt = m.dt();
      SwitchCoef& c = coef_[static_cast<std::size_t>(b)];
      for (int s = 0; s < 2; ++s) {
        const double cur = s == 0 ? ll : ln, other = s == 0 ? ln : ll;
        switch (m.form()) {
          case situation::SpeedModel::kSingle:  // eq. (15): a / (a + L_cur), a = w dt
            c.A[s] = dt, c.S[s] = dt, c.P[s] = cur, c.C[s] = 0.0;
            break;
          case situation::SpeedModel::kMemoryless:  // eq. (18): L_other / (L_L + L_N)
            c.A[s] = 0.0, c.S[s] = 0.0, c.P[s] = 1.0, c.C[s] = other / (ll + ln);
            break;
          default:  // eq. (17): a L_other / (a (L_L + L_N) + L_L L_N)
            c.A[s] = dt * other, c.S[s] = dt * (ll + ln), c.P[s] = ll * ln, c.C[s] = 0.0;
            break;
        }
        amax_ = std::max(amax_, c.A[s]);
        cmax_ = std::max(cmax_, c.C[s]);
        smin_ = std::min(smin_, c.S[s]);
        pmin_ = std::min(pmin_, c.P[s]);
      }
    }
  }

  /// Observed rows of this step with their parameters; log p(o_b | s) (quality) folded into the constant of
  /// anchor b's first observed row, or listed in lonely_ when anchor b has no observed row.
  void prepare_rows() {
    nrows_ = 0;
    nlonely_ = 0;
    std::fill(lonely_.begin(), lonely_.end(), 1);
    for (int r = 0; r < meas_.rows(); ++r) {
      if (std::isnan(y_(r))) continue;
      FastRow& f = rows_[static_cast<std::size_t>(nrows_++)];
      const int a = meas_.row(r).anchor;
      f.anchor = a;
      f.rtoa = meas_.row(r).kind == RowKind::kRtoa ? 1 : 0;
      f.set(FastRow::kY, y_(r));
      for (int e = 0; e < 3; ++e)
        f.set(FastRow::kQ0 + e, e < meas_.layout().space_dim ? meas_.anchors()(a, e) : 0.0);
      for (int z = 0; z < 2; ++z) {
        const RowLik& l = lik_[static_cast<std::size_t>(r) * 2 + static_cast<std::size_t>(z)];
        f.set(FastRow::kMu0 + z, l.mu);
        f.set(FastRow::kInv0 + z, l.inv2);
        f.set(FastRow::kC0 + z, l.c + (lonely_[static_cast<std::size_t>(a)] ? Lq_(a, z) : 0.0));
        double mask = 0.0;
        if (l.rayleigh) {
          const std::uint64_t ones = ~std::uint64_t{0};
          std::memcpy(&mask, &ones, sizeof mask);
        }
        f.set(FastRow::kRay0 + z, mask);
      }
      lonely_[static_cast<std::size_t>(a)] = 0;
    }
    for (int b = 0; b < B_; ++b)
      if (lonely_[static_cast<std::size_t>(b)]) lonely_[static_cast<std::size_t>(nlonely_++)] = b;
  }

  // ---- per-particle work -------------------------------------------------------------------------
#ifdef NLOSLOC_PF_AVX2_DISPATCH
  /// The pass compiled for AVX2 (VEX encoding throughout, the weighting on 4-double packets: see detail::P4):
  /// the same result, bit for bit.
  __attribute__((target("avx2"))) void propagate_weight_avx2(int b0, int e0, int th, long k, double t,
                                                             bool speed) {
    propagate_weight<detail::P4>(b0, e0, th, k, t, speed);
  }
#endif
  /// Moves and weights particles [b0, e0) on thread th; W: the widest packet of the weighting (weight_loop).
  template <class W>
  NLOSLOC_PF_INLINE void propagate_weight(int b0, int e0, int th, long k, double t, bool speed) {
    ThreadWork& w = work_[static_cast<std::size_t>(th)];
    BatchRng& rng = brng_[static_cast<std::size_t>(th)];
    // Refills on AVX2 registers in the AVX2 pass, or in a build for AVX or later (the same words either way)
    rng.use_avx2(detail::kIsP4<W> || detail::kPfLanes >= 4);
    init_acc(w.sacc.data(), 1);
    cbeg_[static_cast<std::size_t>(th)] = b0;
    cend_[static_cast<std::size_t>(th)] = e0;
    for (int i0 = b0; i0 < e0; i0 += kBlock) {
      const int n = std::min(kBlock, e0 - i0);
      w.blk = (i0 - b0) / kBlock;
      const int ku = (n + 3) / 4 * 4;  // uniforms per anchor in this block (fill_uniform needs 4 | count)
      rng.fill_uniform(w.u.data(), B_ * ku);
      rng.fill_normal(w.z.data(), nq_ * n);
      load_block(i0, n, w);
      // 1. situation transition from the previous state (eqs. 9-10, 15-18 / 16)
      int j = 0;
      if (fast2d_) {
        for (int b = 0; b < B_; ++b) {  // conditions as 0/1 doubles (a loop the compiler vectorises)
          const std::uint8_t* sb = w.sb[static_cast<std::size_t>(b)];
          double* sd = &w.sd[static_cast<std::size_t>(b) * kBlock];
          for (int jj = 0; jj < n; ++jj) sd[jj] = sb[jj];
        }
        bool flip = false;
        for (; j + kLanes <= n; j += kLanes) flip |= sight_fast<Packet>(j, ku, w);
        for (; j < n; ++j) flip |= sight_fast<double>(j, ku, w);
        for (int b = 0; b < B_; ++b) {
          std::uint8_t* nb = &ns_[sidx(b, i0)];
          if (!flip) {
            std::copy_n(w.sb[static_cast<std::size_t>(b)], n, nb);
            continue;
          }
          const double* sd = &w.sd[static_cast<std::size_t>(b) * kBlock];
          for (int jj = 0; jj < n; ++jj) nb[jj] = static_cast<std::uint8_t>(sd[jj]);
        }
      } else {
        for (; j < n; ++j) sight_generic(i0, j, ku, k, speed, w);
      }
      // 2. x_t = F x_{t-1} + G n (eq. 4)
      move(i0, n, w);
      if (opt_.resampling == PfResampling::kMergeSelect) bucket_keys(i0, n);
      // 3. log p(y | x, s) + log p(o | s), then the moments
      if (fastrows_) {
        if (meas_.layout().space_dim == 2)
          weight_loop<2, W>(i0, n, w);
        else
          weight_loop<3, W>(i0, n, w);
      } else {
        for (j = 0; j < n; ++j) weight_generic(i0, j, t, w);
      }
    }
    double* part = &parts_[static_cast<std::size_t>(th * stride_)];
    std::copy(w.sacc.begin(), w.sacc.end(), part);
    if (fastrows_)  // the fast path summed w s_b only (N_z = 2): the rest has s_b = 0
      for (int b = 0; b < B_; ++b) part[kSp + 2 * b] = std::max(0.0, part[1] - part[kSp + 2 * b + 1]);
  }

  template <class P>
  NLOSLOC_PF_INLINE static P ld(const double* p) {
    return detail::pk::load<P>(p);
  }
  template <class P>
  NLOSLOC_PF_INLINE static P cst(double v) {
    return detail::pk::set1<P>(v);
  }
  /// Calls f(tag, j) for j = 0, w, 2w, ... while a packet of w lanes fits in n: packets W first (W = P4 on
  /// the AVX2 pass), then Packet; tag is a null pointer to the packet type. Returns where the scalar tail
  /// starts.
  template <class W, class F>
  NLOSLOC_PF_INLINE static int sweep_packets(int n, F&& f) {
    constexpr int kWide = static_cast<int>(sizeof(W) / sizeof(double));
    int j = 0;
    if constexpr (kWide != kLanes)
      for (; j + kWide <= n; j += kWide) f(static_cast<W*>(nullptr), j);
    for (; j + kLanes <= n; j += kLanes) f(static_cast<Packet*>(nullptr), j);
    return j;
  }

  template <class P>
  bool sight_fast(int j, int ku, ThreadWork& w) {
    namespace ei = Eigen::internal;
    const auto& L = meas_.layout();
    const P vx = ld<P>(w.xb[L.velocity] + j), vy = ld<P>(w.xb[L.velocity + 1] + j);
    const P v2 = ei::padd(ei::pmul(vx, vx), ei::pmul(vy, vy));
    const P V = ei::psqrt(v2);
    // pbar(|v|) with a relative margin of 1e-9 (so rounding never makes the pre-test reject a switch)
    const P pv = ei::pdiv(ei::padd(ei::pmul(V, cst<P>(amax_)), cst<P>(cmax_)),
                          ei::padd(ei::pmul(V, cst<P>(smin_)), cst<P>(pmin_)));
    const P pbar = ei::pmul(ei::pmax(pv, cst<P>(cmax_ / pmin_)), cst<P>(1.0 + 1e-9));
    P any = ei::pzero(pbar);
    for (int b = 0; b < B_; ++b)
      any = ei::por(any, ei::pcmp_lt(ld<P>(&w.u[static_cast<std::size_t>(b * ku + j)]), pbar));
    if (!ei::predux_any(any)) return false;
    const P px = ld<P>(w.xb[L.position] + j), py = ld<P>(w.xb[L.position + 1] + j);
    const P half = cst<P>(0.5), one = cst<P>(1.0);
    for (int b = 0; b < B_; ++b) {
      const SwitchCoef& c = coef_[static_cast<std::size_t>(b)];
      const P dx = ei::psub(px, cst<P>(meas_.anchors()(b, 0))),
              dy = ei::psub(py, cst<P>(meas_.anchors()(b, 1)));
      P cr = ei::psub(ei::pmul(dx, vy), ei::pmul(dy, vx));  // d x v: w = |d x v| / |d| (eq. 10)
      P c2 = ei::pmul(cr, cr);
      P d2 = ei::padd(ei::pmul(dx, dx), ei::pmul(dy, dy));
      const P at = ei::pcmp_eq(d2, ei::pzero(d2));
      if (ei::predux_any(at)) {  // at the anchor: w = |v|
        c2 = ei::pselect(at, v2, c2);
        d2 = ei::pselect(at, one, d2);
      }
      double* sdp = &w.sd[static_cast<std::size_t>(b * kBlock + j)];
      const P s = ld<P>(sdp);
      const P m = ei::pcmp_lt(half, s);
      const P u = ld<P>(&w.u[static_cast<std::size_t>(b * ku + j)]);
      const P g = ei::psub(ei::pselect(m, cst<P>(c.A[1]), cst<P>(c.A[0])),
                           ei::pmul(u, ei::pselect(m, cst<P>(c.S[1]), cst<P>(c.S[0]))));
      const P h = ei::psub(ei::pmul(u, ei::pselect(m, cst<P>(c.P[1]), cst<P>(c.P[0]))),
                           ei::pselect(m, cst<P>(c.C[1]), cst<P>(c.C[0])));
      // u < p  <=>  c^2 g|g| > d^2 h|h|
      const P lhs = ei::pmul(c2, ei::pmul(g, ei::pabs(g)));
      const P rhs = ei::pmul(d2, ei::pmul(h, ei::pabs(h)));
      const P sn = ei::pxor(s, ei::pand(ei::pcmp_lt(rhs, lhs), one));  // 0 <-> 1 where switching
      ei::pstoreu(sdp, sn);
    }
    return true;
  }

  void sight_generic(int i0, int j, int ku, long k, bool speed, ThreadWork& w) {
    const auto& L = meas_.layout();
    const int i = i0 + j;
    for (int b = 0; b < B_; ++b) {
      const std::uint8_t sb = w.sb[static_cast<std::size_t>(b)][j];
      const double u = w.u[static_cast<std::size_t>(b * ku + j)];
      int nj = 0;
      if (speed) {
        double p[3], v[3];
        for (int e = 0; e < L.space_dim; ++e) {
          p[e] = w.xb[L.position + e][j];
          v[e] = w.xb[L.velocity + e][j];
        }
        const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>> pm(p, L.space_dim),
            vm(v, L.space_dim);
        const double sp = situation::transversal_speed(pm, vm, meas_.anchors().row(b).transpose());
        if (std::isfinite(sp)) {
          sight_.model(b).transition(k, sp, w.T);  // eqs. (15)-(18) or (16)
          double c = 0.0;
          while (nj < nz_ - 1 && u >= (c += w.T(sb, nj))) ++nj;
        } else {
          // An overflowed state has no speed: the chain stays, as on the fast path (whose switch test is
          // false for NaN), and the particle's likelihood decides (weight 0 for a state that is not finite).
          nj = sb;
        }
      } else {
        while (nj < nz_ - 1 && u >= cum_[cidx(b, sb, nj)]) ++nj;
      }
      ns_[sidx(b, i)] = static_cast<std::uint8_t>(nj);
      w.sd[static_cast<std::size_t>(b * kBlock + j)] = nj;
    }
  }

  /// x_t = F x_{t-1} + G n (eq. 4) from x_ into nx_ (swapped after the pass), one output row at a time over
  /// the block; rows with one to three non-zero terms (all of them in the constant-velocity models) unrolled.
  void move(int i0, int n, const ThreadWork& w) {
    for (int r = 0; r < N; ++r) {
      const double* src[N + N];
      double v[N + N];
      int ne = 0;
      for (int e = fbeg_[r]; e < fbeg_[r + 1]; ++e, ++ne) {
        src[ne] = w.xb[fent_[static_cast<std::size_t>(e)].col];
        v[ne] = fent_[static_cast<std::size_t>(e)].v;
      }
      for (int e = gbeg_[r]; e < gbeg_[r + 1]; ++e, ++ne) {
        src[ne] = &w.z[static_cast<std::size_t>(gent_[static_cast<std::size_t>(e)].col * n)];
        v[ne] = gent_[static_cast<std::size_t>(e)].v;
      }
      double* out = &nx_[idx(r, i0)];
      switch (ne) {
        case 0: std::fill(out, out + n, 0.0); break;
        case 1: lincomb<1>(out, n, src, v); break;
        case 2: lincomb<2>(out, n, src, v); break;
        case 3: lincomb<3>(out, n, src, v); break;
        default:
          for (int j = 0; j < n; ++j) {
            double a = 0.0;
            for (int e = 0; e < ne; ++e) a += v[e] * src[e][j];
            out[j] = a;
          }
      }
    }
  }
  template <int K>
  static void lincomb(double* out, int n, const double* const* src, const double* v) {
    namespace ei = Eigen::internal;
    Packet c[K];
    for (int e = 0; e < K; ++e) c[e] = cst<Packet>(v[e]);
    int j = 0;
    for (; j + kLanes <= n; j += kLanes) {
      Packet a = ei::pmul(c[0], ld<Packet>(src[0] + j));
      for (int e = 1; e < K; ++e) a = ei::padd(a, ei::pmul(c[e], ld<Packet>(src[e] + j)));
      ei::pstoreu(out + j, a);
    }
    for (; j < n; ++j) {
      double a = v[0] * src[0][j];
      for (int e = 1; e < K; ++e) a += v[e] * src[e][j];
      out[j] = a;
    }
  }

  /// exp(d) for d <= 0, exactly 0 below -708 and for d = -inf or NaN.
  template <class P>
  NLOSLOC_PF_INLINE static P wexp(const P& d) {
    namespace pk = detail::pk;
    return pk::select(pk::lt(pk::set1<P>(-708.0), d), pk::exp(d), pk::set1<P>(0.0));
  }

  /// Accumulator rows: `lanes` interleaved rows of stride_ doubles (entry q of lane l at q * lanes + l).
  void init_acc(double* a, int lanes) const {
    std::fill(a, a + lanes, -std::numeric_limits<double>::infinity());
    std::fill(a + lanes, a + lanes * stride_, 0.0);
  }

  /// Adds a weight exp(lw - running max) to the accumulators: [max, sum w, sum w^2, sum w xc (N),
  /// situation sums (B x N_z), sum w xc_p^2 per position axis p]; xc = x - centre_ (the previous estimate).
  /// With `sd`, the lanes hold s in {0, 1} and only the N_z = 2 entry w s_b is summed; returns w.
  template <class P>
  P accumulate(double* a, const P& lw, const P* xc, const double* sd) const {
    namespace ei = Eigen::internal;
    constexpr int W = static_cast<int>(sizeof(P) / sizeof(double));
    const P m0 = ld<P>(a);
    const P up = ei::pcmp_lt(m0, lw);
    P m = m0;
    if (ei::predux_any(up)) {  // new running maximum: rescale (rare after the first particles)
      m = ei::pselect(up, lw, m0);
      const P f = ei::pselect(up, wexp<P>(ei::psub(m0, m)), cst<P>(1.0));
      for (int q = 1; q < stride_; ++q) ei::pstoreu(a + q * W, ei::pmul(ld<P>(a + q * W), f));
      ei::pstoreu(a + 2 * W, ei::pmul(ld<P>(a + 2 * W), f));  // sum w^2 scales by f^2
      ei::pstoreu(a, m);
    }
    const P w = wexp<P>(ei::psub(lw, m));
    auto add = [&](int q, const P& v) { ei::pstoreu(a + q * W, ei::padd(ld<P>(a + q * W), v)); };
    add(1, w);
    add(2, ei::pmul(w, w));
    const P live = ei::pcmp_lt(ei::pzero(w), w);  // weight 0 adds nothing, even with a non-finite state
    const int pos = meas_.layout().position;
    for (int d = 0; d < N; ++d) add(3 + d, ei::pselect(live, ei::pmul(w, xc[d]), ei::pzero(w)));
    for (int e = 0; e < meas_.layout().space_dim; ++e)
      add(k2_ + e, ei::pselect(live, ei::pmul(w, ei::pmul(xc[pos + e], xc[pos + e])), ei::pzero(w)));
    if (sd != nullptr)
      for (int b = 0; b < B_; ++b)
        add(kSp + 2 * b + 1, ei::pmul(w, ld<P>(sd + static_cast<std::size_t>(b) * kBlock)));
    return w;
  }

  /// Stage 3 on the fast path, as loops over the block with independent iterations (packets W while W's
  /// lanes remain (W = P4 only), then Packet, then doubles): per observed row its log density into lw and
  /// the Rayleigh factors into pr; then the log weights, the block's maximum, the weights and the moments.
  /// Sums and maxima are kept in Packet (2-lane) order whatever W is.
  template <int D, class W>
  NLOSLOC_PF_INLINE void weight_loop(int i0, int n, ThreadWork& w) {
    namespace ei = Eigen::internal;
    namespace pk = detail::pk;
    const auto& L = meas_.layout();
    double* lwb = w.lw.data();
    double* pr = w.pr.data();
    std::fill(lwb, lwb + n, 0.0);
    std::fill(pr, pr + n, 1.0);
    const double* px[D];
    for (int e = 0; e < D; ++e) px[e] = &nx_[idx(L.position + e, i0)];
    const double* tp = L.clock_bias >= 0 ? &nx_[idx(L.clock_bias, i0)] : nullptr;
    for (int r = 0; r < nrows_; ++r) {
      const FastRow& f = rows_[static_cast<std::size_t>(r)];
      const double* sd = &w.sd[static_cast<std::size_t>(f.anchor) * kBlock];
      const bool rtoa = f.rtoa != 0 && tp != nullptr;
      // which conditions are Rayleigh (bit z; the masks are NaN bit patterns, != 0)
      const int ray = (f.k[FastRow::kRay0][0] != 0.0 ? 1 : 0) | (f.k[FastRow::kRay1][0] != 0.0 ? 2 : 0);
      auto body = [&](auto tag, int j) NLOSLOC_PF_LAMBDA_INLINE {
        using Q = decltype(detail::packet_of(tag));
        auto k = [&f](int c) NLOSLOC_PF_LAMBDA_INLINE { return pk::load<Q>(f.k[c]); };  // stored broadcast
        const Q zero = pk::set1<Q>(0.0), one = pk::set1<Q>(1.0);
        Q d2 = zero;
        for (int e = 0; e < D; ++e) {
          const Q de = pk::sub(pk::load<Q>(px[e] + j), k(FastRow::kQ0 + e));
          d2 = pk::add(d2, pk::mul(de, de));
        }
        Q g = pk::sqrt(d2);  // ||p - q|| (+ tau), Table I
        if (rtoa) g = pk::add(g, pk::load<Q>(tp + j));
        const Q res = pk::sub(k(FastRow::kY), g);
        // Normal: c - (res - mu)^2 / (2 var); Rayleigh (Table X): log(res / s^2) - res^2 / (2 s^2), the log
        // of res entering through the product pr (0 outside the support: weight 0)
        const Q e0 = pk::sub(res, k(FastRow::kMu0)), e1 = pk::sub(res, k(FastRow::kMu1));
        const Q l0 = pk::sub(k(FastRow::kC0), pk::mul(k(FastRow::kInv0), pk::mul(e0, e0)));
        const Q l1 = pk::sub(k(FastRow::kC1), pk::mul(k(FastRow::kInv1), pk::mul(e1, e1)));
        const Q mb = pk::lt(pk::set1<Q>(0.5), pk::load<Q>(sd + j));
        pk::store(lwb + j, pk::add(pk::load<Q>(lwb + j), pk::select(mb, l1, l0)));
        if (ray != 0) {
          const Q rp = pk::max(res, zero);
          const Q fac = ray == 3 ? rp : ray == 2 ? pk::select(mb, rp, one) : pk::select(mb, one, rp);
          pk::store(pr + j, pk::mul(pk::load<Q>(pr + j), fac));
        }
      };
      for (int j = sweep_packets<W>(n, body); j < n; ++j) body(static_cast<double*>(nullptr), j);
    }
    for (int q = 0; q < nlonely_; ++q) {  // quality of anchors without an observed row
      const int b = lonely_[static_cast<std::size_t>(q)];
      const double* sd = &w.sd[static_cast<std::size_t>(b) * kBlock];
      for (int j = 0; j < n; ++j) lwb[j] += Lq_(b, sd[j] > 0.5 ? 1 : 0);
    }
    // log w_t = log w_{t-1} (normalised) + log p(y | x, s) + log p(o | s); block maximum
    const double* lwi = &logw_(i0);
    double* lwo = &nlogw_(i0);
    const double ninf = -std::numeric_limits<double>::infinity();
    Packet mp = cst<Packet>(ninf);
    double ms = ninf;
    {
      auto logw = [&](auto tag, int j) NLOSLOC_PF_LAMBDA_INLINE {
        using Q = decltype(detail::packet_of(tag));
        const Q v =
            pk::add(pk::add(pk::sub(pk::load<Q>(lwi + j), pk::set1<Q>(prior_shift_)), pk::load<Q>(lwb + j)),
                    pk::log(pk::load<Q>(pr + j)));
        pk::store(lwo + j, v);
        pk::max_into(mp, v);
      };
      for (int j = sweep_packets<W>(n, logw); j < n; ++j) {
        lwo[j] = (lwi[j] - prior_shift_) + lwb[j] + std::log(pr[j]);
        ms = std::max(ms, lwo[j]);
      }
    }
    double lanes[kLanes];
    ei::pstoreu(lanes, mp);
    for (double v : lanes) ms = std::max(ms, v);
    double* a = w.sacc.data();
    if (ms > a[0]) {  // new running maximum: rescale the sums
      const double f = a[0] == ninf ? 0.0 : std::exp(a[0] - ms);
      for (int q = 1; q < stride_; ++q) a[q] *= f;
      a[2] *= f;  // sum w^2 scales by f^2
      a[0] = ms;
    }
    double* wo = &nw_(i0);  // the weights exp(lw - m), kept for the resampling (scale exp(m - z) by block)
    if (a[0] == ninf) {     // every weight so far is zero
      std::fill(wo, wo + n, 0.0);
      w.nbsc[static_cast<std::size_t>(w.blk)] = ninf;
      return;
    }
    // weights and moments about centre_: sum w, w^2, w xc, w_p xc_p^2, w s_b
    const double m = a[0];
    w.nbsc[static_cast<std::size_t>(w.blk)] = m;
    Packet s0 = ei::pzero(Packet()), s00 = s0, s1[N], s2[D], sp[64];
    for (int d = 0; d < N; ++d) s1[d] = s0;
    for (int e = 0; e < D; ++e) s2[e] = s0;
    for (int b = 0; b < B_; ++b) sp[b] = s0;
    const double* xs[N];
    for (int d = 0; d < N; ++d) xs[d] = &nx_[idx(d, i0)];
    auto mom = [&](auto tag, int j, auto* S0, auto* S00, auto* S1, auto* S2,
                   auto* SP) NLOSLOC_PF_LAMBDA_INLINE {
      using Q = decltype(detail::packet_of(tag));
      const Q zero = pk::set1<Q>(0.0);
      const Q wj = wexp<Q>(pk::sub(pk::load<Q>(lwo + j), pk::set1<Q>(m)));
      pk::store(wo + j, wj);
      pk::accumulate(*S0, wj);
      pk::accumulate(*S00, pk::mul(wj, wj));
      // weight 0: the particle adds nothing, even with a non-finite state
      const Q live = pk::lt(zero, wj);
      Q xc[N];
      for (int d = 0; d < N; ++d)
        xc[d] = pk::select(live, pk::sub(pk::load<Q>(xs[d] + j), pk::set1<Q>(centre_(d))), zero);
      for (int d = 0; d < N; ++d) pk::accumulate(S1[d], pk::mul(wj, xc[d]));
      for (int e = 0; e < D; ++e) {  // position: eq. (31)'s variance
        const Q xp = xc[L.position + e];
        pk::accumulate(S2[e], pk::mul(wj, pk::mul(xp, xp)));
      }
      for (int b = 0; b < B_; ++b)
        pk::accumulate(SP[b], pk::mul(wj, pk::load<Q>(&w.sd[static_cast<std::size_t>(b) * kBlock + j])));
    };
    int j = sweep_packets<W>(
        n, [&](auto tag, int jj) NLOSLOC_PF_LAMBDA_INLINE { mom(tag, jj, &s0, &s00, s1, s2, sp); });
    double t0 = ei::predux(s0), t00 = ei::predux(s00), t1[N], t2[D], tp2[64];
    for (int d = 0; d < N; ++d) t1[d] = ei::predux(s1[d]);
    for (int e = 0; e < D; ++e) t2[e] = ei::predux(s2[e]);
    for (int b = 0; b < B_; ++b) tp2[b] = ei::predux(sp[b]);
    for (; j < n; ++j) mom(static_cast<double*>(nullptr), j, &t0, &t00, t1, t2, tp2);
    a[1] += t0;
    a[2] += t00;
    for (int d = 0; d < N; ++d) a[3 + d] += t1[d];
    for (int e = 0; e < D; ++e) a[k2_ + e] += t2[e];
    for (int b = 0; b < B_; ++b) a[kSp + 2 * b + 1] += tp2[b];
  }

  void weight_generic(int i0, int j, double t, ThreadWork& w) {
    const int i = i0 + j;
    const int m = meas_.rows();
    State xn;
    for (int d = 0; d < N; ++d) xn(d) = nx_[idx(d, i)];
    VecX& z = w.zrow;
    meas_.predict(xn, t, z);
    double lw = 0.0;
    if (fastlik_) {
      double prod = 1.0;
      for (int row = 0; row < m; ++row) {
        if (std::isnan(y_(row))) continue;
        const int a = meas_.row(row).anchor;
        const int c = a < 0 ? 0 : ns_[sidx(a, i)];
        double res = y_(row) - z(row);
        if (meas_.is_angle(row)) res = wrap_angle(res);
        const RowLik& l =
            lik_[static_cast<std::size_t>(row) * static_cast<std::size_t>(nz_) + static_cast<std::size_t>(c)];
        if (l.rayleigh) {
          prod *= res > 0.0 ? res : 0.0;  // outside the support: weight 0
          lw += l.c - l.inv2 * res * res;
        } else {
          const double e = res - l.mu;
          lw += l.c - l.inv2 * e * e;
        }
      }
      lw += std::log(prod);
    } else {
      for (int row = 0; row < m; ++row) {
        if (std::isnan(y_(row))) continue;
        const int a = meas_.row(row).anchor;
        const int c = a < 0 ? 0 : ns_[sidx(a, i)];
        double res = y_(row) - z(row);
        if (meas_.is_angle(row)) res = wrap_angle(res);
        lw += meas_.noise(row, c).log_pdf(res);
      }
    }
    for (int b = 0; b < B_; ++b) lw += Lq_(b, ns_[sidx(b, i)]);
    lw += logw_(i) - prior_shift_;
    nlogw_(i) = lw;
    double xc[N];
    for (int d = 0; d < N; ++d) xc[d] = xn(d) - centre_(d);
    double* acc = w.sacc.data();
    const double wi = accumulate<double>(acc, lw, xc, nullptr);
    for (int b = 0; b < B_; ++b) acc[kSp + b * nz_ + ns_[sidx(b, i)]] += wi;
  }

  /// Combines the partial sums of every thread and lane (each relative to its own running maximum) into the
  /// estimate (eq. 28 analogue for sampled particles), covariance, situation probabilities and ESS; returns
  /// log sum_i exp(logw_i), the log-likelihood of the step.
  double reduce(double& ess) {
    const int np = pool_->size();
    double g = -std::numeric_limits<double>::infinity();
    for (int p = 0; p < np; ++p) g = std::max(g, parts_[static_cast<std::size_t>(p * stride_)]);
    tot_.assign(static_cast<std::size_t>(stride_), 0.0);
    if (g == -std::numeric_limits<double>::infinity()) return g;
    for (int p = 0; p < np; ++p) {
      const double* a = &parts_[static_cast<std::size_t>(p * stride_)];
      const double f = std::exp(a[0] - g);
      if (!(f > 0.0)) continue;
      for (int q = 1; q < stride_; ++q)  // sum w^2 (q = 2) scales by f^2
        tot_[static_cast<std::size_t>(q)] += (q == 2 ? f * f : f) * a[q];
    }
    const double sw = tot_[1];
    if (!std::isfinite(g + std::log(sw))) return g + std::log(sw);  // rejected: the summary is kept
    ess = sw * sw / tot_[2];
    State m1;
    for (int d = 0; d < N; ++d) m1(d) = tot_[static_cast<std::size_t>(3 + d)] / sw;
    est_ = centre_ + m1;
    // Position variance (eq. 31's threshold) from the raw moments about centre_ (the previous estimate,
    // close to the new one, so the difference loses little precision); the full covariance on request.
    const auto& L = meas_.layout();
    pos_var_ = 0.0;
    for (int e = 0; e < L.space_dim; ++e) {
      const double me = m1(L.position + e);
      pos_var_ += std::max(0.0, tot_[static_cast<std::size_t>(k2_ + e)] / sw - me * me);
    }
    cov_ready_ = false;
    for (int b = 0; b < B_; ++b)
      for (int z = 0; z < nz_; ++z) prob_(b, z) = tot_[static_cast<std::size_t>(kSp + b * nz_ + z)] / sw;
    return g + std::log(sw);
  }

  /// Weighted covariance of the weighted set about est_, on the pool: the particles x_ with weights
  /// exp(logw_ - shift_), or after a resampling (x_ still holds the weighted set: the copy is deferred) the
  /// weights it used, w_ times its block's scale.
  static constexpr int kCovStride = 1 + N + kNT;
  void compute_covariance() const {
    namespace ei = Eigen::internal;
    constexpr int st = kCovStride;
    std::fill(cparts_.begin(), cparts_.end(), 0.0);  // a thread with an empty chunk is not called
    const bool from_w = resampled_;
    pool_->parallel_for(M_, [&](int b0, int e0, int th) {
      const double* scale = work_[static_cast<std::size_t>(th)].bsc.data();  // used when from_w
      // Sums in locals (packets, then the scalar tail), stored once: the threads' rows of cparts_ share a
      // cache line, and a store per particle bounced it between the cores (36 ms at 1e6 particles).
      auto body = [&](auto q0, int i, auto* S) {
        using Q = decltype(q0);
        const Q wi = from_w ? ei::pmul(ld<Q>(&w_(i)), cst<Q>(scale[(i - b0) / kBlock]))
                            : wexp<Q>(ei::psub(ld<Q>(&logw_(i)), cst<Q>(shift_)));
        const Q live = ei::pcmp_lt(ei::pzero(q0), wi);  // weight 0: the particle adds nothing (even NaN x)
        Q xc[N];
        for (int d = 0; d < N; ++d)
          xc[d] = ei::pselect(live, ei::psub(ld<Q>(&x_[idx(d, i)]), cst<Q>(est_(d))), ei::pzero(q0));
        S[0] = ei::padd(S[0], wi);
        int q = 1 + N;
        for (int d = 0; d < N; ++d) {
          const Q wx = ei::pmul(wi, xc[d]);
          S[1 + d] = ei::padd(S[1 + d], wx);
          for (int e = d; e < N; ++e, ++q) S[q] = ei::padd(S[q], ei::pmul(wx, xc[e]));
        }
      };
      Packet sp[st];
      for (auto& v : sp) v = ei::pzero(Packet());
      int i = b0;
      for (; i + kLanes <= e0; i += kLanes) body(Packet(), i, sp);
      double sd[st];
      for (int q = 0; q < st; ++q) sd[q] = ei::predux(sp[q]);
      for (; i < e0; ++i) body(0.0, i, sd);
      std::copy(sd, sd + st, &cparts_[static_cast<std::size_t>(th * st)]);
    });
    double tot[st] = {};
    for (int t = 0; t < pool_->size(); ++t)
      for (int q = 0; q < st; ++q) tot[q] += cparts_[static_cast<std::size_t>(t * st + q)];
    State m1;
    Cov m2;
    int q = 1 + N;
    for (int d = 0; d < N; ++d) {
      m1(d) = tot[1 + d] / tot[0];
      for (int e = d; e < N; ++e, ++q) m2(d, e) = m2(e, d) = tot[q] / tot[0];
    }
    est_cov_ = m2 - m1 * m1.transpose();
    nlosloc::detail::symmetrize(est_cov_);
    cov_ready_ = true;
  }

  /// Applies the deferred normalisation (logw_ -= shift_).
  void normalise_log_weights() const {
    if (shift_ == 0.0) return;
    logw_.array() -= shift_;
    shift_ = 0.0;
  }

  /// Scalar moments from the normalised log weights (after reset).
  void summarise() {
    w_ = (logw_.array() - log_sum_exp(logw_)).exp();
    State m1 = State::Zero();
    Cov m2 = Cov::Zero();
    prob_.setZero();
    for (int i = 0; i < M_; ++i) {
      const double wi = w_(i);
      if (wi == 0.0) continue;
      State x;
      for (int d = 0; d < N; ++d) x(d) = x_[idx(d, i)];
      m1 += wi * x;
      m2.noalias() += wi * x * x.transpose();
      for (int b = 0; b < B_; ++b) prob_(b, s_[sidx(b, i)]) += wi;
    }
    est_ = m1;
    est_cov_ = m2 - m1 * m1.transpose();
    nlosloc::detail::symmetrize(est_cov_);
    cov_ready_ = true;
    const auto& L = meas_.layout();
    pos_var_ = est_cov_.diagonal().segment(L.position, L.space_dim).sum();
  }

  /// Systematic resampling of the weights exp(logw_ - z), on the pool: each thread takes the pointers
  /// (j + u0) / M that fall in its chunk's share of the cumulative weight and writes their ancestors (the
  /// copy is left to the next pass). With `from_pass`, the weights are the pass's, w_ exp(m_block - z)
  /// (the fast path stored them with its block maxima, and no merge changed them): no exp pass; else they
  /// are computed here. Either way w_ times the block scale bsc is the weight of the resampled set.
  void resample(double z, bool from_pass) {
    namespace ei = Eigen::internal;
    const int T = pool_->size();
    const double lw_equal = -std::log(static_cast<double>(M_));
    if (from_pass) {
      // chunk sums from the pass's sums (each relative to its thread's last maximum a[0]); block scales
      for (int th = 0; th < T; ++th) {
        const double* a = &parts_[static_cast<std::size_t>(th * stride_)];
        const auto u = static_cast<std::size_t>(th);
        csum_[u] = a[0] > -std::numeric_limits<double>::infinity() ? a[1] * std::exp(a[0] - z) : 0.0;
        double* sc = work_[u].bsc.data();
        const int nb = (cend_[u] - cbeg_[u] + kBlock - 1) / kBlock;
        for (int q = 0; q < nb; ++q)
          sc[q] = sc[q] > -std::numeric_limits<double>::infinity() ? std::exp(sc[q] - z) : 0.0;
      }
    } else {
      std::fill(csum_.begin(), csum_.end(), 0.0);  // a thread with an empty chunk is not called
      std::fill(cbeg_.begin(), cbeg_.end(), 0);
      std::fill(cend_.begin(), cend_.end(), 0);
      pool_->parallel_for(M_, [&](int b0, int e0, int th) {
        int i = b0;
        Packet acc = ei::pzero(cst<Packet>(0.0));
        // the weights, and the resampled set's equal log weights in their place (read only here)
        for (; i + kLanes <= e0; i += kLanes) {
          const Packet wi = wexp<Packet>(ei::psub(ld<Packet>(&logw_(i)), cst<Packet>(z)));
          ei::pstoreu(&w_(i), wi);
          ei::pstoreu(&logw_(i), cst<Packet>(lw_equal));
          acc = ei::padd(acc, wi);
        }
        double s = ei::predux(acc);
        for (; i < e0; ++i) {
          s += (w_(i) = wexp<double>(logw_(i) - z));
          logw_(i) = lw_equal;
        }
        const auto u = static_cast<std::size_t>(th);
        csum_[u] = s;
        cbeg_[u] = b0;
        cend_[u] = e0;
        std::fill_n(work_[u].bsc.begin(), (e0 - b0 + kBlock - 1) / kBlock, 1.0);
      });
    }
    double total = 0.0;
    for (int t = 0; t < T; ++t) total += csum_[static_cast<std::size_t>(t)];
    const double u0 = rng_[0].uniform();
    pool_->parallel_for(T, [&](int t0, int t1, int) {
      for (int t = t0; t < t1; ++t) {
        const auto u = static_cast<std::size_t>(t);
        double c0 = 0.0;
        for (std::size_t q = 0; q < u; ++q) c0 += csum_[q];
        const int b0 = cbeg_[u];
        const double* sc = work_[u].bsc.data();
        systematic_resample_chunk([&](int i) { return w_(i) * sc[(i - b0) / kBlock]; }, b0, cend_[u], c0,
                                  c0 + csum_[u], total, M_, u0, t, T, anc_.data());
        if (from_pass) std::fill(&logw_(0) + b0, &logw_(0) + cend_[u], lw_equal);
      }
    });
    resampled_ = true;  // particle j is now x_ / s_ of anc_[j] (ancestor(); the next pass gathers them)
    shift_ = 0.0;
  }

  /// Bucket keys of the moved particles [i0, i0 + n) (in the pass, while they are in cache): see
  /// detail::pf_bucket_keys.
  NLOSLOC_PF_INLINE void bucket_keys(int i0, int n) {
    detail::pf_bucket_keys<N>(&ns_[sidx(0, i0)], static_cast<std::size_t>(M_), B_, &nx_[idx(0, i0)],
                              static_cast<std::size_t>(M_), inv_cell_, n,
                              &mkey_[static_cast<std::size_t>(i0)]);
  }

  /// Bucketed greedy merge (see the file comment) on the keys of the pass; returns the number of absorbed
  /// particles.
  int merge_cells() {
    const double d =
        opt_.merge_threshold >= 0.0 ? opt_.merge_threshold : default_merge_threshold(pos_var_, M_);
    if (!(d > 0.0)) return 0;
    return merge_greedy_parallel(
        mkey_.data(), logw_.data(), M_,
        [&](int a, int b) {
          for (int bb = 0; bb < B_; ++bb)
            if (s_[sidx(bb, a)] != s_[sidx(bb, b)]) return false;  // eq. (29): different situation
          double d2 = 0.0;
          for (int e = 0; e < N; ++e) {
            const double v = x_[idx(e, a)] - x_[idx(e, b)];
            d2 += v * v;
          }
          return d2 < d * d;
        },
        *pool_, mws_);
  }

  static constexpr int kSp = 3 + N;  // offset of the situation sums in an accumulator row

  Motion motion_;
  Meas meas_;
  situation::SightProcess sight_;
  situation::QualityModel quality_;
  PfOptions opt_;
  std::unique_ptr<ThreadPool> pool_;  // stable address for the workers; the filter stays movable
  int M_ = 0, B_ = 0, nz_ = 0, nq_ = 0, stride_ = 0, k2_ = 0;  // k2_: second moments in an accumulator row
  bool fast2d_ = false;    // all chains speed-dependent LOS/NLOS in 2-D: switch test without sqrt/division
  bool fastlik_ = false;   // every noise Normal or Rayleigh: closed-form log densities
  bool fastrows_ = false;  // and N_z = 2 with range rows only: vectorised weights
  bool avx2_ = detail::pf_avx2_enabled();  // propagate_weight_avx2 (run-time AVX2; fixed at construction)
  std::vector<RowLik> lik_;
  std::vector<FastRow> rows_;
  std::vector<int> lonely_;
  int nrows_ = 0, nlonely_ = 0;
  std::vector<SwitchCoef> coef_;
  double amax_ = 0.0, cmax_ = 0.0, smin_ = 0.0, pmin_ = 1.0;
  std::vector<Entry> fent_, gent_;
  int fbeg_[N + 1] = {}, gbeg_[N + 1] = {};
  double t_ = 0.0;
  long k_ = 0;
  std::vector<double> x_, nx_;
  std::vector<std::uint8_t> s_, ns_;
  mutable VecX logw_;
  VecX nlogw_;                  // the pass writes the new log weights here: a rejected step keeps logw_
  mutable double shift_ = 0.0;  // logw_ - shift_ are the normalised log weights
  double prior_shift_ = 0.0;
  VecX w_, nw_;  // weights of the last resampling (by block: times bsc); the pass writes nw_
  std::vector<int> anc_;
  bool resampled_ = false;  // the current set is x_ / s_ through anc_ (ancestor())
  Eigen::Matrix<double, N, Eigen::Dynamic> G_;
  std::vector<Rng> rng_;
  std::vector<BatchRng> brng_;
  std::vector<BatchRng> brng_back_;  // bulk generators before the pass, restored when a step is rejected
  std::vector<ThreadWork> work_;
  std::vector<double> parts_, tot_, csum_, cum_;
  std::vector<int> cbeg_, cend_;
  MatX Lq_, T_, prob_;
  VecX y_;
  ParallelMergeWorkspace mws_;
  std::vector<std::uint32_t> mkey_;  // merge-select: bucket keys of the moved particles (bucket_keys)
  double inv_cell_ = 0.0;            // 1 / width of the buckets' grid cells (0: one cell)
  State est_ = State::Zero(), centre_ = State::Zero();
  mutable Cov est_cov_ = Cov::Zero();
  mutable bool cov_ready_ = false;
  mutable std::vector<double> cparts_;  // per-thread partial sums of compute_covariance()
  double pos_var_ = 0.0;                // position variance of the weighted set (eq. 31)
};

}  // namespace nlosloc::rbpf
