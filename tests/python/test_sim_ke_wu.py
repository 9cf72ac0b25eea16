"""nlosloc.sim parity with C++: K1-K3 with their parameters, the K2 study, the summaries and
tables of report.hpp, estimator_seed and percentile."""

from __future__ import annotations

import re

import numpy as np
import pytest

from nlosloc import sim

CASE = "2LOS/1NLOS"


def test_k1_params_defaults_are_the_papers_and_are_checked() -> None:
    p = sim.K1Params()
    # Ke & Wu Sec. 6 and 6.1
    np.testing.assert_array_equal(p.anchors, [[0, 0], [8600, 0], [4300, 7500]])
    assert (p.sigma_los, p.nlos_mean, p.nlos_std) == (50.0, 513.0, 436.0)
    np.testing.assert_array_equal(p.velocity, [10.0, 15.0])
    assert (p.steps, p.dt, p.discard, p.accel_var, p.gamma) == (2000, 0.1, 100, 1.0, 1.1)
    with pytest.raises(
        ValueError, match=r"^K1Params\.anchors: expected shape \(3, 2\), got \(2, 2\)$"
    ):
        p.anchors = np.zeros((2, 2))
    with pytest.raises(
        ValueError, match=r"^K1Params\.start: expected shape \(2, 1\), got \(3, 1\)$"
    ):
        p.start = [1.0, 2.0, 3.0]
    p.sigma_los = 0.0
    with pytest.raises(ValueError, match=r"^K1Params\.sigma_los: expected a finite value > 0"):
        sim.K1(p)
    p = sim.K1Params()
    p.nlos_mean = 0.0  # was refused by the NLOS noise model, as "ShiftedNormal: shift"
    with pytest.raises(
        ValueError, match=r"^K1Params\.nlos_mean: expected a finite value > 0, got 0"
    ):
        sim.K1(p)
    q = sim.K2Params()
    q.base.nlos_mean = -50.0
    with pytest.raises(
        ValueError, match=r"^K2Params\.base\.nlos_mean: expected a finite value > 0"
    ):
        sim.K2(q)
    p = sim.K1Params()
    p.gamma = 0.5
    with pytest.raises(ValueError, match=r"^K1Params\.gamma: expected a finite value >= 1"):
        sim.K1(p)
    # K2Params.base is edited in place, and K2's messages name it.
    q = sim.K2Params()
    q.base.steps = 5
    assert q.base.steps == 5
    with pytest.raises(ValueError, match=r"^K2Params\.base: expected 0 <= discard < steps"):
        sim.K2(q)
    q = sim.K2Params()
    q.period = 0
    with pytest.raises(ValueError, match=r"^K2Params\.period: expected >= 1, got 0$"):
        sim.K2(q)
    r = sim.K3Params()
    np.testing.assert_array_equal(r.bad, [[0, 0], [38, 39], [80, 81], [100, 100]])
    assert (r.sigma_rel, r.nlos_rel, r.threshold, r.steps) == (0.02, 0.08, 5.0, 200)
    r.iterated_iterations = 0
    with pytest.raises(ValueError, match=r"^K3Params\.iterated_iterations: expected >= 1, got 0$"):
        sim.K3(r)


def test_default_objects_draw_what_the_registered_scenarios_draw() -> None:
    for obj, case in ((sim.K1(), CASE), (sim.K2(), "alternating"), (sim.K3(), "bad/3NLOS")):
        a = obj.draw(case, seed=4, run=3, steps=150)
        b = sim.draw(obj.name, case, seed=4, run=3, steps=150)
        for key in ("states", "y", "sight", "initial_mean", "initial_cov"):
            np.testing.assert_array_equal(a[key], b[key])


