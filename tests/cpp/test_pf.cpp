// Joint particle filter (Huerta Sec. VI-B) fast paths and the bulk generator behind them: BatchRng lanes are
// jumped copies of an Rng, its uniforms and ziggurat normals have the right distribution, the PF's
// square-root-free switching test (eqs. 10, 15-18) flips conditions with the closed-form probabilities, and
// the lazily computed covariance and normalised log weights equal their definitions.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "nlosloc/core/logsumexp.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/rbpf/pf.hpp"

using namespace nlosloc;
using namespace nlosloc::rbpf;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
namespace nn = nlosloc::noise;
namespace si = nlosloc::situation;

namespace {
MatX hexagon() {
  MatX a(6, 2);
  for (int b = 0; b < 6; ++b) {
    a(b, 0) = 3000 * std::cos(b * kPi / 3);
    a(b, 1) = 3000 * std::sin(b * kPi / 3);
  }
  return a;
}
MeasurementStack h2_stack() {
  MeasurementStack st(ConstantVelocityClock2::layout(), hexagon(), 2);
  for (int b = 0; b < 6; ++b)
    st.add_rtoa(b, {nn::Normal(0, std::sqrt(10.0)), nn::Rayleigh::from_variance(5000)});
  return st;
}
/// The H2 model of the PF tests: motion, sight chains, quality, RTOA stack, initial belief.
struct H2Setup {
  ConstantVelocityClock2 motion{0.01, 1.0, 1e-2};
  si::SightProcess proc{si::SightModel::speed_dependent(10, 10, 0.01), 6};
  si::QualityModel q{{nn::Beta(4, 1.5), nn::Beta(1.5, 4)}};
  MeasurementStack st = h2_stack();
  Gaussian<6> g{Vec<6>::Zero(), Vec<6>(25, 25, 10, 1, 1, 10).asDiagonal().toDenseMatrix()};
};
double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }
}  // namespace

TEST_CASE("BatchRng lanes are the parent Rng jumped 1 to 4 times", "[pf][random]") {
  Rng parent(42, 7);
  BatchRng batch(parent);
  std::vector<std::uint64_t> out(4 * 100);
  batch.fill_bits(out.data(), 100);
  for (int l = 0; l < BatchRng::kLanes; ++l) {
    Rng lane = parent;
    for (int j = 0; j <= l; ++j) lane.jump();
    for (int j = 0; j < 100; ++j) CHECK(out[static_cast<std::size_t>(4 * j + l)] == lane());
  }
  // the parent is not advanced, and a jumped copy does not reproduce the parent's sequence
  Rng a(42, 7), b(42, 7);
  b.jump();
  CHECK(a() != b());
  CHECK(parent() == Rng(42, 7)());
}

TEST_CASE("BatchRng on AVX2 refills gives the same words, uniforms and normals", "[pf][random]") {
  BatchRng narrow(Rng(11, 3)), wide(Rng(11, 3));
  wide.use_avx2(true);
  CHECK(wide.uses_avx2() == nlosloc::detail::cpu_has_avx2());
  CHECK_FALSE(narrow.uses_avx2());
  std::vector<std::uint64_t> wa(4 * 37), wb(4 * 37);
  std::vector<double> a(1000), b(1000);
  for (int r = 0; r < 300; ++r) {
    const int n = 1 + (r * 53) % 700;
    narrow.fill_normal(a.data(), n);
    wide.fill_normal(b.data(), n);
    REQUIRE(std::equal(a.begin(), a.begin() + n, b.begin()));
    const int nu = 4 * (r % 41);
    narrow.fill_uniform(a.data(), nu);
    wide.fill_uniform(b.data(), nu);
    REQUIRE(std::equal(a.begin(), a.begin() + nu, b.begin()));
    narrow.fill_bits(wa.data(), 1 + r % 37);
    wide.fill_bits(wb.data(), 1 + r % 37);
    REQUIRE(std::equal(wa.begin(), wa.begin() + 4 * (1 + r % 37), wb.begin()));
    REQUIRE(narrow.uniform() == wide.uniform());
    REQUIRE(narrow.next() == wide.next());
  }
  wide.use_avx2(false);
  CHECK_FALSE(wide.uses_avx2());
}

