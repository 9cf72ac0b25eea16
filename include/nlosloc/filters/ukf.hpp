#pragma once
/// \file ukf.hpp
/// Unscented Kalman filters over a measurement stack, in additive-noise and augmented-noise forms.
///
/// Both predict with the exact linear equations of the motion model (every motion model of the library
/// is linear) and draw the update's sigma points from the predicted (x, P): one Cholesky of P per step.
/// A textbook UKF that propagates sigma points through f and reuses them in the update gives the same
/// mean and covariance up to rounding for linear f, but not the same sigma points; FilterPy comparisons
/// therefore redraw FilterPy's sigmas_f from (x, P) after its predict (tests/python/test_filterpy.py).
#include <algorithm>
#include <cmath>
#include <vector>

#include "nlosloc/core/sigma_points.hpp"
#include "nlosloc/filters/filter_base.hpp"
#include "nlosloc/models/measurement.hpp"

namespace nlosloc {

namespace detail {
/// Weighted mean of the columns of Z with angle rows averaged through residuals to the centre point,
/// so a set that straddles +-pi averages correctly.
template <class Meas, class DZ>
void sigma_mean(const Meas& meas, const Eigen::MatrixBase<DZ>& Z, const SigmaWeights& w, VecX& zbar) {
  const Eigen::Index K = Z.cols();
  for (Eigen::Index i = 0; i < Z.rows(); ++i) zbar[i] = w.wm0 * Z(i, 0) + w.wi * Z.row(i).tail(K - 1).sum();
  if (!meas.has_angles()) return;
  for (int i = 0; i < meas.rows(); ++i) {
    if (!meas.is_angle(i)) continue;
    double acc = 0.0;
    for (Eigen::Index j = 1; j < K; ++j) acc += w.wi * wrap_angle(Z(i, j) - Z(i, 0));
    zbar[i] = wrap_angle(Z(i, 0) + acc);  // sum of weights is 1
  }
}

/// Unscented moments of an additive-noise measurement stack without the noise (Huerta eqs. 49-51;
/// Wan and van der Merwe 2000): from (x, L), L a lower Cholesky factor of P, the predicted measurement
/// z_hat, the noise-free S = sum_j wc_j (Z_j - z_hat)(Z_j - z_hat)^T and the cross covariance Pxz.
/// Pxz uses the known state deviations of the symmetric set, X_{+-i} - x = +-gamma L(:,i) (centre 0):
/// Pxz = wi gamma L D^T with D(:,i) = Z_{+i} - Z_{-i}; z_hat cancels in each pair.
/// Sigma-point images are stored row by row (one row per measurement row, 2N+1 fixed columns) so the
/// range evaluation and the weighted sums run over contiguous fixed-size rows.
template <int N>
class SigmaMoments {
 public:
  static constexpr int K = 2 * N + 1;

  void resize(int m) {
    Z_.setZero(m, K);
    wc_.setConstant(0.0);
  }

  template <class Meas>
  void compute(const Meas& meas, const Vec<N>& x, const Mat<N, N>& L, const SigmaWeights& w, double t,
               VecX& zhat, MatX& S, Eigen::Matrix<double, N, Eigen::Dynamic>& Pxz) {
    sigma_points(x, L, w.gamma, X_);  // eq. (49)
    meas.predict_columns(X_, t, Z_);
    sigma_mean(meas, Z_, w, zhat);  // eq. (51)
    const Eigen::Index m = Z_.rows();
    for (Eigen::Index i = 0; i < m; ++i) Z_.row(i).array() -= zhat[i];
    meas.wrap_residual_cols(Z_);
    wc_.setConstant(w.wi);
    wc_[0] = w.wc0;
    const double gw = w.wi * w.gamma;
    for (Eigen::Index b = 0; b < m; ++b) {
      const Eigen::Matrix<double, 1, K> zb = Z_.row(b).cwiseProduct(wc_);
      for (Eigen::Index a = b; a < m; ++a) S(a, b) = S(b, a) = zb.dot(Z_.row(a));  // eq. (51)
      const Eigen::Matrix<double, N, 1> d =
          (Z_.row(b).template segment<N>(1) - Z_.row(b).template segment<N>(1 + N)).transpose();
      Pxz.col(b).noalias() = gw * (L * d);
    }
  }