def test_custom_k1_params_reach_the_draw_and_the_estimators() -> None:
    p = sim.K1Params()
    p.anchors = np.array([[0.0, 0.0], [3000.0, 0.0], [1500.0, 2500.0]])
    p.sigma_los = 4.0
    p.nlos_mean, p.nlos_std = 100.0, 20.0
    s = sim.K1(p)
    np.testing.assert_array_equal(s.anchors, p.anchors)
    d = s.draw("1LOS/2NLOS", seed=2, run=0, steps=1500)
    dist = np.linalg.norm(d["positions"][:, None, :] - p.anchors[None, :, :], axis=2)
    res = d["y"] - dist
    # node 0 LOS: N(0, 4^2); nodes 1, 2 NLOS: 4 + max(0, N(100, 20^2)) noise, mean about 100
    assert abs(res[:, 0].std() - 4.0) < 0.3 and abs(res[:, 0].mean()) < 0.4
    assert abs(res[:, 1:].mean() - 100.0) < 2.0
    np.testing.assert_array_equal(d["sight"][0], [int(sim.K1.is_nlos(2, b)) for b in range(3)])
    assert sim.K1.nlos_count(2) == 2
    # The registered EKF is built from this scenario's models: with sigma_los = 4 m and LOS
    # everywhere it tracks to a few metres (the default 50 m noise gives about ten times more).
    r = sim.run_monte_carlo(s, "3LOS/0NLOS", runs=2, seed=1, estimators=["EKF"], steps=400)
    r0 = sim.run_monte_carlo("K1", "3LOS/0NLOS", runs=2, seed=1, estimators=["EKF"], steps=400)
    e = np.percentile(r["estimators"]["EKF"]["errors"][:, 100:], 67)
    e0 = np.percentile(r0["estimators"]["EKF"]["errors"][:, 100:], 67)
    assert e < 8.0 and e0 > 5 * e
    with pytest.raises(ValueError, match=r"^case_index: expected 0 <= case_index < 4, got 4$"):
        sim.K1.is_nlos(4, 0)
    with pytest.raises(ValueError, match=r"^anchor: expected 0 <= anchor < 3, got 3$"):
        sim.K1.is_nlos(0, 3)


def test_k2_and_k3_accessors_match_their_draws() -> None:
    q = sim.K2Params()
    q.period = 30
    q.start_nlos = False
    s = sim.K2(q)
    d = s.draw("alternating", seed=1, run=0, steps=200)
    expect = np.array([int(s.nlos_at(k)) for k in range(200)])
    np.testing.assert_array_equal(d["sight"][:, 0], expect)
    np.testing.assert_array_equal(expect[:60], [0] * 30 + [1] * 30)
    with pytest.raises(ValueError, match=r"^k: expected a sample index >= 0, got -1$"):
        s.nlos_at(-1)
    k3 = sim.K3()
    for c, case in enumerate(k3.cases):
        d = k3.draw(case, seed=1, run=0, steps=5)
        np.testing.assert_array_equal(d["sight"][0], [int(sim.K3.is_nlos(c, b)) for b in range(4)])
        assert sim.K3.nlos_count(c) == int(case[-5])  # "good/3NLOS" -> 3
        assert sim.K3.bad_geometry(c) == case.startswith("bad")
        geometry = k3.params.bad if case.startswith("bad") else k3.params.good
        np.testing.assert_array_equal(k3.anchors_of(c), geometry)
    with pytest.raises(ValueError, match=r"^case_index: expected 0 <= case_index < 8, got 8$"):
        k3.anchors_of(8)


@pytest.fixture(scope="module")
def k1_result() -> dict:
    return sim.run_monte_carlo("K1", CASE, runs=3, seed=5, threads=1, steps=300)


