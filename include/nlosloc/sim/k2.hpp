#pragma once
/// \file k2.hpp
/// Scenario K2 of reference/scenarios.md: Ke & Wu 2011 (papers/ke-wu2011-qp-ekf.md) Sec. 6.2, LOS/NLOS
/// transitions: K1's geometry and noise, every node switching LOS <-> NLOS every 200 samples. Its three
/// estimators (proposed, iterated NLOS EKF, EKF), and the K2 study the bench prints: identification accuracy
/// per sample (Fig. 5), ranging error (Fig. 3) and position error, averaged over runs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "nlosloc/sim/k1.hpp"
#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace nlosloc::sim {

/// Parameters of K2: K1's (Sec. 6) plus the switching period.
struct K2Params {
  K1Params base{};         ///< geometry, noise, motion, L, dt, discard, estimator choices of K1
  int period = 200;        ///< Sec. 6: LOS/NLOS of each node changes every 200 samples
  bool start_nlos = true;  ///< choice: the first block is NLOS (the paper's excerpt runs NLOS-LOS-NLOS)
};

/// K2: as K1, all three nodes NLOS in samples [0, 200), LOS in [200, 400), ... (one case "alternating").
class K2 : public Scenario {
 public:
  explicit K2(const K2Params& p = K2Params())
      : p_(checked(p)),
        motion_(p.base.dt, p.base.accel_var, VelocityNoise::kWhiteAcceleration),
        stack_(ConstantVelocity2::layout(), p.base.anchors, 2),
        bias_(p.base.nlos_mean, p.base.nlos_std),
        los_(0.0, p.base.sigma_los) {
    for (int b = 0; b < 3; ++b)
      stack_.add_toa(b,
                     {noise::Normal(0.0, p.base.sigma_los),
                      noise::ShiftedNormal(p.base.nlos_mean, std::hypot(p.base.sigma_los, p.base.nlos_std))});
  }

  /// `p` if every field is in range, else std::invalid_argument naming the field (K2Params.base.<field>).
  static const K2Params& checked(const K2Params& p) {
    NLOSLOC_ENSURE(p.period >= 1, "K2Params.period: expected >= 1, got " + std::to_string(p.period));
    K1::checked(p.base, "K2Params.base");
    return p;
  }