 private:
  Eigen::Matrix<double, N, K, Eigen::RowMajor> X_;
  Eigen::Matrix<double, Eigen::Dynamic, K, Eigen::RowMajor> Z_;
  Eigen::Matrix<double, 1, K> wc_;
};

/// Unscented moments with the measurement noise inside the sigma points (Huerta Table III, eqs. 49-51 over
/// the augmented vector [x; u], u ~ N(0, I_q) mapped through each row's quantile, Grisales eq. 29): from
/// (x, L) and the sight `s`, z_hat, S (noise included) and Pxz. Shared by UkfAugmented and the RBPF bank.
/// With missing rows (NaN in y) the transform runs over [x; u_a], u_a the inputs that the present rows
/// read (MeasurementStack::for_each_input), with the weights of n + q_a: the inputs of a missing row would
/// otherwise stay in the set as dimensions that move no used row and still change the weights and the
/// spread, and the update would differ from the one of a stack built without that row.
template <int N>
class AugmentedMoments {
 public:
  /// Buffers for m rows and q inputs, and the weights of `scheme` for every n + q_a, q_a <= q (none where
  /// the scheme has no weights for that dimension: then a step with those rows missing keeps all inputs).
  void resize(int m, int q, const SigmaScheme& scheme) {
    q_ = q;
    const int K = 2 * (N + q) + 1;
    Z_.setZero(m, K);
    Zw_.setZero(m, K);
    D_.setZero(m, N);
    u_.setZero(q);
    used_.assign(static_cast<std::size_t>(q), 0);
    active_.assign(static_cast<std::size_t>(q), 0);
    wtab_.assign(static_cast<std::size_t>(q) + 1, SigmaWeights{});
    wok_.assign(static_cast<std::size_t>(q) + 1, 0);
    for (int qa = 0; qa <= q; ++qa) {
      try {  // a negative kappa may leave the smaller dimensions without weights (n + kappa <= 0)
        wtab_[static_cast<std::size_t>(qa)] = scheme.weights(N + qa);
        wok_[static_cast<std::size_t>(qa)] = 1;
      } catch (const std::invalid_argument&) {
      }
    }
  }

  /// `w` are the weights of dimension N + q (eq. 49 with L_a = n + q). y: the measurement, whose NaN rows
  /// leave their inputs out of the set (null: every row present).
  template <class Meas>
  void compute(const Meas& meas, const Vec<N>& x, const Mat<N, N>& L, const SigmaWeights& w, double t,
               const VecXi& s, VecX& zhat, MatX& S, Eigen::Matrix<double, N, Eigen::Dynamic>& Pxz,
               const VecX* y = nullptr) {
    const SigmaWeights& wa = select_inputs(meas, w, y);
    const int qa = qa_;
    const double g = wa.gamma;
    const int La = N + qa, Ka = 2 * La + 1;
    // Points of blockdiag(P, I_qa) around (x, 0): state directions, then noise directions (eq. 49).
    u_.setZero();
    auto eval = [&](const Vec<N>& xj, Eigen::Index col) {
      auto z = Z_.col(col);
      meas.predict_augmented(xj, t, u_, s, z);
    };
    eval(x, 0);
    for (int i = 0; i < N; ++i) {
      eval(x + g * L.col(i), 1 + i);
      eval(x - g * L.col(i), 1 + La + i);
    }
    for (int k = 0; k < qa; ++k) {
      const int in = qa < q_ ? active_[static_cast<std::size_t>(k)] : k;
      u_[in] = g;
      eval(x, 1 + N + k);
      u_[in] = -g;
      eval(x, 1 + La + N + k);
      u_[in] = 0.0;
    }
    auto Z = Z_.leftCols(Ka);
    sigma_mean(meas, Z, wa, zhat);  // eq. (51)
    for (Eigen::Index j = 0; j < Ka; ++j) Z.col(j) -= zhat;
    meas.wrap_residual_cols(Z);
    auto Zw = Zw_.leftCols(Ka);
    Zw = Z;
    Zw.col(0) *= wa.wc0;
    Zw.rightCols(Ka - 1) *= wa.wi;
    S.noalias() = Zw.lazyProduct(Z.transpose());  // eq. (51), noise inside the points
    // Only the state directions have x deviations, +-g L(:,i): Pxz = sum_i wi g L(:,i) (Z+i - Z-i)^T.
    for (int i = 0; i < N; ++i) D_.col(i) = Z.col(1 + i) - Z.col(1 + La + i);
    Pxz.noalias() = (wa.wi * g) * L.lazyProduct(D_.transpose());
  }

