// EnumerationBoxQp, the default solver of Ke & Wu eq. (14): hand cases, the KKT conditions on random
// positive definite and rank-deficient problems, agreement with proxsuite, warm start and argument checks.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "nlosloc/mitigation/box_qp_enumeration.hpp"
#include "nlosloc/mitigation/box_qp_proxsuite.hpp"
#include "nlosloc/mitigation/qp_bias_ekf.hpp"

using namespace nlosloc;
using namespace nlosloc::mitigation;
using Catch::Matchers::WithinAbs;

namespace {

struct Problem {
  MatX H;
  VecX g, lower, upper;
};

/// H = A A^T with A n x rank (rank < n: positive semidefinite, singular), g and a box around 0 of random
/// widths, some variables with lower == upper.
Problem random_problem(std::mt19937_64& rng, int n, int rank) {
  std::normal_distribution<double> N(0.0, 1.0);
  std::uniform_real_distribution<double> U(0.0, 3.0);
  Problem p;
  MatX A(n, rank);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < rank; ++j) A(i, j) = N(rng);
  p.H = A * A.transpose();
  p.g.resize(n);
  p.lower.resize(n);
  p.upper.resize(n);
  for (int i = 0; i < n; ++i) {
    p.g[i] = 3.0 * N(rng);
    p.lower[i] = -U(rng);
    p.upper[i] = (rng() % 10 == 0) ? p.lower[i] : U(rng);
  }
  return p;
}

/// The KKT conditions of the box QP at x, checked independently of the solver: x in the box; the
/// gradient H x + g zero on the variables strictly inside, >= 0 at a lower bound, <= 0 at an upper one.
void check_kkt(const Problem& p, const VecX& x, double tol) {
  const VecX grad = p.H * x + p.g;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    CAPTURE(i, x[i], grad[i], p.lower[i], p.upper[i]);
    REQUIRE(x[i] >= p.lower[i]);
    REQUIRE(x[i] <= p.upper[i]);
    if (p.lower[i] == p.upper[i]) continue;
    if (x[i] == p.lower[i]) {
      CHECK(grad[i] >= -tol);
    } else if (x[i] == p.upper[i]) {
      CHECK(grad[i] <= tol);
    } else {
      CHECK(std::abs(grad[i]) <= tol);
    }
  }
}

double objective(const Problem& p, const VecX& x) { return 0.5 * x.dot(p.H * x) + p.g.dot(x); }

}  // namespace

TEST_CASE("enumeration box QP: hand cases", "[mitigation][qp]") {
  EnumerationBoxQp qp(3);
  CHECK(qp.name() == "enumeration");
  // min 1/2 x^T diag(2, 0, 1) x + g^T x, g = (-4, 1, 3), 0 <= x <= (1, 5, 5): x_0 = min(4/2, 1) = 1 at its
  // upper bound (gradient -2 <= 0), x_1 and x_2 at 0 (gradients 1 and 3 >= 0); f = 1 - 4 = -3.
  const MatX H = Vec<3>(2, 0, 1).asDiagonal();
  const QpResult r = qp.solve(H, Vec<3>(-4, 1, 3), VecX::Zero(3), Vec<3>(1, 5, 5));
  REQUIRE(r.ok());
  CHECK(qp.x() == Vec<3>(1, 0, 0));
  CHECK(r.objective == -3.0);
  // Interior minimiser: x = -H^-1 g = (1, -2, 0.5), inside the box.
  const QpResult r2 =
      qp.solve(H + MatX::Identity(3, 3), Vec<3>(-3, 2, -1), VecX::Constant(3, -5.0), VecX::Constant(3, 5.0));
  REQUIRE(r2.ok());
  CHECK((qp.x() - Vec<3>(1, -2, 0.5)).cwiseAbs().maxCoeff() < 1e-15);
  CHECK_THAT(r2.objective, WithinAbs(-3.75, 1e-12));  // f = 1/2 g^T x = 1/2 (-3 - 4 - 0.5)
  // H = 0, g = 0: every point is a minimiser; f = 0 at the one returned.
  const QpResult r3 = qp.solve(MatX::Zero(3, 3), VecX::Zero(3), Vec<3>(1, -1, 2), Vec<3>(2, 1, 2));
  REQUIRE(r3.ok());
  CHECK(r3.objective == 0.0);
  CHECK(qp.x()[2] == 2.0);  // lower == upper
  // Rank 1 (H = [1 1; 1 1]), x_0 in [1, 2], x_1 in [-5, 5], g = 0: the minimisers are x_0 + x_1 = 0, where
  // the all-free assignment's H_FF is singular and must be skipped for one with x_0 at a bound.
  EnumerationBoxQp q2(2);
  const QpResult r4 = q2.solve(MatX::Ones(2, 2), VecX::Zero(2), Vec<2>(1, -5), Vec<2>(2, 5));
  REQUIRE(r4.ok());
  CHECK_THAT(q2.x().sum(), WithinAbs(0.0, 1e-15));
  CHECK(r4.objective == 0.0);
}

