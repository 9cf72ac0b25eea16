#pragma once
/// \file random.hpp
/// The one seeded random generator of nlosloc: xoshiro256++ (Blackman and Vigna 2019) seeded through
/// splitmix64. Every draw of a scenario goes through an Rng, so a run is reproducible bit for bit from
/// (seed, stream) on the same build. Satisfies UniformRandomBitGenerator, so std and Boost distributions
/// accept it, but normal() and uniform() here are our own and do not depend on the standard library.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#define NLOSLOC_RNG_SSE2 1
#endif
// GCC/Clang on x86-64: BatchRng can refill on 256-bit AVX2 registers in a function compiled for AVX2 (target
// attribute), chosen at run time (BatchRng::use_avx2), whatever the build's flags.
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#include <immintrin.h>
#define NLOSLOC_RNG_AVX2 1
#endif

namespace nlosloc {

/// Seeded pseudo-random generator (xoshiro256++). Copyable; copies continue the same sequence.
class Rng {
 public:
  using result_type = std::uint64_t;
  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return std::numeric_limits<result_type>::max(); }

  /// Generator for `seed`; `stream` selects an independent sequence (e.g. the Monte Carlo run index).
  explicit Rng(std::uint64_t seed = 0, std::uint64_t stream = 0) { reseed(seed, stream); }

  void reseed(std::uint64_t seed, std::uint64_t stream = 0) {
    std::uint64_t z = seed ^ (0x9E3779B97F4A7C15ULL * (stream + 1));
    for (auto& w : s_) w = splitmix64(z);
    has_spare_ = false;
  }

  result_type operator()() {
    const std::uint64_t r = rotl(s_[0] + s_[3], 23) + s_[0];
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return r;
  }

  /// Uniform in the open interval (0, 1): 53 random bits, never 0 or 1.
  double uniform() { return (static_cast<double>((*this)() >> 11) + 0.5) * 0x1.0p-53; }

  /// Standard normal variate (Marsaglia polar method; the second variate is kept for the next call).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * f;
    has_spare_ = true;
    return u * f;
  }

  /// Normal with mean mu and standard deviation sigma.
  double normal(double mu, double sigma) { return mu + sigma * normal(); }

  /// Advances the generator by 2^128 draws (xoshiro256 jump polynomial, Blackman and Vigna 2019): 2^128
  /// non-overlapping subsequences for parallel use. Clears the kept normal variate.
  void jump() {
    static constexpr std::uint64_t kJump[4] = {0x180ec6d33cfd0abaULL, 0xd5a61266f0c9392cULL,
                                               0xa9582618e03fc9aaULL, 0x39abdc4529b1661cULL};
    std::uint64_t t[4] = {0, 0, 0, 0};
    for (std::uint64_t j : kJump)
      for (int b = 0; b < 64; ++b) {
        if (j & (std::uint64_t{1} << b))
          for (int w = 0; w < 4; ++w) t[w] ^= s_[w];
        (*this)();
      }
    for (int w = 0; w < 4; ++w) s_[w] = t[w];
    has_spare_ = false;
  }

  /// The four words of the xoshiro256 state (for BatchRng).
  std::array<std::uint64_t, 4> state() const { return {s_[0], s_[1], s_[2], s_[3]}; }

  /// Words of save_state(): the four state words, the kept normal's flag (0 or 1) and its bits.
  static constexpr int kStateWords = 6;
  /// The whole state, kept normal variate included: restore_state() of it continues the same sequence (a
  /// checkpoint of a filter that draws).
  void save_state(std::uint64_t* out) const {
    for (int w = 0; w < 4; ++w) out[w] = s_[w];
    out[4] = has_spare_ ? 1 : 0;
    std::memcpy(&out[5], &spare_, sizeof spare_);
  }
  /// Sets the state from kStateWords words of save_state(). Returns false and changes nothing for words no
  /// generator has: an all-zero xoshiro state (a fixed point) or a flag other than 0 or 1.
  bool restore_state(const std::uint64_t* in) {
    if ((in[0] | in[1] | in[2] | in[3]) == 0 || in[4] > 1) return false;
    for (int w = 0; w < 4; ++w) s_[w] = in[w];
    has_spare_ = in[4] == 1;
    std::memcpy(&spare_, &in[5], sizeof spare_);
    return true;
  }

  /// Uniform integer in [0, n), n > 0 (Lemire's unbiased multiply-shift).
  std::uint64_t below(std::uint64_t n) {
    __uint128_t m = static_cast<__uint128_t>((*this)()) * n;
    auto l = static_cast<std::uint64_t>(m);
    if (l < n) {
      const std::uint64_t t = (0 - n) % n;
      while (l < t) {
        m = static_cast<__uint128_t>((*this)()) * n;
        l = static_cast<std::uint64_t>(m);
      }
    }
    return static_cast<std::uint64_t>(m >> 64);
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t& z) {
    std::uint64_t r = (z += 0x9E3779B97F4A7C15ULL);
    r = (r ^ (r >> 30)) * 0xBF58476D1CE4E5B9ULL;
    r = (r ^ (r >> 27)) * 0x94D049BB133111EBULL;
    return r ^ (r >> 31);
  }
  std::uint64_t s_[4];
  double spare_ = 0.0;
  bool has_spare_ = false;
};

