// No heap allocation in a filter step: built as its own executable with EIGEN_RUNTIME_NO_MALLOC, so any
// Eigen allocation inside step() aborts the test (Eigen's own check, not a timing or a guess), and with
// the global operator new replaced by a counting one, so std:: containers that grow are caught too.
// Eigen's check is an eigen_assert, which NDEBUG (set by every Release build) turns off: Eigen then
// allocates with std::malloc, unseen by the counting operator new below, and an allocation in step()
// passed. So asserts stay on in this test whatever the build type.
#undef NDEBUG
#define EIGEN_RUNTIME_NO_MALLOC  // main() is Catch2's, in the shared object tests/cpp/main.cpp
#include <atomic>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <new>

#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/filters/iukf.hpp"
#include "nlosloc/filters/kf.hpp"
#include "nlosloc/filters/ukf.hpp"
#include "nlosloc/mitigation/bias_augmented_ekf.hpp"
#include "nlosloc/mitigation/qp_bias_ekf.hpp"
#include "nlosloc/rbpf/pf.hpp"
#include "nlosloc/rbpf/rbpf.hpp"

// Counting allocator: every operator new in the process goes through here; counted only while armed.
namespace {
std::atomic<bool> g_armed{false};
std::atomic<long> g_news{0};
void* counted_new(std::size_t n) {
  if (g_armed.load(std::memory_order_relaxed)) g_news.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
}  // namespace
void* operator new(std::size_t n) { return counted_new(n); }
void* operator new[](std::size_t n) { return counted_new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_new(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_new(n);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

using namespace nlosloc;
namespace nn = nlosloc::noise;

namespace {
/// Forbids Eigen allocations and counts operator new calls in its scope (news() after it ends).
struct NoMalloc {
  NoMalloc() {
    g_news.store(0);
    g_armed.store(true);
    Eigen::internal::set_is_malloc_allowed(false);
  }
  ~NoMalloc() {
    Eigen::internal::set_is_malloc_allowed(true);
    g_armed.store(false);
  }
  static long news() { return g_news.load(); }
};

MeasurementStack stack_with_angles() {
  MatX anchors(3, 2);
  anchors << 0, 0, 8600, 0, 4300, 7500;
  MeasurementStack st(ConstantVelocity2::layout(), anchors, 2);
  for (int b = 0; b < 3; ++b) st.add_toa(b, {nn::Normal(0, 50), nn::Rayleigh::from_variance(2000.0)});
  st.add_aoa(0, {nn::Normal(0, 0.01), nn::Normal(0, 0.05)});
  st.add_tdoa(1, 2, {nn::Normal(0, 50), nn::Normal(0, 80)}, {nn::Normal(0, 50), nn::Normal(0, 80)});
  return st;
}

template <class F>
void run_without_malloc(F& f, int rows, int anchors) {
  VecX y(rows);
  y.setConstant(3000.0);
  y[3] = 0.7;         // the AOA row
  y[rows - 1] = NAN;  // a missing row
  VecXi s = VecXi::Zero(anchors);
  s[1] = 1;
  StepResult r;
  {
    NoMalloc guard;
    for (int k = 0; k < 5; ++k) r = f.step(y, s);
    f.predict();
  }
  CHECK(NoMalloc::news() == 0);
  CHECK(r.rows_used == rows - 1);
  CHECK(std::isfinite(r.log_likelihood));
}
}  // namespace

TEST_CASE("filter steps do not allocate", "[nomalloc]") {
  const ConstantVelocity2 motion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
  Gaussian<4> g;
  g.mean << 1000, 1000, 10, 15;
  g.cov = Vec<4>(2500, 2500, 100, 100).asDiagonal();
  const MeasurementStack st = stack_with_angles();
  Ukf<ConstantVelocity2> ukf(motion, st, g);
  UkfAugmented<ConstantVelocity2> aug(motion, st, g);
  Ekf<ConstantVelocity2> ekf(motion, st, g);
  run_without_malloc(ukf, st.rows(), st.num_anchors());
  run_without_malloc(aug, st.rows(), st.num_anchors());
  run_without_malloc(ekf, st.rows(), st.num_anchors());
  MatX H = MatX::Zero(2, 4);
  H(0, 0) = H(1, 1) = 1;
  Kf<ConstantVelocity2> kf(motion, H, MatX::Identity(2, 2), g);
  VecX y(2);
  y << 1000, NAN;
  {
    NoMalloc guard;
    for (int k = 0; k < 5; ++k) kf.step(y);
  }
  CHECK(NoMalloc::news() == 0);
  CHECK(kf.mean().allFinite());
}

namespace {
/// Six RTOA anchors on a 3 km hexagon, two conditions (Huerta Simulation 2), and a short simulated track.
struct Hex {
  ConstantVelocityClock2 motion{0.01, 1.0, 1e-2};
  MeasurementStack st{ConstantVelocityClock2::layout(), hexagon(), 2};
  situation::SightProcess proc{situation::SightModel::speed_dependent(10, 10, 0.01), 6};
  situation::QualityModel q{{nn::Beta(4, 1.5), nn::Beta(1.5, 4)}};
  Gaussian<6> g;
  std::vector<VecX> y, o;
  Hex() {
    for (int b = 0; b < 6; ++b)
      st.add_rtoa(b, {nn::Normal(0, std::sqrt(10.0)), nn::Rayleigh::from_variance(5000)});
    g.mean.setZero();
    g.cov = Vec<6>(25, 25, 10, 1, 1, 10).asDiagonal();
    Rng rng(3);
    Vec<6> x = Vec<6>::Zero();
    x(3) = 1.0;
    VecXi s = proc.sample_initial(rng);
    VecX w(6);
    for (int k = 1; k <= 30; ++k) {
      x = motion.F() * x;
      situation::transversal_speeds(x.head<2>(), x.segment<2>(3), st.anchors(), w);
      s = proc.sample_next(s, k, w, rng);
      VecX yk(6);
      st.predict(x, 0.0, yk);
      for (int b = 0; b < 6; ++b) yk(b) += st.noise(b, s(b)).sample(rng);
      yk(5) = NAN;  // a missing range
      y.push_back(yk);
      o.push_back(q.sample(s, rng));
    }
  }
  static MatX hexagon() {
    MatX a(6, 2);
    for (int b = 0; b < 6; ++b) {
      a(b, 0) = 3000 * std::cos(b * 3.141592653589793 / 3);
      a(b, 1) = 3000 * std::sin(b * 3.141592653589793 / 3);
    }
    return a;
  }
};

/// Runs steps [0, 5) unguarded (first-step paths, buffers reach their size), then [5, 30) guarded.
template <class Step>
long news_in_steps(const Hex& h, Step&& step) {
  for (std::size_t k = 0; k < 5; ++k) step(h.y[k], h.o[k]);
  NoMalloc guard;
  for (std::size_t k = 5; k < h.y.size(); ++k) step(h.y[k], h.o[k]);
  return NoMalloc::news();
}
template <class F>
long news_in_steps(F& f, const Hex& h) {
  return news_in_steps(h, [&f](const VecX& y, const VecX& o) { f.step(y, o); });
}
}  // namespace

TEST_CASE("IUKF, RBPF and PF steps do not allocate", "[nomalloc]") {
  const Hex h;
  Iukf<ConstantVelocityClock2> iukf(h.motion, h.st, h.g, situation::ForwardFilter(h.proc, h.q));
  CHECK(news_in_steps(h, [&iukf](const VecX& y, const VecX& o) { iukf.step_quality(y, o); }) == 0);
  for (auto variant : {rbpf::RbpfVariant::kReordered, rbpf::RbpfVariant::kClassical})
    for (std::uint64_t max_offspring : {std::uint64_t{4096}, std::uint64_t{20}})  // full and bounded (eq. 23)
      for (int threads : {1, 2})
        for (auto form : {NoiseForm::kAdditive, NoiseForm::kAugmented}) {
          CAPTURE(static_cast<int>(variant), max_offspring, threads, static_cast<int>(form));
          rbpf::RbpfOptions opt;
          opt.variant = variant;
          opt.noise_form = form;
          opt.num_particles = variant == rbpf::RbpfVariant::kReordered ? 64 : 2;  // 64: parallel phases
          opt.max_offspring = max_offspring;
          opt.threads = threads;
          rbpf::Rbpf<ConstantVelocityClock2> f(h.motion, h.st, h.proc, h.q, h.g, opt);
          CHECK(news_in_steps(f, h) == 0);
        }
  for (auto resampling : {rbpf::PfResampling::kSystematic, rbpf::PfResampling::kMergeSelect})
    for (int threads : {1, 2}) {
      CAPTURE(static_cast<int>(resampling), threads);
      rbpf::PfOptions po;
      po.num_particles = 2000;
      po.resampling = resampling;
      po.threads = threads;
      po.seed = 4;
      rbpf::ParticleFilter<ConstantVelocityClock2> pf(h.motion, h.st, h.proc, h.q, h.g, po);
      CHECK(news_in_steps(pf, h) == 0);
    }
}

TEST_CASE("the RBPF neighbour grid does not allocate after reserve", "[nomalloc]") {
  // (the RBPF reserves M points once; a step rebuilds the grid for up to M parents)
  std::vector<double> x(128);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 0.37 * static_cast<double>(i * i % 97);
  rbpf::detail::LineGrid g;
  g.reserve(x.size());
  long news = 0;
  {
    const NoMalloc guard;
    for (std::size_t n : {std::size_t{128}, std::size_t{5}, std::size_t{0}, std::size_t{128}})
      for (double d : {0.5, 0.0, 1e9})
        g.build(
            n, [&](std::size_t i) { return x[i]; }, d);
    news = NoMalloc::news();
  }
  CHECK(news == 0);
  CHECK(g.rows() == 128);  // (the last build: every point in one cell)
}

TEST_CASE("Ke-Wu trackers: QP-bias EKF (both bias references) and bias-augmented EKF do not allocate",
          "[nomalloc]") {
  // K1 geometry (anchors of scenarios.md K1), a mobile at (1000, 1000), anchor 2 NLOS by 400 m so the
  // innovation test fires and the QP runs every step.
  const MatX anchors = (MatX(3, 2) << 0, 0, 8660, 0, 4330, 7500).finished();
  const ConstantVelocity2 motion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
  Gaussian<4> g;
  g.mean << 1000, 1000, 0, 0;
  g.cov = Vec<4>(2500, 2500, 100, 100).asDiagonal();
  std::vector<VecX> zs;
  Rng rng(8);
  for (int k = 0; k < 30; ++k) {
    VecX z(3);
    for (int i = 0; i < 3; ++i)
      z[i] = (anchors.row(i).transpose() - Vec<2>(1000, 1000)).norm() + 50 * rng.normal();
    z[2] += 400.0;
    if (k % 9 == 4) z[0] = NAN;  // a missing range now and then
    zs.push_back(z);
  }
  auto news = [&](auto& f) {
    for (int k = 0; k < 5; ++k) f.step(zs[static_cast<std::size_t>(k)]);
    NoMalloc guard;
    for (std::size_t k = 5; k < zs.size(); ++k) f.step(zs[k]);
    return NoMalloc::news();
  };
  if (mitigation::have_default_box_qp())
    for (auto ref : {mitigation::BiasReference::kPrediction, mitigation::BiasReference::kSnapshot}) {
      CAPTURE(static_cast<int>(ref));
      mitigation::QpBiasEkfOptions o;
      o.reference = ref;
      mitigation::QpBiasEkf f(motion, anchors, g, o);
      CHECK(news(f) == 0);
      CHECK(f.step(zs[6]).bias_estimated);  // the QP path was exercised
    }
  mitigation::BiasAugmentedEkf aug(motion, anchors, g);
  CHECK(news(aug) == 0);
}