def test_summarize_against_numpy(k1_result: dict) -> None:
    r = k1_result
    summary = sim.summarize(sim.K1(), r)
    assert (summary.scenario, summary.case, summary.runs, summary.steps, summary.discard) == (
        "K1",
        CASE,
        3,
        300,
        100,
    )
    assert sim.default_levels() == [50.0, 67.0, 90.0, 95.0]
    paper = {
        (v["estimator"], v["metric"]): v["value"]
        for v in sim.scenario_info("K1")["paper"]
        if v["case"] == CASE
    }
    assert [e.name for e in summary.estimators] == list(r["estimators"])
    for e in summary.estimators:
        runs = r["estimators"][e.name]
        pooled = runs["errors"][:, 100:].ravel()
        np.testing.assert_allclose(
            e.percentiles, np.percentile(pooled, [50, 67, 90, 95]), rtol=1e-12
        )
        assert e.at(67.0) == e.percentiles[1] and np.isnan(e.at(68.0))
        assert e.time_per_step_ns == pytest.approx(runs["time_per_step_ns"].mean(), rel=1e-12)
        assert e.paper_p67 == paper.get((e.name, "p67"))
        assert e.paper_p95 == paper.get((e.name, "p95"))
        if "sight_anchor_accuracy" in runs:
            assert e.sight_accuracy == pytest.approx(
                runs["sight_anchor_accuracy"].mean(), rel=1e-12
            )
        else:
            assert e.sight_accuracy is None
    assert sim.K1().paper_value("EKF", CASE, "p67") == paper[("EKF", "p67")]
    with pytest.raises(ValueError, match="^case: unknown case 'no such case' of scenario K1"):
        sim.K1().paper_value("EKF", "no such case", "p67")  # was None, as for "nothing published"
    assert len(sim.K1().paper) == len(sim.scenario_info("K1")["paper"])
    # by name, with other levels
    other = sim.summarize("K1", r, levels=[10.0, 99.0])
    pooled = r["estimators"]["EKF"]["errors"][:, 100:].ravel()
    np.testing.assert_allclose(other.estimators[0].percentiles, np.percentile(pooled, [10, 99]))


def test_summarize_refuses_a_result_it_cannot_read(k1_result: dict) -> None:
    with pytest.raises(ValueError, match=r"^result: is a run of scenario 'K1', not of 'H1'$"):
        sim.summarize("H1", k1_result)
    bad = dict(k1_result)
    del bad["discard"]
    with pytest.raises(
        ValueError, match=r"^result: expected the dict of run_monte_carlo, missing key 'discard'$"
    ):
        sim.summarize("K1", bad)
    bad = dict(k1_result)
    bad["estimators"] = {"EKF": dict(k1_result["estimators"]["EKF"])}
    bad["estimators"]["EKF"]["errors"] = bad["estimators"]["EKF"]["errors"][:2]
    with pytest.raises(
        ValueError,
        match=re.escape(
            "result['estimators']['EKF']['errors']: expected shape (3, 300), got (2, 300)"
        ),
    ):
        sim.summarize("K1", bad)
    with pytest.raises(ValueError, match=r"^levels: expected percentage levels in \[0, 100\]"):
        sim.summarize("K1", k1_result, levels=[50.0, 101.0])


def test_tables_carry_the_summary(k1_result: dict) -> None:
    summary = sim.summarize("K1", k1_result)
    t = sim.format_table(summary)
    assert t.startswith(f"K1 case {CASE}: 3 runs x 300 steps, errors over steps k >= 100")
    for e in summary.estimators:
        row = next(line for line in t.splitlines() if line.split()[:1] == [e.name])
        assert f"{e.at(67.0):10.2f}" in row and f"{e.paper_p67:10.2f}" in row
        assert f"{e.at(67.0) / e.paper_p67:10.3f}" in row
    p = sim.format_percentile_table(summary)
    assert "ours 50%" in p and "paper" not in p
    ekf = summary.estimators[0]
    assert "".join(f" {v:10.2f}" for v in ekf.percentiles) in p
    # H1's paper gives CDFs only: format_table falls back to the percentile table.
    h1 = sim.run_monte_carlo("H1", "default", runs=1, seed=1, estimators=["EKF-LOS"], steps=60)
    hs = sim.summarize("H1", h1)
    assert sim.format_table(hs) == sim.format_percentile_table(hs)
    c = sim.format_choices("K1")
    assert c == sim.format_choices(sim.K1())
    assert c.startswith("K1: " + sim.scenario_info("K1")["description"])
    assert "  1. " + sim.scenario_info("K1")["choices"][0] in c