TEST_CASE("BatchRng::fill_normal is the ziggurat of its words, rejections and tail included",
          "[pf][random]") {
  // Reference: Marsaglia and Tsang (2000) on the generator's own words, one variate at a time (next() and
  // uniform() of a copy). fill_normal tests the rectangles on its buffer first: the same words must give
  // the same variates, across refills and wherever a word is rejected.
  const auto& z = nlosloc::detail::ZigguratNormal::get();
  auto reference = [&z](BatchRng& g, int& rejected, int& tail) {
    for (;;) {
      const std::uint64_t w = g.next();
      const int i = static_cast<int>(w & 0xff);
      const double u = 2.0 * (static_cast<double>(w >> 12) * 0x1.0p-52) - 1.0;
      const double x = u * z.x[i];
      if (std::abs(x) < z.x[i + 1]) return x;
      ++rejected;
      if (i == 0) {
        ++tail;
        const double R = nlosloc::detail::ZigguratNormal::kR;
        double xt, yt;
        do {
          xt = -std::log(g.uniform()) / R;
          yt = -std::log(g.uniform());
        } while (2.0 * yt < xt * xt);
        return u < 0.0 ? -(R + xt) : R + xt;
      }
      if (z.fx[i + 1] + (z.fx[i] - z.fx[i + 1]) * g.uniform() < std::exp(-0.5 * x * x)) return x;
    }
  };
  for (const bool avx2 : {false, true}) {
    BatchRng g(Rng(2024, 1)), ref(Rng(2024, 1));
    g.use_avx2(avx2);
    (void)g.next();  // start mid-buffer
    (void)ref.next();
    int rejected = 0, tail = 0, count = 0;
    std::vector<double> out(5000);
    for (int r = 0; r < 80; ++r) {
      const int n = r % 2 == 0 ? 5000 : 1 + (r * 7) % 100;
      g.fill_normal(out.data(), n);
      for (int k = 0; k < n; ++k, ++count)
        REQUIRE(out[static_cast<std::size_t>(k)] == reference(ref, rejected, tail));
    }
    CHECK(count > 200000);
    CHECK(rejected > 500);  // about 1% of the words: wedges and tails were exercised
    CHECK(tail > 5);
    CHECK(g.next() == ref.next());  // the same words consumed
  }
}

TEST_CASE("Rng and BatchRng: save_state / restore_state continue the same sequence", "[pf][random]") {
  Rng a(9, 2);
  (void)a.normal();  // leaves a kept normal variate: part of the state
  std::uint64_t words[Rng::kStateWords];
  a.save_state(words);
  CHECK(words[4] == 1);
  Rng b(1, 1);
  REQUIRE(b.restore_state(words));
  CHECK(a.normal() == b.normal());  // the kept variate
  for (int j = 0; j < 50; ++j) CHECK(a() == b());
  BatchRng ba(Rng(5, 0)), bb(Rng(6, 0));
  (void)ba.uniform();  // part of the buffer used: the position is part of the state
  std::uint64_t bw[BatchRng::kStateWords];
  ba.save_state(bw);
  CHECK(bw[BatchRng::kStateWords - 1] == 1);
  REQUIRE(bb.restore_state(bw));
  double na[200], nb[200];
  ba.fill_normal(na, 200);
  bb.fill_normal(nb, 200);
  CHECK(std::equal(na, na + 200, nb));
  CHECK(ba.uniform() == bb.uniform());
  // words no generator has are refused, and change nothing
  std::uint64_t zero[Rng::kStateWords] = {};
  CHECK_FALSE(b.restore_state(zero));
  words[4] = 2;  // the kept normal's flag is 0 or 1
  CHECK_FALSE(b.restore_state(words));
  bw[BatchRng::kStateWords - 1] = BatchRng::kBuffer + 1;
  CHECK_FALSE(bb.restore_state(bw));
  bw[BatchRng::kStateWords - 1] = 0;
  for (int w = 0; w < 4; ++w) bw[w * BatchRng::kLanes + 2] = 0;  // lane 2 all zero
  CHECK_FALSE(bb.restore_state(bw));
  CHECK(a() == b());
  CHECK(ba.uniform() == bb.uniform());
}

TEST_CASE("pf_simd_lanes: the widest packet of the instruction set this file is compiled for", "[pf]") {
  // nlosloc_native_tests compiles this file with -march=native: on an AVX-512 or AVX machine this checks
  // that the PF's loops there really run on the wider packets.
#if defined(__AVX512F__)
  CHECK(pf_simd_lanes() == 8);
#elif defined(__AVX__)
  CHECK(pf_simd_lanes() == 4);
#elif defined(__SSE2__) || defined(__ARM_NEON)
  CHECK(pf_simd_lanes() == 2);
#else
  CHECK(pf_simd_lanes() >= 1);
#endif
  CHECK(rbpf::detail::kPfLanes * static_cast<int>(sizeof(double)) ==
        static_cast<int>(sizeof(rbpf::detail::PfPacket)));
}