  std::string name() const override { return "K2"; }
  std::string description() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    return "Ke & Wu 2011 Sec. 6.2: K1's 3 TOA nodes and noise, every node alternating " +
           std::string(p_.start_nlos ? "NLOS/LOS" : "LOS/NLOS") + " every " + std::to_string(p_.period) +
           " samples, L = " + std::to_string(p_.base.steps) + ", dt = " + f(p_.base.dt) + " s";
  }
  std::vector<std::string> choices() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    const K1Params& p = p_.base;
    const std::string r = f(p.sigma_los) + "^2";
    const std::string bias = "N(" + f(p.nlos_mean) + ", " + f(p.nlos_std) + "^2)";
    const std::string first = p_.start_nlos ? "NLOS" : "LOS", second = p_.start_nlos ? "LOS" : "NLOS";
    std::string init;
    for (int i = 0; i < 4; ++i) init += (i > 0 ? ", " : "") + f(p.initial_std[i]) + "^2";
    const std::string updates = p.iterated_iterations == 1
                                    ? std::string("one update per step")
                                    : std::to_string(p.iterated_iterations) + " updates per step";
    return {
        "all three nodes switch together; samples [0, " + std::to_string(p_.period) + ") " + first + ", [" +
            std::to_string(p_.period) + ", " + std::to_string(2LL * p_.period) + ") " + second +
            ", ... (the paper's 60 s excerpt runs NLOS-LOS-NLOS)",
        "everything else as K1: start " + detail::fmt_point(p.start[0], p.start[1]) + " m, NLOS error " +
            (p.nlos_nonnegative ? "max(0, " + bias + ")" : bias) +
            " drawn every step, initial belief truth + N(0, diag(" + init + ")), first " +
            std::to_string(p.discard) + " samples left out",
        "estimators as in K1 (proposed: gamma = " + f(p.gamma) + ", R = " + r +
            " I, QP referenced to the prediction; iterated NLOS EKF: bias random walk " +
            f(p.iterated_bias_walk_std) + " m/step, prior N(0, " + f(p.iterated_bias_prior_std) + "^2), " +
            updates + "; EKF: R = " + r + " I; proposed-soft: soft threshold lambda = 1)",
        "identification accuracy: the proposed tracker's eq. (32) decision (global, given to every node) "
        "against the true sight, per sample; ranging error of an estimator: | ||p^ - a_i|| - d_i |",
    };
  }
  std::vector<std::string> cases() const override { return {"alternating"}; }
  int steps() const override { return p_.base.steps; }
  double dt() const override { return p_.base.dt; }
  MatX anchors() const override { return p_.base.anchors; }
  int discard() const override { return p_.base.discard; }
  int state_dim() const override { return ConstantVelocity2::kDim; }
  const MeasurementStack& measurements() const override { return stack_; }
  std::string paper_source() const override {
    return "Ke & Wu 2011 Sec. 6.2, Figs. 3-5 (qualitative: proposed tracks the true range in NLOS; eq. (32) "
           "identifies the changes except a few false points at the start)";
  }

  const K2Params& params() const { return p_; }
  const ConstantVelocity2& motion() const { return motion_; }
  /// True when the nodes are NLOS at sample k.
  bool nlos_at(int k) const { return ((k / p_.period) % 2 == 0) == p_.start_nlos; }

 protected:
  void generate(int /*c*/, int T, Rng& rng, Draw& d) const override {
    constexpr int B = 3;
    const K1Params& p = p_.base;
    d.states.resize(T, 4);
    d.positions.resize(T, 2);
    d.y.resize(T, B);
    d.sight.resize(T, B);
    d.quality.setConstant(T, B, std::numeric_limits<double>::quiet_NaN());
    Vec<4> x;
    x << p.start, p.velocity;
    ke_wu_initial_belief(x, p.initial_std, rng, d);
    const double sa = std::sqrt(p.accel_var), dt = p.dt;
    for (int k = 0; k < T; ++k) {
      if (k > 0) ke_wu_advance(motion_, sa, dt, rng, x);  // Ke & Wu eqs. (16)-(17)
      d.states.row(k) = x.transpose();
      d.positions.row(k) = x.head<2>().transpose();
      const bool nlos = nlos_at(k);
      for (int b = 0; b < B; ++b) {
        // Ke & Wu eqs. (1)-(2).
        double z = (x.head<2>() - p.anchors.row(b).transpose()).norm() + los_.sample(rng);
        if (nlos) {
          const double nb = bias_.sample(rng);
          z += p.nlos_nonnegative ? std::max(nb, 0.0) : nb;  // as K1: Ke & Wu Sec. 2, b_i(k) >= 0
        }
        d.y(k, b) = z;
        d.sight(k, b) = nlos ? 1 : 0;
      }
    }
  }

 private:
  K2Params p_;
  ConstantVelocity2 motion_;
  MeasurementStack stack_;
  noise::ShiftedNormal bias_;
  noise::Normal los_;
};

/// K2 "proposed" (as K1's).
inline std::unique_ptr<Estimator> make_k2_proposed(const K2& s, int /*case_index*/) {
  return make_k1_qp_bias_ekf(K1::kProposed, s.params().base, s.motion(), 0.0);
}
/// K2 "proposed-soft" (as K1's).
inline std::unique_ptr<Estimator> make_k2_proposed_soft(const K2& s, int /*case_index*/) {
  return make_k1_qp_bias_ekf(K1::kProposedSoft, s.params().base, s.motion(), K1::kSoftThreshold);
}
/// K2 "iterated-NLOS-EKF" (as K1's).
inline std::unique_ptr<Estimator> make_k2_iterated(const K2& s, int /*case_index*/) {
  const K1Params& p = s.params().base;
  mitigation::BiasAugmentedEkfOptions o;
  o.noise.sigma0 = p.sigma_los;
  o.bias_prior_std = p.iterated_bias_prior_std;
  o.bias_walk_std = p.iterated_bias_walk_std;
  o.iterations = p.iterated_iterations;
  return std::make_unique<BiasAugmentedEkfEstimator>(
      K1::kIterated, mitigation::BiasAugmentedEkf(s.motion(), p.anchors, Gaussian<4>(), o));
}
/// K2 "EKF" (as K1's: R = 50^2 I, LOS assumed).
inline std::unique_ptr<Estimator> make_k2_ekf(const K2& s, int /*case_index*/) {
  return make_filter_estimator(K1::kEkf, Ekf<ConstantVelocity2>(s.motion(), s.measurements(), Gaussian<4>()),
                               SightPolicy::kAssumeLos);
}

