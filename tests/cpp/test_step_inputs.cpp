// Input checks of the situation-aware filters (Rbpf, ParticleFilter, Iukf): check_inputs(y, o) throws the
// std::invalid_argument that step(y, o) (Iukf: step_quality) throws, naming the argument, for a y or o of
// the wrong length and for an infinite entry; NaN (missing) is accepted. A rejected step changes nothing:
// estimate, covariance, time and situation probabilities stay, and the next step equals that of a twin
// that never saw the bad inputs.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "nlosloc/filters/iukf.hpp"
#include "nlosloc/rbpf/pf.hpp"
#include "nlosloc/rbpf/rbpf.hpp"

using namespace nlosloc;
using namespace nlosloc::rbpf;
using Catch::Matchers::Contains;

namespace {
/// Three TOA anchors and one AOA row (m = 4 rows, B = 3 anchors: the two lengths differ), a fixed
/// two-condition chain and Normal quality statistics.
struct InputCheckModel {
  ConstantVelocity2 motion{0.1, 1.0};
  MeasurementStack st;
  situation::SightProcess proc;
  situation::QualityModel q{{noise::Normal(0.8, 0.2), noise::Normal(0.3, 0.2)}};
  Gaussian<4> g;
  VecX y, o;
  InputCheckModel() : st(ConstantVelocity2::layout(), anchors(), 2) {
    for (int b = 0; b < 3; ++b) st.add_toa(b, {noise::Normal(0, 3), noise::Rayleigh::from_variance(2000)});
    st.add_aoa(0, {noise::Normal(0, 0.01), noise::Normal(0, 0.05)});
    MatX T(2, 2);
    T << 0.9, 0.1, 0.2, 0.8;
    proc = situation::SightProcess(situation::SightModel::fixed(T), 3);
    g.mean << 300, 400, 1, 2;
    g.cov = Vec<4>(100, 100, 4, 4).asDiagonal();
    y.resize(4);
    y << 500, 850, 640, 0.9;
    o.resize(3);
    o << 0.75, 0.35, 0.8;
  }
  static MatX anchors() {
    MatX a(3, 2);
    a << 0, 0, 1000, 0, 0, 1000;
    return a;
  }
};

struct BadInput {
  const char* what;
  VecX y, o;
  std::string message;
};
std::vector<BadInput> bad_inputs(const VecX& y, const VecX& o) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<BadInput> v;
  v.push_back({"short y", y.head(3), o, "y: expected shape (4, 1), got (3, 1)"});
  VecX yl(5);
  yl << y, 1.0;
  v.push_back({"long y", yl, o, "y: expected shape (4, 1), got (5, 1)"});
  v.push_back({"short o", y, o.head(2), "o: expected shape (3, 1), got (2, 1)"});
  VecX ol(4);
  ol << o, 0.5;
  v.push_back({"long o", y, ol, "o: expected shape (3, 1), got (4, 1)"});
  VecX yi = y;
  yi(1) = inf;
  v.push_back({"inf in y", yi, o, "y: expected finite values, or NaN for a missing row; got inf at row 1"});
  yi = y;
  yi(3) = -inf;
  v.push_back({"-inf in y", yi, o, "y: expected finite values, or NaN for a missing row; got inf at row 3"});
  VecX oi = o;
  oi(2) = inf;
  v.push_back(
      {"inf in o", y, oi, "o: expected finite statistics, or NaN for a missing one; got inf at anchor 2"});
  return v;
}

/// Element-wise equal lists of matrices (sizes first: Eigen's == asserts on a size mismatch).
bool same_state(const std::vector<MatX>& a, const std::vector<MatX>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].rows() != b[i].rows() || a[i].cols() != b[i].cols() || a[i] != b[i]) return false;
  return true;
}
MatX scalar(double v) { return MatX::Constant(1, 1, v); }