TEST_CASE("enumeration box QP: KKT on random definite and singular problems, agrees with proxsuite",
          "[mitigation][qp]") {
  std::mt19937_64 rng(20110127);
  int compared = 0;
  double worst_obj = 0.0, worst_x = 0.0;
  for (int n = 1; n <= EnumerationBoxQp::kMaxVariables; ++n) {
    EnumerationBoxQp qp(n);
    for (int rank : {n, std::max(1, n - 2)}) {
      for (int t = 0; t < 40; ++t) {
        CAPTURE(n, rank, t);
        const Problem p = random_problem(rng, n, rank);
        const QpResult r = qp.solve(p.H, p.g, p.lower, p.upper);
        REQUIRE(r.ok());
        CHECK(r.iterations >= 1);
        const double scale = 1.0 + p.g.cwiseAbs().maxCoeff() + 3.0 * p.H.cwiseAbs().maxCoeff();
        check_kkt(p, qp.x(), 1e-9 * scale);
        CHECK_THAT(r.objective, WithinAbs(objective(p, qp.x()), 1e-12 * scale));
        if (have_proxsuite_box_qp()) {
          auto ref = make_proxsuite_box_qp(n);
          const QpResult rr = ref->solve(p.H, p.g, p.lower, p.upper);
          REQUIRE(rr.ok());
          // the enumeration is exact: never above proxsuite's (tolerance 1e-9) objective
          CHECK(r.objective <= rr.objective + 1e-9 * scale);
          worst_obj = std::max(worst_obj, std::abs(r.objective - rr.objective) / scale);
          if (rank == n) worst_x = std::max(worst_x, (qp.x() - ref->x()).cwiseAbs().maxCoeff());
          ++compared;
        }
      }
    }
  }
  if (have_proxsuite_box_qp()) {
    CHECK(compared == 640);
    CHECK(worst_obj < 1e-8);
    CHECK(worst_x < 1e-6);  // definite: the minimiser is unique
  }
}