TEST_CASE("BatchRng uniforms are in (0, 1) with the uniform moments", "[pf][random]") {
  BatchRng r(Rng(3));
  const int n = 1 << 20;
  std::vector<double> u(static_cast<std::size_t>(n));
  r.fill_uniform(u.data(), n);
  double m = 0.0, m2 = 0.0;
  for (double v : u) {
    REQUIRE(v > 0.0);
    REQUIRE(v < 1.0);
    // (k + 1/2) 2^-52: 2^52 u - 1/2 is an integer
    const double k = std::ldexp(v, 52) - 0.5;
    REQUIRE(k == std::floor(k));
    m += v;
    m2 += v * v;
  }
  m /= n;
  m2 /= n;
  CHECK_THAT(m, WithinAbs(0.5, 5.0 * std::sqrt(1.0 / 12.0 / n)));
  CHECK_THAT(m2 - m * m, WithinAbs(1.0 / 12.0, 1e-3));
}

TEST_CASE("BatchRng ziggurat normals: moments, tail mass and Kolmogorov-Smirnov", "[pf][random]") {
  BatchRng r(Rng(11));
  const int n = 2000000;
  std::vector<double> z(static_cast<std::size_t>(n));
  r.fill_normal(z.data(), n);
  double m1 = 0.0, m2 = 0.0, m3 = 0.0, m4 = 0.0;
  int tail = 0;
  for (double v : z) {
    m1 += v;
    m2 += v * v;
    m3 += v * v * v;
    m4 += v * v * v * v;
    if (std::abs(v) > nlosloc::detail::ZigguratNormal::kR) ++tail;
  }
  m1 /= n;
  m2 /= n;
  m3 /= n;
  m4 /= n;
  const double sn = 1.0 / std::sqrt(static_cast<double>(n));
  CHECK_THAT(m1, WithinAbs(0.0, 5.0 * sn));
  CHECK_THAT(m2, WithinAbs(1.0, 5.0 * std::sqrt(2.0) * sn));
  CHECK_THAT(m3, WithinAbs(0.0, 5.0 * std::sqrt(15.0) * sn));
  CHECK_THAT(m4, WithinAbs(3.0, 5.0 * std::sqrt(96.0) * sn));
  // the tail sampler (beyond R) carries its exact mass 2 (1 - Phi(R))
  const double pt = 2.0 * (1.0 - normal_cdf(nlosloc::detail::ZigguratNormal::kR));
  CHECK_THAT(static_cast<double>(tail), WithinAbs(n * pt, 5.0 * std::sqrt(n * pt)));
  // KS distance against Phi (critical value at level 1e-4 is about 2.0 / sqrt(n))
  std::sort(z.begin(), z.end());
  double ks = 0.0;
  for (int i = 0; i < n; i += 7) {
    const double f = normal_cdf(z[static_cast<std::size_t>(i)]);
    ks = std::max(
        {ks, std::abs(f - static_cast<double>(i) / n), std::abs(f - static_cast<double>(i + 1) / n)});
  }
  CHECK(ks < 2.0 * sn);
  // the ziggurat table closes: the top layer has area V too
  const auto& t = nlosloc::detail::ZigguratNormal::get();
  CHECK_THAT(t.x[255] * (1.0 - t.fx[255]), WithinRel(nlosloc::detail::ZigguratNormal::kV, 1e-6));
}

TEST_CASE("joint PF: sight switches follow the closed-form probabilities of eqs. 15, 17 and 18", "[pf]") {
  // one step from a prior with fast mobiles (sigma_v = 100 m/s, so w dt is about 1 m): the number of
  // condition changes over all particles and anchors must match sum p(w_i, s_i) (Bernoulli counts, 5 sigma).
  for (auto form : {si::SpeedModel::kSingle, si::SpeedModel::kMultiple, si::SpeedModel::kMemoryless}) {
    ConstantVelocityClock2 motion(0.01, 1.0, 1e-2);
    si::SightProcess proc(si::SightModel::speed_dependent(10, 30, 0.01, form), 6);
    si::QualityModel q{{nn::Beta(4, 1.5), nn::Beta(1.5, 4)}};
    const MeasurementStack st = h2_stack();
    Gaussian<6> g;
    g.mean << 100, -200, 0, 0, 0, 0;
    g.cov = Vec<6>(1e6, 1e6, 10, 1e4, 1e4, 10).asDiagonal();
    PfOptions po;
    po.num_particles = 100001;  // odd: the scalar tails run too
    po.ess_threshold = 0.0;
    po.threads = 2;
    po.seed = 5;
    ParticleFilter<ConstantVelocityClock2> pf(motion, st, proc, q, g, po);
    const MatX x0 = pf.particles();
    const Eigen::MatrixXi s0 = pf.situations();
    VecX y = VecX::Constant(6, std::numeric_limits<double>::quiet_NaN());  // no ranges: prior only
    pf.step(y, VecX::Constant(6, std::numeric_limits<double>::quiet_NaN()));
    const Eigen::MatrixXi s1 = pf.situations();
    double expected = 0.0, var = 0.0;
    int flips = 0;
    for (int i = 0; i < po.num_particles; ++i)
      for (int b = 0; b < 6; ++b) {
        const double w = si::transversal_speed(x0.col(i).head<2>(), x0.col(i).segment<2>(3),
                                               st.anchors().row(b).transpose());
        const double p = si::speed_switch_probability(proc.model(b), s0(b, i), w);
        expected += p;
        var += p * (1.0 - p);
        flips += s0(b, i) != s1(b, i) ? 1 : 0;
      }
    INFO("form " << static_cast<int>(form) << ": " << flips << " flips, expected " << expected);
    CHECK(expected > 1000.0);
    CHECK(std::abs(flips - expected) < 5.0 * std::sqrt(var));
  }
}