def test_format_k3_probability_against_numpy() -> None:
    r = sim.run_monte_carlo("K3", "bad/4NLOS", runs=2, seed=3, threads=1)
    text = sim.format_k3_probability(r, threshold=2.0)
    lines = text.splitlines()
    assert len(lines) == len(r["estimators"])
    for line, (name, e) in zip(lines, r["estimators"].items(), strict=True):
        p = np.mean(e["errors"][:, r["discard"] :] <= 2.0)
        assert line == f"  K3 {'bad/4NLOS':<11} {name:<20} P(error <= 2 m) = {p:.3f}"
    with pytest.raises(ValueError, match=r"^threshold: expected a finite value > 0"):
        sim.format_k3_probability(r, threshold=0.0)
    # the line names the result's scenario (it said K3 for any)
    r = sim.run_monte_carlo("K1", "2LOS/1NLOS", 1, 1, ["EKF"], steps=105)
    assert sim.format_k3_probability(r).startswith("  K1 2LOS/1NLOS  EKF ")


def test_k2_study_is_the_monte_carlo_runs_averaged() -> None:
    names = ["proposed", "EKF"]
    st = sim.run_k2_study(3, seed=7, steps=450, estimators=names)
    assert (st.runs, st.steps, st.period, st.discard) == (3, 450, 200, 100)
    np.testing.assert_array_equal(st.nlos, [int(sim.K2().nlos_at(k)) for k in range(450)])
    mc = sim.run_monte_carlo(
        "K2", "alternating", runs=3, seed=7, estimators=names, steps=450, threads=1
    )
    assert [e.name for e in st.estimators] == names
    for e in st.estimators:
        np.testing.assert_allclose(
            e.position_error, mc["estimators"][e.name]["errors"].mean(axis=0), rtol=1e-12, atol=1e-9
        )
        assert e.range_error.shape == (450, 3)
    assert st.estimators[1].identification is None
    ident = st.estimators[0].identification
    np.testing.assert_allclose(
        ident, mc["estimators"]["proposed"]["sight_accuracy"].mean(axis=0), atol=1e-12
    )
    text = sim.format_k2_study(st)
    assert text.startswith("K2 study: 3 runs x 450 steps, nodes switch every 200 samples")
    assert "after the switch at 400: " + " ".join(f"{v:.2f}" for v in ident[400:410]) in text
    # a run that ends before the second switch has no such line
    assert "after the switch" not in sim.format_k2_study(sim.run_k2_study(1, 7, steps=300))
    with pytest.raises(ValueError, match=r"^runs: expected >= 1, got 0$"):
        sim.run_k2_study(0, 1)
    with pytest.raises(ValueError, match=r"^steps: expected >= 1"):
        sim.run_k2_study(1, 1, steps=0)


def test_estimator_seed_is_fnv1a_of_the_name() -> None:
    def fnv(seed: int, name: str) -> int:
        h = 0xCBF29CE484222325
        for ch in name.encode():
            h = ((h ^ ch) * 0x100000001B3) % 2**64
        return seed ^ h ^ 0xE57A000000000001

    for seed, name in ((1, "EKF"), (2**64 - 1, "rRBPF-128"), (0, "")):
        assert sim.estimator_seed(seed, name) == fnv(seed, name)
    with pytest.raises(
        ValueError, match=r"^seed: expected an integer in \[0, 2\*\*64 - 1\], got -1$"
    ):
        sim.estimator_seed(-1, "EKF")


def test_percentile_is_numpys() -> None:
    x = np.random.default_rng(3).exponential(size=101)
    for q in (0.0, 12.5, 50.0, 67.0, 100.0):
        assert sim.percentile(x, q) == pytest.approx(np.percentile(x, q), rel=1e-14)
    assert np.isnan(sim.percentile([], 50.0))
    with pytest.raises(ValueError, match=r"^q: expected a percentage in \[0, 100\], got 101"):
        sim.percentile(x, 101.0)