  /// Inputs in the last compute(): q_a, and their indices.
  int active_inputs() const { return qa_; }

 private:
  /// Sets qa_ to the number of inputs read by the rows of y that are not NaN and, when fewer than q_,
  /// lists them in active_[0, qa_) in input order; returns their weights. Every input (qa_ = q_, input k
  /// is the k-th) and `w` when no row is missing or the scheme has no weights for the smaller dimension.
  template <class Meas>
  const SigmaWeights& select_inputs(const Meas& meas, const SigmaWeights& w, const VecX* y) {
    qa_ = q_;
    if (!y || !y->hasNaN()) return w;
    std::fill(used_.begin(), used_.end(), char{0});
    for (int i = 0; i < meas.rows(); ++i)
      if (!std::isnan((*y)[i]))
        meas.for_each_input(i, [this](int k) { used_[static_cast<std::size_t>(k)] = 1; });
    int qa = 0;
    for (int k = 0; k < q_; ++k)
      if (used_[static_cast<std::size_t>(k)]) active_[static_cast<std::size_t>(qa++)] = k;
    if (qa == q_ || !wok_[static_cast<std::size_t>(qa)]) return w;
    qa_ = qa;
    return wtab_[static_cast<std::size_t>(qa)];
  }

  int q_ = 0, qa_ = 0;
  MatX Z_, Zw_;
  Eigen::Matrix<double, Eigen::Dynamic, N> D_;
  VecX u_;
  std::vector<char> used_;
  std::vector<int> active_;
  std::vector<SigmaWeights> wtab_;
  std::vector<char> wok_;
};
}  // namespace detail

/// How a sigma-point filter treats the measurement noise.
enum class NoiseForm {
  kAdditive = 0,  ///< y = g(x) + n with n's exact mean and covariance under the sight (Ukf)
  kAugmented = 1  ///< noise inside the sigma points through each row's quantile (Huerta Table III)
};

/// UKF with additive measurement noise: y = g(x) + n, n with the mean and covariance of each row's
/// distribution under the current sight (Huerta Table VI per condition; Julier/Wan-van der Merwe UT).
template <class Motion, class Meas = MeasurementStack>
class Ukf : public FilterBase<Ukf<Motion, Meas>, Motion> {
  using Base = FilterBase<Ukf<Motion, Meas>, Motion>;
  friend Base;

 public:
  using Base::kDim;
  static constexpr int kPoints = 2 * kDim + 1;

  Ukf(const Motion& motion, const Meas& meas, const Gaussian<kDim>& initial,
      const SigmaScheme& scheme = SigmaScheme::scaled(), double t0 = 0.0)
      : Base(motion, initial, t0), meas_(meas), scheme_(scheme), w_(scheme.weights(kDim)) {
    detail::check_layout<kDim>(meas);
    meas.check_ready();
    meas.check_finite_moments("Ukf");
    const int m = meas.rows();
    tail_.resize(m);
    mom_.resize(m);
    nmean_.setZero(m);
    R_.setZero(m, m);
    y_.setZero(m);
    los_.setZero(meas.num_anchors());
  }

  const Meas& measurements() const { return meas_; }
  const SigmaScheme& scheme() const { return scheme_; }
  const SigmaWeights& weights() const { return w_; }

  /// Unscented update (Huerta Table VI, one sight condition; Wan and van der Merwe 2000).
  StepResult update(const Eigen::Ref<const VecX>& y, const VecXi* sight = nullptr) {
    precheck(y, sight);
    return update_unchecked(y, sight);
  }
  StepResult update(const Eigen::Ref<const VecX>& y, const VecXi& sight) { return update(y, &sight); }