TEST_CASE("joint PF: lazy covariance and normalised log weights equal their definitions", "[pf]") {
  const H2Setup h;
  const auto& [motion, proc, q, st, g] = h;
  Rng rng(2);
  for (int threads : {1, 2}) {
    PfOptions po;
    po.num_particles = 3001;
    po.ess_threshold = 0.0;
    po.threads = threads;
    ParticleFilter<ConstantVelocityClock2> pf(motion, st, proc, q, g, po);
    for (int k = 0; k < 3; ++k) {
      VecX y(6), o(6);
      for (int b = 0; b < 6; ++b) {
        y(b) = 3000.0 + 3.0 * rng.normal();
        o(b) = 0.7;
      }
      y(2) = std::numeric_limits<double>::quiet_NaN();  // a missing row: anchor 2's quality still counts
      const PfStepInfo info = pf.step(y, o);
      const VecX& lw = pf.log_weights();
      CHECK_THAT(log_sum_exp(lw), WithinAbs(0.0, 1e-9));
      const VecX w = lw.array().exp();
      const MatX X = pf.particles();
      const Vec<6> m = X * w;
      const MatX C = (X.colwise() - m) * w.asDiagonal() * (X.colwise() - m).transpose();
      CHECK((pf.estimate() - m).cwiseAbs().maxCoeff() < 1e-9);
      CHECK((pf.covariance() - C).cwiseAbs().maxCoeff() < 1e-7 * std::max(1.0, C.cwiseAbs().maxCoeff()));
      CHECK_THAT(info.ess, WithinRel(1.0 / w.squaredNorm(), 1e-9));
      VecX p1 = VecX::Zero(6);
      const Eigen::MatrixXi S = pf.situations();
      for (int i = 0; i < po.num_particles; ++i)
        for (int b = 0; b < 6; ++b) p1(b) += S(b, i) * w(i);
      CHECK((pf.situation_probabilities().col(1) - p1).cwiseAbs().maxCoeff() < 1e-9);
    }
  }
}

TEST_CASE("joint PF: the resampled set is the systematic resampling of the weighted one", "[pf]") {
  // Two filters with one seed draw the same weighted set in their first step (the resampling draws from
  // another stream); the one that resamples (ess_threshold = 1) must hold copies of those particles, each
  // i about M w_i times (systematic: |copies - M w_i| < 1), with their situations. Its copy is deferred to
  // the next pass (ancestors), so this also checks particles(), situations() and the covariance of the
  // weighted set (computed on request) through them.
  const H2Setup h;
  const auto& [motion, proc, q, st, g] = h;
  for (int threads : {1, 2}) {
    PfOptions keep, res;
    keep.num_particles = res.num_particles = 3000;
    keep.threads = res.threads = threads;
    keep.ess_threshold = 0.0;
    res.ess_threshold = 1.0;
    ParticleFilter<ConstantVelocityClock2> a(motion, st, proc, q, g, keep), b(motion, st, proc, q, g, res);
    VecX y(6), o = VecX::Constant(6, 0.7);
    Rng rng(5);
    for (int k = 0; k < 2; ++k) {
      for (int i = 0; i < 6; ++i) y(i) = 3000.0 + 3.0 * rng.normal();
      const PfStepInfo ia = a.step(y, o), ib = b.step(y, o);
      REQUIRE(ib.resampled);
      if (k == 0) {
        CHECK(ia.log_likelihood == ib.log_likelihood);
        const MatX XA = a.particles(), XB = b.particles();
        const Eigen::MatrixXi SA = a.situations(), SB = b.situations();
        const VecX w = a.log_weights().array().exp();
        std::vector<std::pair<double, int>> byx;  // a's particles by first component (distinct reals)
        for (int i = 0; i < XA.cols(); ++i) byx.emplace_back(XA(0, i), i);
        std::sort(byx.begin(), byx.end());
        std::vector<int> copies(static_cast<std::size_t>(XA.cols()), 0);
        bool all_found = true, same = true;
        for (int j = 0; j < XB.cols(); ++j) {
          const auto it = std::lower_bound(byx.begin(), byx.end(), std::make_pair(XB(0, j), -1));
          if (it == byx.end() || it->first != XB(0, j)) {
            all_found = false;
            continue;
          }
          ++copies[static_cast<std::size_t>(it->second)];
          same = same && XB.col(j) == XA.col(it->second) && SB.col(j) == SA.col(it->second);
        }
        CHECK(all_found);
        CHECK(same);
        double worst = 0.0;
        for (int i = 0; i < XA.cols(); ++i)
          worst = std::max(worst, std::abs(copies[static_cast<std::size_t>(i)] - 3000.0 * w(i)));
        CHECK(worst < 1.0 + 1e-9);
        CHECK((b.log_weights().array() == -std::log(3000.0)).all());
        // b's covariance is that of the weighted set, computed after its resampling (deferred copy)
        CHECK((b.covariance() - a.covariance()).cwiseAbs().maxCoeff() <=
              1e-9 * a.covariance().cwiseAbs().maxCoeff());
      } else {
        // the next pass moved the gathered ancestors: b's new estimate is finite and near a's (measured
        // 1.6 mm on one thread, 2.1 mm on two; a's estimate is 1.02 m from the prior mean; was < 1 m)
        CHECK((b.estimate() - a.estimate()).head<2>().norm() < 5e-3);
      }
    }
  }
}