namespace detail {
/// True when the CPU running this process has AVX2 (GCC/Clang on x86-64; false elsewhere).
inline bool cpu_has_avx2() {
#ifdef NLOSLOC_RNG_AVX2
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return has;
#else
  return false;
#endif
}

/// Ziggurat tables of the standard normal (Marsaglia and Tsang 2000, 256 layers of area V): x[0] = V / f(R),
/// x[1] = R, x[i+1] = f^{-1}(V / x[i] + f(x[i])), x[256] = 0; f(x) = exp(-x^2 / 2) and fx[i] = f(x[i]).
struct ZigguratNormal {
  static constexpr double kR = 3.6541528853610088;  // start of the tail
  static constexpr double kV = 4.92867323399e-3;    // area of every layer (tail included in layer 0)
  double x[257], fx[257];
  ZigguratNormal() {
    x[0] = kV / std::exp(-0.5 * kR * kR);
    x[1] = kR;
    for (int i = 1; i < 256; ++i) {
      const double a = kV / x[i] + std::exp(-0.5 * x[i] * x[i]);
      x[i + 1] = a < 1.0 ? std::sqrt(-2.0 * std::log(a)) : 0.0;
    }
    x[256] = 0.0;
    for (int i = 0; i <= 256; ++i) fx[i] = std::exp(-0.5 * x[i] * x[i]);
  }
  static const ZigguratNormal& get() {
    static const ZigguratNormal z;
    return z;
  }
};
}  // namespace detail

/// Bulk generator for hot loops (the particle filter): kLanes xoshiro256++ generators run in lockstep
/// (SSE2 when available, otherwise the same arithmetic in scalar code: identical outputs), lane l being the
/// parent Rng jumped l + 1 times by 2^128, so the lanes never overlap the parent or each other. Its output
/// is a different sequence from the parent's (the parent is not advanced). Copyable. use_avx2(true) makes
/// the refills run on AVX2 registers where the CPU has AVX2: the same words, faster.
class BatchRng {
 public:
  static constexpr int kLanes = 4;
  static constexpr int kBuffer = 64;  ///< 64-bit words drawn per refill of the internal buffer

  BatchRng() : BatchRng(Rng()) {}
  explicit BatchRng(Rng parent) {
    for (int l = 0; l < kLanes; ++l) {
      parent.jump();
      const auto st = parent.state();
      for (int w = 0; w < 4; ++w) s_[w][l] = st[static_cast<std::size_t>(w)];
    }
  }

  /// Refills on 256-bit AVX2 registers from now on (on, and the CPU has AVX2) or on SSE2 / scalar code (the
  /// default). Either way the words are the same: only the speed differs. Not part of save_state().
  void use_avx2(bool on) { wide_ = on && detail::cpu_has_avx2(); }
  /// Whether refills run on AVX2 registers.
  bool uses_avx2() const { return wide_; }