TEST_CASE("enumeration box QP: warm start, defaults and argument checks", "[mitigation][qp]") {
  std::mt19937_64 rng(7);
  const Problem p = random_problem(rng, 6, 6);
  EnumerationBoxQp qp(6);
  const QpResult first = qp.solve(p.H, p.g, p.lower, p.upper);
  REQUIRE(first.ok());
  const VecX x = qp.x();
  const QpResult again = qp.solve(p.H, p.g, p.lower, p.upper);
  REQUIRE(again.ok());
  CHECK(again.iterations == 1);  // the last solve's active set is tried first
  CHECK(qp.x() == x);
  // make_box_qp: proxsuite when built with it (it picks near the least-norm minimiser on a singular H),
  // else the enumeration; QpBiasEkf: the enumeration for its positive definite prediction-referenced QP.
  const std::string general = have_proxsuite_box_qp() ? "proxsuite-dense" : "enumeration";
  CHECK(make_box_qp(3)->name() == general);
  CHECK(make_box_qp(8)->name() == general);
  if (have_proxsuite_box_qp()) CHECK(make_box_qp(9)->name() == "proxsuite-dense");
  const MatX anchors = (MatX(3, 2) << 0, 0, 10, 0, 0, 10).finished();
  Gaussian<4> g0;
  g0.mean << 3, 4, 0, 0;
  g0.cov = Mat<4, 4>::Identity();
  const ConstantVelocity2 mo(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
  CHECK(QpBiasEkf(mo, anchors, g0).bias_estimator().solver().name() == "enumeration");
  QpBiasEkfOptions snap;
  snap.reference = BiasReference::kSnapshot;
  CHECK(QpBiasEkf(mo, anchors, g0, snap).bias_estimator().solver().name() == general);
  CHECK(BiasEstimator(anchors).solver().name() == general);
  CHECK_THROWS_WITH(EnumerationBoxQp(9),
                    "n: expected 1 <= n <= 8 variables for the enumeration solver, got 9");
  CHECK_THROWS_AS(EnumerationBoxQp(0), std::invalid_argument);
  CHECK_THROWS_AS(make_box_qp(0), std::invalid_argument);
  BoxQpSettings bad;
  bad.eps_abs = 0.0;
  CHECK_THROWS_WITH(EnumerationBoxQp(3, bad), Catch::Matchers::Contains("settings.eps_abs"));
  CHECK_THROWS_WITH(qp.solve(p.H, p.g, p.upper, p.lower), Catch::Matchers::Contains("lower"));
  CHECK_THROWS_WITH(qp.solve(p.H.topLeftCorner(5, 5), p.g, p.lower, p.upper), Catch::Matchers::Contains("H"));
  // a rejected call leaves the last minimiser
  CHECK(qp.x() == x);
}

TEST_CASE("enumeration box QP: the active set kept picks the vertex on a singular H, and restores",
          "[mitigation][qp]") {
  const VecX lo = VecX::Zero(3), hi = VecX::Constant(3, 2.0);
  // The optimal set of this QP is the segment x0 + x1 = 1, x2 = 0: the vertex returned is the first
  // the search reaches, from the kept active set.
  const MatX H = (MatX(3, 3) << 1, 1, 0, 1, 1, 0, 0, 0, 2).finished();
  const VecX g = (VecX(3) << -1, -1, 0.5).finished();
  EnumerationBoxQp q(3);
  CHECK(q.active_set() == std::vector<int>{0, 0, 0});
  REQUIRE(q.solve(MatX::Identity(3, 3), (VecX(3) << -1, 1, 1).finished(), lo, hi).ok());
  CHECK(q.active_set() == std::vector<int>{0, 1, 1});  // x0 free, x1 and x2 at their lower bounds
  EnumerationBoxQp r(3);
  r.set_active_set(q.active_set());
  REQUIRE(r.solve(H, g, lo, hi).ok());
  CHECK(r.x() == (VecX(3) << 1, 0, 0).finished());
  EnumerationBoxQp fresh(3);
  REQUIRE(fresh.solve(H, g, lo, hi).ok());
  CHECK(fresh.x() == (VecX(3) << 0, 1, 0).finished());
  // refused values leave the solver as it was
  CHECK_THROWS_WITH(r.set_active_set({0, 1}), "active_set: expected 3 entries, got 2");
  CHECK_THROWS_WITH(r.set_active_set({0, 3, 1}),
                    "active_set: expected entries 0 (free), 1 (lower) or 2 (upper), got 3 at 1");
  CHECK(r.active_set() == std::vector<int>{0, 1, 1});
}

TEST_CASE("box QP clone: an independent solver that solves as the original would", "[mitigation][qp]") {
  std::mt19937_64 rng(11);
  const Problem a = random_problem(rng, 5, 3), b = random_problem(rng, 5, 5);  // singular, definite
  std::vector<std::unique_ptr<BoxQp>> solvers;
  solvers.push_back(std::make_unique<EnumerationBoxQp>(5));
  solvers.push_back(std::make_unique<FailingBoxQp>(5));
  if (have_proxsuite_box_qp()) solvers.push_back(make_proxsuite_box_qp(5));
  for (auto& q : solvers) {
    INFO(q->name());
    q->solve(a.H, a.g, a.lower, a.upper);  // state (the enumeration's last active set) from problem a
    const std::unique_ptr<BoxQp> c = q->clone();
    REQUIRE(c != nullptr);
    CHECK(c->name() == q->name());
    CHECK(c->size() == 5);
    CHECK(c->x() == q->x());  // the last minimiser comes along
    const QpResult rq = q->solve(b.H, b.g, b.lower, b.upper), rc = c->solve(b.H, b.g, b.lower, b.upper);
    CHECK(rc.status == rq.status);
    CHECK(rc.iterations == rq.iterations);
    CHECK(c->x() == q->x());
    // independent: solving a again on the clone leaves the original's minimiser of b
    const VecX xb = q->x();
    c->solve(a.H, a.g, a.lower, a.upper);
    CHECK(q->x() == xb);
  }
}

namespace {
/// Four anchors on a 20 m square, a belief at (8, 6) and a tracker that estimates biases at every update.
struct Square4 {
  MatX anchors = (MatX(4, 2) << 0, 0, 20, 0, 0, 20, 20, 20).finished();
  Gaussian<4> g0 = [] {
    Gaussian<4> g;
    g.mean << 8, 6, 1, 0;
    g.cov = Mat<4, 4>::Identity();
    return g;
  }();
  ConstantVelocity2 mo{0.1, 1.0, VelocityNoise::kWhiteAcceleration};
  QpBiasEkfOptions o = [] {
    QpBiasEkfOptions q;
    q.always_estimate = true;
    return q;
  }();
};

/// A solver written before BoxQp::clone() existed: the default clone() returns null.
class NoCloneQp final : public BoxQp {
 public:
  explicit NoCloneQp(int n) : x_(VecX::Zero(n)) {}
  int size() const override { return static_cast<int>(x_.size()); }
  std::string name() const override { return "no-clone"; }
  const VecX& x() const override { return x_; }
  QpResult solve(const Eigen::Ref<const MatX>&, const Eigen::Ref<const VecX>&, const Eigen::Ref<const VecX>&,
                 const Eigen::Ref<const VecX>& upper) override {
    x_ = upper;  // any feasible point will do here
    QpResult r;
    r.status = QpStatus::kSolved;
    return r;
  }

 private:
  VecX x_;
};
}  // namespace

TEST_CASE("QpBiasEkf copies: an independent tracker with its own solver, or a clear refusal",
          "[mitigation][qp]") {
  const Square4 sq;
  const MatX& anchors = sq.anchors;
  const Gaussian<4>& g0 = sq.g0;
  const ConstantVelocity2& mo = sq.mo;
  const QpBiasEkfOptions& o = sq.o;
  auto ranges = [&](int k) {
    VecX z(4);
    const Vec<2> p(8.0 + 0.1 * k, 6.0);
    for (int i = 0; i < 4; ++i) z[i] = (anchors.row(i).transpose() - p).norm() + (i == 1 ? 4.0 : 0.0);
    return z;
  };
  QpBiasEkf f(mo, anchors, g0, o);
  f.update(ranges(0));
  QpBiasEkf c(f);
  CHECK(&c.bias_estimator().solver() != &f.bias_estimator().solver());
  CHECK(c.bias_estimator().solver().name() == "enumeration");
  for (int k = 1; k <= 5; ++k) {
    f.step(ranges(k));
    c.step(ranges(k));
    CHECK(c.mean() == f.mean());
    CHECK(c.cov() == f.cov());
    CHECK(c.bias() == f.bias());
    CHECK(c.nlos_detected() == f.nlos_detected());
  }
  const Vec<4> before = f.mean();
  c.step(ranges(6));  // the copy moves on alone
  CHECK(f.mean() == before);
  // Assignment copies as well.
  QpBiasEkf d(mo, anchors, g0, o);
  d = f;
  d.step(ranges(6));
  CHECK(d.mean() == c.mean());
  // A solver without clone(): the copy is refused, naming it; an assignment leaves the target as it was.
  QpBiasEkf n(mo, anchors, g0, o, std::make_unique<NoCloneQp>(4));
  CHECK_THROWS_WITH(QpBiasEkf(n), Catch::Matchers::Contains("solver: the BoxQp 'no-clone' cannot be copied"));
  CHECK_THROWS_AS(d = n, std::invalid_argument);
  CHECK(d.mean() == c.mean());
  CHECK(d.bias_estimator().solver().name() == "enumeration");
  QpBiasEkf moved(std::move(n));  // moving needs no clone
  CHECK(moved.bias_estimator().solver().name() == "no-clone");
}

namespace {
/// Solves through the enumeration solver, or throws when *armed (a solver written in Python may raise).
class ThrowingQp final : public BoxQp {
 public:
  ThrowingQp(int n, std::shared_ptr<bool> armed) : inner_(n), armed_(std::move(armed)) {}
  int size() const override { return inner_.size(); }
  std::string name() const override { return "throwing"; }
  const VecX& x() const override { return inner_.x(); }
  QpResult solve(const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                 const Eigen::Ref<const VecX>& lower, const Eigen::Ref<const VecX>& upper) override {
    if (*armed_) throw std::runtime_error("boom");
    return inner_.solve(H, g, lower, upper);
  }

 private:
  EnumerationBoxQp inner_;
  std::shared_ptr<bool> armed_;
};
}  // namespace

TEST_CASE("QpBiasEkf: a solver that throws leaves the tracker as it was", "[mitigation][qp]") {
  const Square4 sq;
  const MatX& anchors = sq.anchors;
  const Gaussian<4>& g0 = sq.g0;
  const ConstantVelocity2& mo = sq.mo;
  const QpBiasEkfOptions& o = sq.o;
  VecX z(4);
  for (int i = 0; i < 4; ++i)
    z[i] = (anchors.row(i).transpose() - g0.mean.head<2>()).norm() + (i == 2 ? 5 : 0);
  auto armed = std::make_shared<bool>(false);
  QpBiasEkf f(mo, anchors, g0, o, std::make_unique<ThrowingQp>(4, armed));
  f.update(z);
  REQUIRE(f.last_step().bias_estimated);
  const Vec<4> m = f.mean();
  const Mat<4, 4> P = f.cov();
  const VecX b = f.bias(), lb = f.bias_estimator().last().bias;
  const double t = f.time();
  const unsigned flags = f.last_step().flags;
  *armed = true;
  CHECK_THROWS_WITH(f.step(z), "boom");
  CHECK_THROWS_WITH(f.update(z), "boom");
  CHECK(f.mean() == m);
  CHECK(f.cov() == P);
  CHECK(f.time() == t);
  CHECK(f.bias() == b);
  CHECK(f.bias_estimator().last().bias == lb);
  CHECK(f.last_step().flags == flags);
  // and it goes on as if the refused calls had not been made
  *armed = false;
  QpBiasEkf g(mo, anchors, g0, o);
  g.update(z);
  f.step(z);
  g.step(z);
  CHECK(f.mean() == g.mean());
  CHECK(f.bias() == g.bias());
}

namespace {
/// The built-in solvers of size n (proxsuite when compiled in), each named.
std::vector<std::unique_ptr<BoxQp>> built_in_solvers(int n) {
  std::vector<std::unique_ptr<BoxQp>> s;
  s.push_back(std::make_unique<EnumerationBoxQp>(n));
  s.push_back(std::make_unique<FailingBoxQp>(n));
  if (have_proxsuite_box_qp()) s.push_back(make_proxsuite_box_qp(n));
  return s;
}
}  // namespace

TEST_CASE("box QP: a non-symmetric or indefinite H is refused, naming H, the solver unchanged",
          "[mitigation][qp][input]") {
  const VecX lo = VecX::Constant(3, -1.0), hi = VecX::Ones(3), g = Vec<3>(1.0, -1.0, 0.5);
  for (auto& q : built_in_solvers(3)) {
    INFO(q->name());
    // A valid problem first: H = I, x = clip(-g0) = (-1, 0.5, -0.25), x_0 at its lower bound.
    q->solve(MatX::Identity(3, 3), Vec<3>(2.0, -0.5, 0.25), lo, hi);
    const VecX x = q->x();
    // Indefinite: diag(2, -1, 1) has its box minimum -1.875 at (-0.5, 1, -0.5); proxsuite reported a
    // stationary point (objective 0.125) as solved. The pivots 2, 1 go first, -1 is left on row 1.
    CHECK_THROWS_WITH(q->solve(Vec<3>(2.0, -1.0, 1.0).asDiagonal().toDenseMatrix(), g, lo, hi),
                      "H: expected a positive semidefinite matrix, got negative curvature -1 at row 1 "
                      "(pivoted Cholesky)");
    // No curvature on rows 1 and 2 but a coupling: the block [0 2; 2 0] has the eigenvalue -2.
    const MatX coupled = (MatX(3, 3) << 1, 0, 0, 0, 0, 2, 0, 2, 0).finished();
    CHECK_THROWS_WITH(q->solve(coupled, g, lo, hi),
                      "H: expected a positive semidefinite matrix, got negative curvature -2 at rows 1, 2 "
                      "(pivoted Cholesky)");
    // Non-symmetric (proxsuite read one triangle, the enumeration failed without a word).
    const MatX asym = (MatX(3, 3) << 2, 1.5, 0, -1.5, 1, 0, 0, 0, 1).finished();
    CHECK_THROWS_WITH(q->solve(asym, g, lo, hi),
                      "H: expected a symmetric matrix, got H[0,1] = 1.5 != H[1,0] = -1.5");
    MatX almost = MatX::Identity(3, 3);
    almost(2, 0) = 0.25;
    almost(0, 2) = 0.25 + 3e-10;  // 1e-10 of the largest entry (1) is the tolerance
    CHECK_THROWS_WITH(
        q->solve(almost, g, lo, hi),
        Catch::Matchers::StartsWith("H: expected a symmetric matrix, got H[0,2] = 0.2500000003"));
    CHECK_THROWS_WITH(q->solve(MatX::Identity(3, 3), g, hi, lo), Catch::Matchers::StartsWith("lower, upper"));
    // the rejected calls left the last result
    CHECK(q->x() == x);
    const auto* e = dynamic_cast<const EnumerationBoxQp*>(q.get());
    if (e != nullptr) CHECK(e->active_set() == std::vector<int>{1, 0, 0});  // x_0 at its lower bound
    // Within the tolerances: round-off asymmetry (1e-11 of max |H|) and a pivot -1e-13 >= -3e-12 (n 1e-12
    // max diag) are accepted as the PSD matrices they approximate.
    almost(0, 2) = 0.25 + 1e-11;
    CHECK_NOTHROW(q->solve(almost, g, lo, hi));
    CHECK_NOTHROW(q->solve(Vec<3>(1.0, -1e-13, 1.0).asDiagonal().toDenseMatrix(), g, lo, hi));
    CHECK_THROWS_WITH(q->solve(Vec<3>(1.0, -1e-11, 1.0).asDiagonal().toDenseMatrix(), g, lo, hi),
                      "H: expected a positive semidefinite matrix, got negative curvature -1e-11 at row 1 "
                      "(pivoted Cholesky)");
  }
}

TEST_CASE("box QP: rank-deficient PSD H (zero rows, H = 0, rank 1, A A^T) solve to the box minimum",
          "[mitigation][qp]") {
  const VecX lo = Vec<3>(-1.0, 0.0, -2.0), hi = Vec<3>(1.0, 2.0, 0.5);
  const VecX g = Vec<3>(1.0, -1.0, 0.5);
  const Vec<3> v(1.0, 2.0, -1.0);
  // Minima by hand. H = 0: the linear program, x at the bound against g: -1 - 2 - 1 = -4.
  // H = v v^T (rank 1), f = 1/2 s^2 + g^T x with s = v^T x: x_1 and x_2 free need -1 + 2 s = 0 = 0.5 - s,
  // so s = 0.5, and x_0 = -1 (gradient 1 + s > 0); on that segment (x_2 = 2 x_1 - 1.5, x_1 in [0, 1])
  // f = 1/8 - 1 - x_1 + x_2 / 2 = -1.625, a minimiser set, not a point.
  // Zero row and column 1: diag(2, 0, 1): x_0 = -0.5, x_1 = 2, x_2 = -0.5: -0.25 - 2 - 0.125 = -2.375.
  struct Case {
    const char* what;
    MatX H;
    double fmin;
  };
  Case cases[] = {{"H = 0", MatX::Zero(3, 3), -4.0},
                  {"rank 1", v * v.transpose(), -1.625},
                  {"zero row", Vec<3>(2.0, 0.0, 1.0).asDiagonal().toDenseMatrix(), -2.375}};
  for (auto& q : built_in_solvers(3)) {
    if (q->name() == "failing") continue;
    for (const Case& c : cases) {
      INFO(q->name() << ": " << c.what);
      const QpResult r = q->solve(c.H, g, lo, hi);
      REQUIRE(r.ok());
      CHECK_THAT(r.objective, WithinAbs(c.fmin, 1e-7));
    }
  }
  // H = A A^T with its round-off (asymmetric to ~1e-16, rank 2) passes on every seed of the random test.
  std::mt19937_64 rng(3);
  EnumerationBoxQp qp(6);
  for (int t = 0; t < 200; ++t) {
    const Problem p = random_problem(rng, 6, 2);
    MatX H = p.H;
    H(0, 5) *= 1.0 + 1e-15;  // round-off between the two triangles
    REQUIRE(qp.solve(H, p.g, p.lower, p.upper).ok());
  }
}

namespace {
/// Everything a BiasEstimator shows: the last estimate and the intermediates of eqs. (9)-(14).
struct EstimatorView {
  MatX H0, U, L, Sv, Svg, Hq;
  VecX y, r, gq, bias, lower, upper;
  Vec<2> x0, x_tilde;
  unsigned flags;
  QpStatus status;
  int iterations;
  explicit EstimatorView(const BiasEstimator& e)
      : H0(e.H0()),
        U(e.U()),
        L(e.L()),
        Sv(e.sigma_v()),
        Svg(e.sigma_v_ginv()),
        Hq(e.qp_hessian()),
        y(e.y()),
        r(e.r()),
        gq(e.qp_gradient()),
        bias(e.last().bias),
        lower(e.last().lower),
        upper(e.last().upper),
        x0(e.last().reference.point),
        x_tilde(e.last().x_tilde),
        flags(e.last().flags),
        status(e.last().qp.status),
        iterations(e.last().qp.iterations) {}
};
/// Bit-equal views (a NaN anywhere would compare unequal: none is expected here).
void check_same(const EstimatorView& a, const EstimatorView& b) {
  CHECK(a.H0 == b.H0);
  CHECK(a.U == b.U);
  CHECK(a.L == b.L);
  CHECK(a.Sv == b.Sv);
  CHECK(a.Svg == b.Svg);
  CHECK(a.Hq == b.Hq);
  CHECK(a.y == b.y);
  CHECK(a.r == b.r);
  CHECK(a.gq == b.gq);
  CHECK(a.bias == b.bias);
  CHECK(a.lower == b.lower);
  CHECK(a.upper == b.upper);
  CHECK(a.x0 == b.x0);
  CHECK(a.x_tilde == b.x_tilde);
  CHECK(a.flags == b.flags);
  CHECK(a.status == b.status);
  CHECK(a.iterations == b.iterations);
}
}  // namespace

TEST_CASE("a solver that throws leaves the estimator's intermediates as they were (tracker and bare)",
          "[mitigation][qp][input]") {
  const Square4 sq;
  VecX z(4), z2(4);
  for (int i = 0; i < 4; ++i) {
    const double d = (sq.anchors.row(i).transpose() - sq.g0.mean.head<2>()).norm();
    z[i] = d + (i == 2 ? 5 : 0);
    z2[i] = d + (i == 1 ? 7 : 0.5);  // another problem: every intermediate would change
  }
  for (auto ref : {BiasReference::kPrediction, BiasReference::kSnapshot}) {
    CAPTURE(static_cast<int>(ref));
    QpBiasEkfOptions o = sq.o;
    o.reference = ref;
    auto armed = std::make_shared<bool>(false);
    QpBiasEkf f(sq.mo, sq.anchors, sq.g0, o, std::make_unique<ThrowingQp>(4, armed));
    f.update(z);
    REQUIRE(f.last_step().bias_estimated);
    REQUIRE(f.bias_estimator().last().qp.ok());
    const EstimatorView before(f.bias_estimator());
    const MitigationStep last = f.last_step();
    *armed = true;
    CHECK_THROWS_WITH(f.step(z2), "boom");
    CHECK_THROWS_WITH(f.update(z2), "boom");
    check_same(EstimatorView(f.bias_estimator()), before);
    CHECK(f.last_step().innovation_sq == last.innovation_sq);
    CHECK(f.last_step().threshold == last.threshold);
    // the same step, not refused, does change them
    *armed = false;
    f.update(z2);
    CHECK(f.bias_estimator().qp_hessian() != before.Hq);
    CHECK(f.bias_estimator().r() != before.r);
  }
  // A bare estimator, both forms: H0, U and y (snapshot) and the rest restored.
  auto armed = std::make_shared<bool>(false);
  BiasEstimator est(sq.anchors, std::make_unique<ThrowingQp>(4, armed));
  const VecX var = Vec<4>(1.0, 2.0, 1.5, 1.0);
  est.estimate(z, var);
  REQUIRE(est.last().qp.ok());
  const EstimatorView snap(est);
  *armed = true;
  CHECK_THROWS_WITH(est.estimate(z2, var), "boom");
  check_same(EstimatorView(est), snap);
  CHECK_THROWS_WITH(est.estimate_from_innovation(z2, VecX::Ones(4), MatX::Identity(4, 4)), "boom");
  check_same(EstimatorView(est), snap);
  *armed = false;
  est.estimate_from_innovation(z, Vec<4>(1.0, -1.0, 2.0, 0.0), MatX::Identity(4, 4));
  const EstimatorView pred(est);
  *armed = true;
  CHECK_THROWS_WITH(est.estimate(z2, var), "boom");
  check_same(EstimatorView(est), pred);
}