TEST_CASE("joint PF: a rejected step changes nothing, and the next step is that of a clean filter", "[pf]") {
  const H2Setup h;
  const auto& [motion, proc, q, st, g] = h;
  for (int threads : {1, 2}) {
    for (auto rs : {PfResampling::kSystematic, PfResampling::kMergeSelect}) {
      PfOptions po;
      po.num_particles = 2000;
      po.threads = threads;
      po.resampling = rs;
      po.seed = 4;
      ParticleFilter<ConstantVelocityClock2> f(motion, st, proc, q, g, po), clean(motion, st, proc, q, g, po);
      Rng rng(3);
      VecX y(6), o = VecX::Constant(6, 0.7);
      auto draw = [&] {
        for (int b = 0; b < 6; ++b) y(b) = 3000.0 + 3.0 * rng.normal();
      };
      for (int k = 0; k < 2; ++k) {
        draw();
        f.step(y, o);
        clean.step(y, o);
      }
      const MatX X0 = f.particles();
      const Eigen::MatrixXi S0 = f.situations();
      const VecX lw0 = f.log_weights();
      const Vec<6> e0 = f.estimate();
      const Mat<6, 6> C0 = f.covariance();
      const double t0 = f.time();
      VecX bad = y;
      bad(0) = -1e200;  // far below every predicted range: zero density for every particle (both conditions)
      CHECK_THROWS_AS(f.step(bad, o), NumericalError);
      CHECK(f.particles() == X0);
      CHECK(f.situations() == S0);
      CHECK(f.log_weights() == lw0);
      CHECK(f.estimate() == e0);
      CHECK(f.covariance() == C0);
      CHECK(f.time() == t0);
      // an impossible quality statistic is an input error, found before anything moves
      VecX ob = o;
      ob(3) = 1.5;
      CHECK_THROWS_WITH(f.step(y, ob), "o: statistic of anchor 3 has zero density under every condition");
      CHECK(f.particles() == X0);
      // the generators were restored too: the next steps are those of the filter that never saw the bad data
      for (int k = 0; k < 2; ++k) {
        draw();
        f.step(y, o);
        clean.step(y, o);
        CHECK(f.particles() == clean.particles());
        CHECK(f.log_weights() == clean.log_weights());
      }
    }
  }
}

namespace {
/// Same particles, weights, summaries and time, exactly.
bool same_pf(const ParticleFilter<ConstantVelocityClock2>& a,
             const ParticleFilter<ConstantVelocityClock2>& b) {
  return a.particles() == b.particles() && a.situations() == b.situations() &&
         a.log_weights() == b.log_weights() && a.estimate() == b.estimate() &&
         a.covariance() == b.covariance() && a.situation_probabilities() == b.situation_probabilities() &&
         a.time() == b.time();
}
}  // namespace