  /// Writes 4 * n_quads 64-bit words: word 4 j + l is the j-th output of lane l.
  void fill_bits(std::uint64_t* out, int n_quads) {
#ifdef NLOSLOC_RNG_AVX2
    if (wide_) {
      fill_bits_avx2(out, n_quads);
      return;
    }
#endif
#ifdef NLOSLOC_RNG_SSE2
    __m128i s[4][2];
    for (int w = 0; w < 4; ++w)
      for (int h = 0; h < 2; ++h) s[w][h] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(&s_[w][2 * h]));
    for (int j = 0; j < n_quads; ++j)
      for (int h = 0; h < 2; ++h) {
        const __m128i a = _mm_add_epi64(s[0][h], s[3][h]);
        const __m128i r = _mm_add_epi64(_mm_or_si128(_mm_slli_epi64(a, 23), _mm_srli_epi64(a, 41)), s[0][h]);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 4 * j + 2 * h), r);
        const __m128i t = _mm_slli_epi64(s[1][h], 17);
        s[2][h] = _mm_xor_si128(s[2][h], s[0][h]);
        s[3][h] = _mm_xor_si128(s[3][h], s[1][h]);
        s[1][h] = _mm_xor_si128(s[1][h], s[2][h]);
        s[0][h] = _mm_xor_si128(s[0][h], s[3][h]);
        s[2][h] = _mm_xor_si128(s[2][h], t);
        s[3][h] = _mm_or_si128(_mm_slli_epi64(s[3][h], 45), _mm_srli_epi64(s[3][h], 19));
      }
    for (int w = 0; w < 4; ++w)
      for (int h = 0; h < 2; ++h) _mm_storeu_si128(reinterpret_cast<__m128i*>(&s_[w][2 * h]), s[w][h]);
#else
    for (int j = 0; j < n_quads; ++j)
      for (int l = 0; l < kLanes; ++l) {
        const std::uint64_t a = s_[0][l] + s_[3][l];
        out[4 * j + l] = ((a << 23) | (a >> 41)) + s_[0][l];
        const std::uint64_t t = s_[1][l] << 17;
        s_[2][l] ^= s_[0][l];
        s_[3][l] ^= s_[1][l];
        s_[1][l] ^= s_[2][l];
        s_[0][l] ^= s_[3][l];
        s_[2][l] ^= t;
        s_[3][l] = (s_[3][l] << 45) | (s_[3][l] >> 19);
      }
#endif
  }

  /// n uniforms in the open interval (0, 1) with 52 random bits each ((k + 1/2) 2^-52), n a multiple of 4.
  void fill_uniform(double* out, int n) {
    std::uint64_t b[kBuffer];
    for (int k = 0; k < n; k += kBuffer) {
      const int m = n - k < kBuffer ? n - k : kBuffer;
      fill_bits(b, m / kLanes);
      to_uniform(b, out + k, m);
    }
  }

  /// One 64-bit word (from the internal buffer, refilled kBuffer words at a time).
  std::uint64_t next() {
    if (pos_ == kBuffer) {
      fill_bits(buf_, kBuffer / kLanes);
      pos_ = 0;
    }
    return buf_[pos_++];
  }
  /// Uniform in (0, 1) with 53 random bits, as Rng::uniform().
  double uniform() { return (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53; }

  /// Words of save_state(): each lane's four state words (word w of lane l at w kLanes + l), the buffer of
  /// drawn words and the position of the next one in it (0 to kBuffer).
  static constexpr int kStateWords = 4 * kLanes + kBuffer + 1;
  /// The whole state, buffered words included: restore_state() of it continues the same sequence.
  void save_state(std::uint64_t* out) const {
    for (int w = 0; w < 4; ++w)
      for (int l = 0; l < kLanes; ++l) out[w * kLanes + l] = s_[w][l];
    std::memcpy(out + 4 * kLanes, buf_, sizeof buf_);
    out[kStateWords - 1] = static_cast<std::uint64_t>(pos_);
  }
  /// Sets the state from kStateWords words of save_state(). Returns false and changes nothing for words no
  /// generator has: a lane with an all-zero state (a fixed point) or a position beyond kBuffer.
  bool restore_state(const std::uint64_t* in) {
    if (in[kStateWords - 1] > static_cast<std::uint64_t>(kBuffer)) return false;
    for (int l = 0; l < kLanes; ++l)
      if ((in[l] | in[kLanes + l] | in[2 * kLanes + l] | in[3 * kLanes + l]) == 0) return false;
    for (int w = 0; w < 4; ++w)
      for (int l = 0; l < kLanes; ++l) s_[w][l] = in[w * kLanes + l];
    std::memcpy(buf_, in + 4 * kLanes, sizeof buf_);
    pos_ = static_cast<int>(in[kStateWords - 1]);
    return true;
  }

  /// n standard normal variates by the ziggurat method (Marsaglia and Tsang 2000, 256 layers): exact
  /// sampling of N(0, 1) (rectangles accepted directly, wedges by rejection, the tail by Marsaglia's 1964
  /// method); about 1.01 words per variate.
  void fill_normal(double* out, int n) {
    const auto& z = detail::ZigguratNormal::get();
    // The rectangle test (normal()'s first) on the buffer with the position in a register; a word it rejects
    // goes to normal(), which draws it again: the same words give the same variates as a loop of normal().
    for (int k = 0; k < n;) {
      if (pos_ == kBuffer) {
        fill_bits(buf_, kBuffer / kLanes);
        pos_ = 0;
      }
      int p = pos_;
      const int end = kBuffer - p < n - k ? kBuffer : p + (n - k);
      for (; p < end; ++p) {
        int i;
        const double x = candidate(z, buf_[p], i);
        if (!(std::abs(x) < z.x[i + 1])) break;
        out[k++] = x;
      }
      pos_ = p;
      if (p < end) out[k++] = normal(z);
    }
  }

 private:
#ifdef NLOSLOC_RNG_AVX2
  /// fill_bits with the four lanes in one 256-bit register (xoshiro256++ on each 64-bit lane, as above).
  __attribute__((target("avx2"))) void fill_bits_avx2(std::uint64_t* out, int n_quads) {
    __m256i s0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s_[0]));
    __m256i s1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s_[1]));
    __m256i s2 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s_[2]));
    __m256i s3 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s_[3]));
    for (int j = 0; j < n_quads; ++j) {
      const __m256i a = _mm256_add_epi64(s0, s3);
      const __m256i r =
          _mm256_add_epi64(_mm256_or_si256(_mm256_slli_epi64(a, 23), _mm256_srli_epi64(a, 41)), s0);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 4 * j), r);
      const __m256i t = _mm256_slli_epi64(s1, 17);
      s2 = _mm256_xor_si256(s2, s0);
      s3 = _mm256_xor_si256(s3, s1);
      s1 = _mm256_xor_si256(s1, s2);
      s0 = _mm256_xor_si256(s0, s3);
      s2 = _mm256_xor_si256(s2, t);
      s3 = _mm256_or_si256(_mm256_slli_epi64(s3, 45), _mm256_srli_epi64(s3, 19));
    }
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(s_[0]), s0);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(s_[1]), s1);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(s_[2]), s2);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(s_[3]), s3);
  }