 private:
  StepResult update_unchecked(const Eigen::Ref<const VecX>& y, const VecXi* sight) {
    const VecXi& s = sight ? *sight : los_;
    y_ = y;
    StepResult res;
    Mat<kDim, kDim> L;
    const CholeskyStatus st = detail::factor_state_cov(this->P_, L, &res.jitter);
    res.status = st;
    if (st == CholeskyStatus::kFailed) Base::fail("Ukf.update: P");
    auto& t = tail_;
    mom_.compute(meas_, this->x_, L, w_, this->t_, t.zhat, t.S, t.Pxz);  // Huerta eqs. (49)-(51)
    meas_.noise_moments(this->x_, s, nmean_, R_);                        // additive noise
    t.S += R_;
    t.zhat += nmean_;
    if (!t.apply(
            y_, [this](VecX& r) { meas_.wrap_residual(r); }, this->x_, this->P_, res))
      Base::fail("Ukf.update: S");
    return res;
  }

 private:
  void precheck(const Eigen::Ref<const VecX>& y, const VecXi* sight) const {
    detail::check_measurement(y, meas_.rows());
    if (sight) meas_.check_sight(*sight);
  }
  Meas meas_;
  SigmaScheme scheme_;
  SigmaWeights w_;
  detail::SigmaMoments<kDim> mom_;
  MatX R_;
  VecX nmean_, y_;
  VecXi los_;
  detail::UpdateTail<kDim> tail_;
};

/// UKF with the measurement noise in the sigma points: the state is augmented with one standard normal
/// per noise input, mapped through each distribution's quantile (Huerta Sec. V-A; Grisales eq. 29), so
/// non-Gaussian (Rayleigh, GEV, ...) and state-dependent noise (two-way ranging) enter exactly.
template <class Motion, class Meas = MeasurementStack>
class UkfAugmented : public FilterBase<UkfAugmented<Motion, Meas>, Motion> {
  using Base = FilterBase<UkfAugmented<Motion, Meas>, Motion>;
  friend Base;

 public:
  using Base::kDim;

  UkfAugmented(const Motion& motion, const Meas& meas, const Gaussian<kDim>& initial,
               const SigmaScheme& scheme = SigmaScheme::scaled(), double t0 = 0.0)
      : Base(motion, initial, t0), meas_(meas), scheme_(scheme) {
    detail::check_layout<kDim>(meas);
    meas.check_ready();
    q_ = meas.noise_dim();
    w_ = scheme.weights(kDim + q_);  // L_a = n + q (Huerta eq. 49)
    const int m = meas.rows();
    tail_.resize(m);
    mom_.resize(m, q_, scheme);
    y_.setZero(m);
    los_.setZero(meas.num_anchors());
  }

  const Meas& measurements() const { return meas_; }
  const SigmaScheme& scheme() const { return scheme_; }
  const SigmaWeights& weights() const { return w_; }
  int augmented_dim() const { return kDim + q_; }

  StepResult update(const Eigen::Ref<const VecX>& y, const VecXi* sight = nullptr) {
    precheck(y, sight);
    return update_unchecked(y, sight);
  }
  StepResult update(const Eigen::Ref<const VecX>& y, const VecXi& sight) { return update(y, &sight); }

 private:
  StepResult update_unchecked(const Eigen::Ref<const VecX>& y, const VecXi* sight) {
    const VecXi& s = sight ? *sight : los_;
    y_ = y;
    StepResult res;
    Mat<kDim, kDim> L;
    const CholeskyStatus st = detail::factor_state_cov(this->P_, L, &res.jitter);
    res.status = st;
    if (st == CholeskyStatus::kFailed) Base::fail("UkfAugmented.update: P");
    auto& t = tail_;
    mom_.compute(meas_, this->x_, L, w_, this->t_, s, t.zhat, t.S, t.Pxz, &y_);  // Table III, eqs. (49)-(51)
    if (!t.apply(
            y_, [this](VecX& r) { meas_.wrap_residual(r); }, this->x_, this->P_, res))
      Base::fail("UkfAugmented.update: S");
    return res;
  }

 private:
  void precheck(const Eigen::Ref<const VecX>& y, const VecXi* sight) const {
    detail::check_measurement(y, meas_.rows());
    if (sight) meas_.check_sight(*sight);
  }
  Meas meas_;
  SigmaScheme scheme_;
  SigmaWeights w_;
  int q_ = 0;
  detail::AugmentedMoments<kDim> mom_;
  VecX y_;
  VecXi los_;
  detail::UpdateTail<kDim> tail_;
};

}  // namespace nlosloc