TEST_CASE("joint PF: a restored twin steps on bit for bit, resampled or not", "[pf]") {
  const H2Setup h;
  const auto& [motion, proc, q, st, g] = h;
  const Gaussian<6> elsewhere{Vec<6>::Constant(40.0), Mat<6, 6>::Identity()};
  struct Case {
    PfResampling rs;
    double ess;
  };
  // never resampled (the normalisation deferred), resampled every step (the copy deferred), merge-select
  for (const Case c : {Case{PfResampling::kSystematic, 0.0}, Case{PfResampling::kSystematic, 1.0},
                       Case{PfResampling::kMergeSelect, 0.5}})
    for (int threads : {1, 2}) {
      CAPTURE(static_cast<int>(c.rs), c.ess, threads);
      PfOptions po;
      po.num_particles = 2000;  // 15 blocks of 128 and a tail of 80
      po.threads = threads;
      po.resampling = c.rs;
      po.ess_threshold = c.ess;
      po.seed = 4;
      ParticleFilter<ConstantVelocityClock2> a(motion, st, proc, q, g, po);
      po.seed = 5;  // other generators and particles: restore() must replace them all
      ParticleFilter<ConstantVelocityClock2> b(motion, st, proc, q, elsewhere, po);
      Rng rng(3);
      VecX y(6), o(6);
      auto draw = [&] {
        for (int j = 0; j < 6; ++j) {
          y(j) = 3000.0 + 3.0 * rng.normal() + (j == 1 ? 400.0 : 0.0);  // anchor 1 NLOS
          o(j) = j == 1 ? 0.3 : 0.7;
        }
      };
      b.restore(a.save());  // straight after the reset
      REQUIRE(same_pf(a, b));
      for (int k = 0; k < 2; ++k) {
        draw();
        a.step(y, o);
        b.step(y, o);
      }
      CHECK(same_pf(a, b));
      for (int k = 0; k < 5; ++k) {
        draw();
        a.step(y, o);
      }
      const PfSnapshot s = a.save();
      CHECK(s.step == 7);
      CHECK(s.generators.size() == static_cast<std::size_t>(threads * PfSnapshot::kGeneratorWords));
      b.restore(s);
      REQUIRE(same_pf(a, b));
      int differing = 0;
      for (int k = 0; k < 10; ++k) {
        draw();
        const PfStepInfo ia = a.step(y, o), ib = b.step(y, o);
        differing +=
            same_pf(a, b) && ia.log_likelihood == ib.log_likelihood && ia.merged == ib.merged ? 0 : 1;
      }
      CHECK(differing == 0);
    }
}

TEST_CASE("joint PF: the AVX2 pass steps bit for bit as the portable pass", "[pf]") {
  // Filters built with NLOSLOC_NO_AVX2=1 run the portable pass; the others the AVX2 build where the CPU
  // has it. Same seed, same data: particles, weights, summaries and step results must be identical.
  const H2Setup h;
  const auto& [motion, proc, q, st, g] = h;
  const char* before = std::getenv("NLOSLOC_NO_AVX2");
  const std::string saved = before != nullptr ? before : "";
  struct Case {
    PfResampling rs;
    double ess;
  };
  for (const Case c : {Case{PfResampling::kSystematic, 0.0}, Case{PfResampling::kSystematic, 0.6},
                       Case{PfResampling::kMergeSelect, 0.5}})
    for (int threads : {1, 2}) {
      CAPTURE(static_cast<int>(c.rs), c.ess, threads);
      PfOptions po;
      po.num_particles = 2001;  // 15 blocks of 128 and a tail of 81 (P4, Packet2d and scalar loops)
      po.threads = threads;
      po.resampling = c.rs;
      po.ess_threshold = c.ess;
      po.seed = 8;
      po.merge_threshold = c.rs == PfResampling::kMergeSelect ? 3.0 : -1.0;  // wide: groups to merge
      unsetenv("NLOSLOC_NO_AVX2");
      ParticleFilter<ConstantVelocityClock2> fast(motion, st, proc, q, g, po);
      setenv("NLOSLOC_NO_AVX2", "1", 1);
      ParticleFilter<ConstantVelocityClock2> portable(motion, st, proc, q, g, po);
      setenv("NLOSLOC_NO_AVX2", "0", 1);  // "0" is unset
      CHECK(ParticleFilter<ConstantVelocityClock2>(motion, st, proc, q, g, po).uses_avx2() ==
            rbpf::detail::cpu_has_avx2());
      CHECK(fast.uses_avx2() == rbpf::detail::cpu_has_avx2());
      CHECK_FALSE(portable.uses_avx2());
      if (!fast.uses_avx2()) WARN("no AVX2 on this CPU (or build): both filters run the portable pass");
      Rng rng(11);
      VecX y(6), o(6);
      int merged = 0, resampled = 0, differing = 0;
      for (int k = 0; k < 12; ++k) {
        for (int j = 0; j < 6; ++j) {
          y(j) = 3000.0 + 3.0 * rng.normal() + (j == 2 ? 300.0 : 0.0);  // anchor 2 NLOS (Rayleigh rows)
          o(j) = j == 2 ? 0.25 : 0.75;
        }
        if (k == 5) y(4) = std::numeric_limits<double>::quiet_NaN();  // a missing row
        const PfStepInfo a = fast.step(y, o), b = portable.step(y, o);
        merged += a.merged;
        resampled += a.resampled ? 1 : 0;
        differing += same_pf(fast, portable) && a.log_likelihood == b.log_likelihood && a.ess == b.ess &&
                             a.merged == b.merged && a.resampled == b.resampled
                         ? 0
                         : 1;
      }
      CHECK(differing == 0);
      if (c.rs == PfResampling::kMergeSelect) CHECK(merged > 0);  // the merge ran on groups
      if (c.ess > 0.0) CHECK(resampled > 0);
    }
  if (before != nullptr)
    setenv("NLOSLOC_NO_AVX2", saved.c_str(), 1);
  else
    unsetenv("NLOSLOC_NO_AVX2");
}