#endif
  /// The ziggurat's point for word b: layer i from its low 8 bits, x = u x[i] with u in [-1, 1) from the
  /// other 52.
  static double candidate(const detail::ZigguratNormal& z, std::uint64_t b, int& i) {
    i = static_cast<int>(b & 0xff);
    return (2.0 * (static_cast<double>(b >> 12) * 0x1.0p-52) - 1.0) * z.x[i];
  }
  double normal(const detail::ZigguratNormal& z) {
    for (;;) {
      int i;
      const double x = candidate(z, next(), i);
      if (std::abs(x) < z.x[i + 1]) return x;  // inside the layer's rectangle
      if (i == 0) {                            // base layer beyond R: the tail (Marsaglia 1964)
        double xt, yt;
        do {
          xt = -std::log(uniform()) / detail::ZigguratNormal::kR;
          yt = -std::log(uniform());
        } while (2.0 * yt < xt * xt);
        return x < 0.0 ? -(detail::ZigguratNormal::kR + xt) : detail::ZigguratNormal::kR + xt;  // x[0] > 0
      }
      if (z.fx[i + 1] + (z.fx[i] - z.fx[i + 1]) * uniform() < std::exp(-0.5 * x * x)) return x;  // wedge
    }
  }
  static void to_uniform(const std::uint64_t* in, double* out, int n) {
#ifdef NLOSLOC_RNG_SSE2
    const __m128i one = _mm_set1_epi64x(0x3FF0000000000000LL);
    const __m128d off = _mm_set1_pd(1.0 - 0x1.0p-53);
    for (int k = 0; k + 1 < n; k += 2) {
      const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + k));
      const __m128d v = _mm_castsi128_pd(_mm_or_si128(_mm_srli_epi64(b, 12), one));  // 1 + k 2^-52
      _mm_storeu_pd(out + k, _mm_sub_pd(v, off));                                    // (k + 1/2) 2^-52
    }
#else
    for (int k = 0; k < n; ++k) {
      const std::uint64_t b = (in[k] >> 12) | 0x3FF0000000000000ULL;
      double v;
      std::memcpy(&v, &b, sizeof v);
      out[k] = v - (1.0 - 0x1.0p-53);
    }
#endif
  }
  std::uint64_t s_[4][kLanes];
  std::uint64_t buf_[kBuffer] = {};
  int pos_ = kBuffer;
  bool wide_ = false;  // refills on AVX2 (use_avx2)
};

}  // namespace nlosloc