/// The filter f after one good step: every bad input is refused by check_inputs and by step (same
/// message), leaving state(f) as it was; missing entries (NaN in y and o) pass check_inputs. Then f and
/// its twin (the same steps without the refused calls) take a step with missing entries: the same state,
/// and the time moved by dt.
template <class Filter, class Step, class State>
void check_refused_inputs(Filter& f, Filter& twin, const InputCheckModel& m, Step step, State state) {
  step(f, m.y, m.o);
  step(twin, m.y, m.o);
  const std::vector<MatX> before = state(f);
  REQUIRE(same_state(before, state(twin)));
  for (const BadInput& b : bad_inputs(m.y, m.o)) {
    INFO(b.what);
    CHECK_THROWS_AS(f.check_inputs(b.y, b.o), std::invalid_argument);
    CHECK_THROWS_WITH(f.check_inputs(b.y, b.o), Contains(b.message));
    CHECK_THROWS_AS(step(f, b.y, b.o), std::invalid_argument);
    CHECK_THROWS_WITH(step(f, b.y, b.o), Contains(b.message));
    CHECK(same_state(state(f), before));
  }
  VecX ym = m.y, om = m.o;
  ym(0) = std::numeric_limits<double>::quiet_NaN();
  om(1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_NOTHROW(f.check_inputs(ym, m.o));
  CHECK_NOTHROW(f.check_inputs(m.y, om));
  CHECK_NOTHROW(f.check_inputs(ym, om));
  CHECK(same_state(state(f), before));
  const double t = f.time();
  CHECK_NOTHROW(step(f, ym, om));
  step(twin, ym, om);
  CHECK(f.time() == t + m.motion.dt());
  CHECK(same_state(state(f), state(twin)));
  CHECK_FALSE(same_state(state(f), before));  // the step with missing entries did move the filter
}
}  // namespace

TEST_CASE("Rbpf check_inputs and step refuse bad y and o alike, and a refused step changes nothing",
          "[rbpf][input]") {
  const InputCheckModel m;
  auto step = [](Rbpf<ConstantVelocity2>& f, const VecX& y, const VecX& o) { f.step(y, o); };
  auto state = [](const Rbpf<ConstantVelocity2>& f) {
    return std::vector<MatX>{MatX(f.estimate()), MatX(f.covariance()),
                             scalar(f.time()),   f.situation_probabilities(),
                             MatX(f.weights()),  scalar(static_cast<double>(f.step_index()))};
  };
  for (const auto variant : {RbpfVariant::kReordered, RbpfVariant::kClassical}) {
    CAPTURE(static_cast<int>(variant));
    RbpfOptions opt;
    opt.variant = variant;
    opt.num_particles = 8;
    Rbpf<ConstantVelocity2> f(m.motion, m.st, m.proc, m.q, m.g, opt),
        twin(m.motion, m.st, m.proc, m.q, m.g, opt);
    check_refused_inputs(f, twin, m, step, state);
  }
}

TEST_CASE("ParticleFilter check_inputs and step refuse bad y and o alike, and a refused step changes nothing",
          "[pf][input]") {
  const InputCheckModel m;
  auto step = [](ParticleFilter<ConstantVelocity2>& f, const VecX& y, const VecX& o) { f.step(y, o); };
  auto state = [](const ParticleFilter<ConstantVelocity2>& f) {
    return std::vector<MatX>{MatX(f.estimate()),          MatX(f.covariance()), scalar(f.time()),
                             f.situation_probabilities(), f.particles(),        MatX(f.log_weights())};
  };
  PfOptions opt;
  opt.num_particles = 500;
  opt.seed = 3;
  ParticleFilter<ConstantVelocity2> f(m.motion, m.st, m.proc, m.q, m.g, opt),
      twin(m.motion, m.st, m.proc, m.q, m.g, opt);
  check_refused_inputs(f, twin, m, step, state);
}

TEST_CASE("Iukf check_inputs and step_quality refuse bad y and o alike, and a refused step changes nothing",
          "[situation][iukf][input]") {
  const InputCheckModel m;
  auto step = [](Iukf<ConstantVelocity2>& f, const VecX& y, const VecX& o) { f.step_quality(y, o); };
  auto state = [](const Iukf<ConstantVelocity2>& f) {
    return std::vector<MatX>{MatX(f.mean()), MatX(f.cov()), scalar(f.time()), f.forward().probabilities(),
                             scalar(static_cast<double>(f.forward().step_index()))};
  };
  Iukf<ConstantVelocity2> f(m.motion, m.st, m.g, situation::ForwardFilter(m.proc, m.q)),
      twin(m.motion, m.st, m.g, situation::ForwardFilter(m.proc, m.q));
  check_refused_inputs(f, twin, m, step, state);
}