TEST_CASE("PF bucket keys: four at a time equal the one-particle key, bit for bit", "[pf]") {
  // Cells of either sign, on and off integers, |x / w| at and beyond 2^51 (the vector floor's limit), NaN
  // and infinities (clamped), several widths; 203 particles: blocks of four and a tail of three.
  const int n = 203, B = 6;
  Rng rng(5);
  std::vector<std::uint8_t> s(static_cast<std::size_t>(B * n));
  for (auto& v : s) v = static_cast<std::uint8_t>(rng.below(2));
  const double specials[] = {0.0,
                             -0.0,
                             2.5,
                             -2.5,
                             3.0,
                             -3.0,
                             1e300,
                             -1e300,
                             2251799813685247.0,
                             2251799813685248.0,
                             -2251799813685248.0,
                             4.7e18,
                             -4.7e18,
                             std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(),
                             1e-320};
  for (const double inv : {1.0, 1.0 / 3.7, 1e-3, 1e9, 0.0}) {
    CAPTURE(inv);
    for (const int N : {4, 6}) {
      std::vector<double> x(static_cast<std::size_t>(N * n));
      for (std::size_t i = 0; i < x.size(); ++i)
        x[i] =
            i % 13 == 5 ? specials[(i / 13) % (sizeof specials / sizeof specials[0])] : 50.0 * rng.normal();
      std::vector<std::uint32_t> got(static_cast<std::size_t>(n));
      int differing = 0;
      if (N == 4) {
        rbpf::detail::pf_bucket_keys<4>(s.data(), n, B, x.data(), n, inv, n, got.data());
        for (int j = 0; j < n; ++j)
          differing += got[static_cast<std::size_t>(j)] ==
                               rbpf::detail::pf_bucket_key<4>(s.data(), n, B, x.data(), n, inv, j)
                           ? 0
                           : 1;
      } else {
        rbpf::detail::pf_bucket_keys<6>(s.data(), n, B, x.data(), n, inv, n, got.data());
        for (int j = 0; j < n; ++j)
          differing += got[static_cast<std::size_t>(j)] ==
                               rbpf::detail::pf_bucket_key<6>(s.data(), n, B, x.data(), n, inv, j)
                           ? 0
                           : 1;
      }
      CHECK(differing == 0);
    }
  }
  // the one-particle key by hand: B = 1, N = 1, s = 1, x = -2.5 with w = 1 (cell -3)
  const std::uint8_t s1 = 1;
  const double x1 = -2.5;
  std::uint64_t h = (std::uint64_t{1} + 1) * 0xBF58476D1CE4E5B9ULL;
  h ^= static_cast<std::uint64_t>(std::int64_t{-3}) * 0x9E3779B97F4A7C15ULL;
  h ^= h >> 31;
  h *= 0x9E3779B97F4A7C15ULL;
  CHECK(rbpf::detail::pf_bucket_key<1>(&s1, 1, 1, &x1, 1, 1.0, 0) == static_cast<std::uint32_t>(h >> 32));
}

#ifdef NLOSLOC_PF_AVX2_DISPATCH
TEST_CASE("PF exp on four lanes equals Eigen's SSE2 pexp bit for bit where the result is normal", "[pf]") {
  // The AVX2 pass's weights exp(lw - max) take arguments in (-708, 0]: uniform there, log-uniform towards 0,
  // and multiples of ln 2 / 2 (the range reduction's boundaries), each with its neighbours.
  namespace pk = rbpf::detail::pk;
  Rng rng(9);
  std::vector<double> v = {0.0, -0.0, -1e-300, -5e-324, -707.9999999, -707.5, -0.5, -1.0};
  for (int i = 0; i < 100000; ++i) v.push_back(-708.0 * rng.uniform());
  for (int i = 0; i < 20000; ++i) v.push_back(-std::pow(10.0, -300.0 * rng.uniform() + 2.0));
  for (int k = 1; k < 2040; ++k) {
    const double a = -k * 0.34657359027997264;
    if (a > -708.0) {
      v.push_back(a);
      v.push_back(std::nextafter(a, 0.0));
      v.push_back(std::nextafter(a, -1e9));
    }
  }
  while (v.size() % 4 != 0) v.push_back(-1.0);
  int differing = 0;
  for (std::size_t i = 0; i < v.size(); i += 4) {
    rbpf::detail::P4 a;
    std::memcpy(&a.v, &v[i], sizeof a.v);
    const rbpf::detail::P4 got = pk::exp(a);
    double want[4];
    Eigen::internal::pstoreu(want,
                             Eigen::internal::pexp(Eigen::internal::ploadu<rbpf::detail::PfPacket>(&v[i])));
    Eigen::internal::pstoreu(
        want + 2, Eigen::internal::pexp(Eigen::internal::ploadu<rbpf::detail::PfPacket>(&v[i + 2])));
    differing += std::memcmp(&got.v, want, sizeof want) == 0 ? 0 : 1;
  }
  CHECK(differing == 0);
  CHECK(v.size() > 125000);
}
#endif