/// Registers K2 and its estimators (one line each).
inline void register_k2(Registry& r) {
  r.add_scenario<K2>();
  if (mitigation::have_default_box_qp()) r.add_estimator<K2>("K2", K1::kProposed, make_k2_proposed);
  r.add_estimator<K2>("K2", K1::kIterated, make_k2_iterated);
  r.add_estimator<K2>("K2", K1::kEkf, make_k2_ekf);
  if (mitigation::have_default_box_qp()) r.add_estimator<K2>("K2", K1::kProposedSoft, make_k2_proposed_soft);
}

/// Per-estimator output of the K2 study (means over runs).
struct K2EstimatorStudy {
  std::string name;
  VecX position_error;  ///< T: mean ||p^_k - p_k|| (m)
  RowMatX range_error;  ///< T x B: mean | ||p^_k - a_i|| - d_i(k) | (m)
  VecX identification;  ///< T: fraction of (run, node) pairs whose sight was identified; empty if none
};

/// The K2 study: Figs. 3-5 of Ke & Wu Sec. 6.2 as numbers.
struct K2Study {
  int runs = 0, steps = 0, period = 0, discard = 0;
  std::uint64_t first_run = 0;  ///< the runs averaged are first_run .. first_run + runs - 1
  VecXi nlos;                   ///< T: 1 where the nodes are NLOS
  std::vector<K2EstimatorStudy> estimators;
};

/// Runs `estimators` (each made once, with s and case 0) on the draws Rng(seed, r), r = first_run ..
/// first_run + runs - 1, of scenario s, which may carry custom parameters (single thread; the same draws as
/// the Monte Carlo runner with the same first_run), and averages position error, ranging error and
/// identification. `steps` 0 = s.steps(). Throws std::invalid_argument on a bad count, first_run + runs - 1
/// beyond 2^64 - 1, no estimator, a name given twice or a factory that returns null.
inline K2Study run_k2_study(const K2& s, int runs, std::uint64_t seed, int steps,
                            const std::vector<EstimatorSpec>& estimators, std::uint64_t first_run = 0) {
  NLOSLOC_ENSURE(runs >= 1, "runs: expected >= 1, got " + std::to_string(runs));
  detail::check_first_run(first_run, runs);
  NLOSLOC_ENSURE(steps >= 0,
                 "steps: expected >= 0 (0 = the scenario's default), got " + std::to_string(steps));
  check_estimator_specs(estimators);  // results are listed by name, as run_monte_carlo's
  const int T = steps > 0 ? steps : s.steps();
  // as run_monte_carlo: no step left to average gave all-NaN statistics
  NLOSLOC_ENSURE(T > s.discard(), "steps: expected more than the scenario's " + std::to_string(s.discard()) +
                                      " discarded first steps, got " + std::to_string(T));
  const MatX A = s.anchors();
  const auto B = A.rows();
  K2Study st;
  st.runs = runs;
  st.first_run = first_run;
  st.steps = T;
  st.period = s.params().period;
  st.discard = s.discard();
  st.nlos.resize(T);
  for (int k = 0; k < T; ++k) st.nlos[k] = s.nlos_at(k) ? 1 : 0;
  std::vector<std::unique_ptr<Estimator>> est;
  for (const auto& spec : estimators) {
    est.push_back(spec.make(s, 0));
    NLOSLOC_ENSURE(est.back() != nullptr, "estimators: factory of '" + spec.name + "' returned null");
    K2EstimatorStudy e;
    e.name = spec.name;
    e.position_error.setZero(T);
    e.range_error.setZero(T, B);
    if (est.back()->estimates_sight()) e.identification.setZero(T);
    st.estimators.push_back(std::move(e));
  }
  VecX pos(2), o(B);
  VecXi sight(B);
  for (int r = 0; r < runs; ++r) {
    const std::uint64_t run = first_run + static_cast<std::uint64_t>(r);
    const Draw d = s.draw("alternating", seed, run, T);
    for (std::size_t e = 0; e < est.size(); ++e) {
      Rng rng(estimator_seed(seed, estimators[e].name), run);
      est[e]->reset(d, rng);
      auto& out = st.estimators[e];
      for (int k = 0; k < T; ++k) {
        const VecX y = d.y.row(k).transpose();
        o = d.quality.row(k).transpose();
        est[e]->step(k, y, o, pos);
        const Vec<2> p = d.positions.row(k).transpose();
        out.position_error[k] += (pos - p).norm() / runs;
        for (Eigen::Index b = 0; b < B; ++b) {
          const Vec<2> a = A.row(b).transpose();
          out.range_error(k, b) += std::abs((pos - a).norm() - (p - a).norm()) / runs;
        }
        if (out.identification.size() > 0) {
          est[e]->sight_estimate(sight);
          int hits = 0;
          for (Eigen::Index b = 0; b < B; ++b) hits += sight[b] == d.sight(k, b);
          out.identification[k] += static_cast<double>(hits) / static_cast<double>(B) / runs;
        }
      }
    }
  }
  return st;
}