TEST_CASE("joint PF restore: a bad snapshot is refused, naming the field, and changes nothing", "[pf]") {
  const H2Setup h;
  const auto& [motion, proc, q, st, g] = h;
  PfOptions po;
  po.num_particles = 300;
  po.threads = 2;
  ParticleFilter<ConstantVelocityClock2> f(motion, st, proc, q, g, po);
  VecX y = VecX::Constant(6, 3000.0), o = VecX::Constant(6, 0.7);
  f.step(y, o);
  const PfSnapshot good = f.save();
  const auto refused = [&](const std::function<void(PfSnapshot&)>& edit) {
    PfSnapshot s = good;
    edit(s);
    try {
      f.restore(s);
    } catch (const std::invalid_argument& e) {
      const PfSnapshot now = f.save();  // unchanged
      CHECK(now.particles == good.particles);
      CHECK(now.generators == good.generators);
      CHECK(now.step == good.step);
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  using Catch::Matchers::StartsWith;
  CHECK_THAT(refused([](PfSnapshot& s) { s.particles.conservativeResize(Eigen::NoChange, 299); }),
             StartsWith("snapshot.particles: expected shape (6, 300)"));
  CHECK_THAT(refused([](PfSnapshot& s) { s.particles(2, 7) = std::nan(""); }),
             StartsWith("snapshot.particles"));
  CHECK_THAT(refused([](PfSnapshot& s) { s.situations.resize(5, 300); }),
             StartsWith("snapshot.situations: expected shape (6, 300)"));
  CHECK(refused([](PfSnapshot& s) { s.situations(1, 3) = 2; }) ==
        "snapshot.situations: expected condition indices 0 to 1");
  CHECK_THAT(refused([](PfSnapshot& s) { s.log_weights.resize(3); }),
             StartsWith("snapshot.log_weights: expected shape (300, 1)"));
  CHECK_THAT(
      refused([](PfSnapshot& s) { s.log_weights.array() += 0.5; }),
      StartsWith("snapshot.log_weights: expected normalised log weights (log-sum-exp 0), got log-sum-exp"));
  CHECK(refused([](PfSnapshot& s) { s.log_weights[0] = std::nan(""); }) ==
        "snapshot.log_weights: expected finite values or -inf");
  CHECK(refused([](PfSnapshot& s) { s.situation_probabilities(4, 0) += 0.1; }) ==
        "snapshot.situation_probabilities: every row must hold probabilities (>= 0) summing to 1; row 4 does "
        "not");
  CHECK_THAT(refused([](PfSnapshot& s) { s.estimate(0) = std::nan(""); }), StartsWith("snapshot.estimate"));
  CHECK(refused([](PfSnapshot& s) { s.covariance(0, 1) += 1.0; }) ==
        "snapshot.covariance: expected a symmetric positive semi-definite matrix");
  CHECK(refused([](PfSnapshot& s) { s.covariance(2, 2) = -1.0; }) ==
        "snapshot.covariance: expected a symmetric positive semi-definite matrix");
  CHECK(refused([](PfSnapshot& s) { s.position_variance = -1.0; }) ==
        "snapshot.position_variance: expected a finite value >= 0");
  CHECK(refused([](PfSnapshot& s) { s.generators.pop_back(); }) ==
        "snapshot.generators: expected 87 words for each of the filter's 2 threads (174), got 173");
  // the second thread's BatchRng position beyond its buffer
  CHECK(refused([](PfSnapshot& s) { s.generators.back() = 65; }) ==
        "snapshot.generators: thread 1's words are no generator state (an all-zero state, or a flag or "
        "buffer position out of range)");
  CHECK(refused([](PfSnapshot& s) { s.time = std::nan(""); }) == "snapshot.time: expected a finite time (s)");
  CHECK(refused([](PfSnapshot& s) { s.step = -1; }) == "snapshot.step: expected >= 0, got -1");
  // a singular covariance (no spread along a direction) and a particle ruled out (-inf) are valid
  CHECK(refused([](PfSnapshot& s) {
          s.covariance.row(3).setZero();
          s.covariance.col(3).setZero();
          s.log_weights[7] = -std::numeric_limits<double>::infinity();
          s.log_weights.array() -= log_sum_exp(s.log_weights);
        }) == "accepted");
  CHECK(f.covariance()(3, 3) == 0.0);
}