/// The study of the registry's K2 with the estimators registered for it (all, or `names`).
inline K2Study run_k2_study(const Registry& reg, int runs, std::uint64_t seed, int steps = 0,
                            std::vector<std::string> names = {}, std::uint64_t first_run = 0) {
  const auto* s = dynamic_cast<const K2*>(&reg.scenario("K2"));
  NLOSLOC_ENSURE(s != nullptr, "run_k2_study: the registry's K2 is not a sim::K2");
  if (names.empty()) names = reg.estimators("K2");
  std::vector<EstimatorSpec> specs;
  for (const auto& n : names) specs.push_back({n, reg.estimator("K2", n)});
  return run_k2_study(*s, runs, seed, steps, specs, first_run);
}

/// Text summary of the K2 study: per estimator, mean position and ranging errors in NLOS and LOS blocks,
/// identification accuracy overall, per sight, in the first 5 samples after each switch and elsewhere.
inline std::string format_k2_study(const K2Study& st) {
  std::string out;
  char b[512];
  std::snprintf(b, sizeof b,
                "K2 study: %s x %d steps, nodes switch every %d samples, statistics over k >= %d\n",
                detail::runs_label(st.runs, st.first_run).c_str(), st.steps, st.period, st.discard);
  out += b;
  std::snprintf(b, sizeof b, "  %-20s %12s %12s %12s %12s %10s %10s %10s %10s %10s\n", "estimator",
                "pos NLOS m", "pos LOS m", "range NLOS", "range LOS", "ident all", "ident NLOS", "ident LOS",
                "ident <5", "ident >=5");
  out += b;
  for (const auto& e : st.estimators) {
    double pn = 0, pl = 0, rn = 0, rl = 0, ia = 0, in = 0, il = 0, i5 = 0, ir = 0;
    int cn = 0, cl = 0, c5 = 0, cr = 0;
    const bool ident = e.identification.size() > 0;
    for (int k = st.discard; k < st.steps; ++k) {
      const bool nl = st.nlos[k] != 0;
      const double re = e.range_error.row(k).mean();
      const double id = ident ? e.identification[k] : 0.0;
      (nl ? pn : pl) += e.position_error[k];
      (nl ? rn : rl) += re;
      (nl ? in : il) += id;
      (nl ? cn : cl) += 1;
      ia += id;
      const bool near_switch = (k % st.period) < 5 && k >= st.period;
      (near_switch ? i5 : ir) += id;
      (near_switch ? c5 : cr) += 1;
    }
    const auto avg = [](double s, int c) { return c > 0 ? s / c : std::nan(""); };
    const int call = cn + cl;
    std::snprintf(b, sizeof b, "  %-20s %12.2f %12.2f %12.2f %12.2f", e.name.c_str(), avg(pn, cn),
                  avg(pl, cl), avg(rn, cn), avg(rl, cl));
    out += b;
    if (ident) {
      std::snprintf(b, sizeof b, " %10.3f %10.3f %10.3f %10.3f %10.3f\n", avg(ia, call), avg(in, cn),
                    avg(il, cl), avg(i5, c5), avg(ir, cr));
    } else {
      std::snprintf(b, sizeof b, " %10s %10s %10s %10s %10s\n", "-", "-", "-", "-", "-");
    }
    out += b;
  }
  // Fig. 5 analogue: the first identifying estimator's accuracy in the 10 samples after the second switch
  // (k = 2 period, past the transient), when the run reaches it.
  const int sw = 2 * st.period;
  for (const auto& e : st.estimators) {
    if (e.identification.size() == 0 || sw >= st.steps) continue;
    out += "  " + e.name + " identification per sample (mean over runs), k = 0..9 after the switch at " +
           std::to_string(sw) + ": ";
    for (int k = sw; k < std::min(st.steps, sw + 10); ++k) {
      std::snprintf(b, sizeof b, "%.2f ", e.identification[k]);
      out += b;
    }
    out += "\n";
    break;
  }
  return out;
}

}  // namespace nlosloc::sim
