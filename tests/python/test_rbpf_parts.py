"""The RBPF's building blocks from Python, against brute force: the offspring enumerations (eq. 23
and the bounded best-first one), the prune selection, the parallel merge (equal to the serial
one), the column-wise measurement prediction and the snapshot baselines' solver."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from nlosloc import rbpf, sim, snapshot


def brute(a: np.ndarray) -> list[tuple[int, float]]:
    """(key, sum) of every situation vector of the log factors a (B, N_z), in key order."""
    b, nz = a.shape
    out = []
    for s in itertools.product(range(nz), repeat=b):
        s = s[::-1]  # anchor 0 varies fastest, as the keys' least significant digit
        out.append((rbpf.encode_situation(list(s), nz), float(sum(a[i, s[i]] for i in range(b)))))
    return sorted(out)


def test_enumerations_against_brute_force() -> None:
    rng = np.random.default_rng(5)
    a = rng.normal(size=(4, 3))  # 81 situation vectors
    full = brute(a)
    keys, sums = rbpf.enumerate_offspring(a, 81)
    assert keys.dtype == np.uint64
    assert [int(k) for k in keys] == [k for k, _ in full]  # all of them, in key order
    np.testing.assert_allclose(sums, [v for _, v in full], rtol=0, atol=1e-12)
    best = sorted(full, key=lambda kv: -kv[1])
    for limit in [1, 7, 80]:  # bounded: the `limit` heaviest, heaviest first
        keys, sums = rbpf.enumerate_offspring(a, limit)
        assert [int(k) for k in keys] == [k for k, _ in best[:limit]]
        np.testing.assert_allclose(sums, [v for _, v in best[:limit]], rtol=0, atol=1e-12)
        k2, s2 = rbpf.enumerate_best(a, limit)
        np.testing.assert_array_equal(k2, keys)
    keys, _ = rbpf.enumerate_best(a, 1000)  # limit above N_z^B: every vector, best first
    assert [int(k) for k in keys] == [k for k, _ in best]
    # a condition ruled out (-inf) sinks every vector that uses it
    a[0, 1] = -np.inf
    keys, sums = rbpf.enumerate_best(a, 81)
    assert np.all(np.isinf(sums[54:])) and np.all(np.isfinite(sums[:54]))
    # two ruled out, and a whole anchor: impossible vectors weigh -inf in both enumerations, never
    # NaN (the full one's running sum once gave -inf - (-inf))
    a[2, 0] = -np.inf
    for rows in (a, np.vstack([a[:3], np.full((1, 3), -np.inf)])):
        full = brute(rows)
        keys, sums = rbpf.enumerate_offspring(rows, 81)
        assert [int(k) for k in keys] == [k for k, _ in full]
        np.testing.assert_allclose(sums, [v for _, v in full], rtol=0, atol=1e-12)
        keys, sums = rbpf.enumerate_best(rows, 81)
        assert not np.isnan(sums).any()
        order = np.argsort(keys)
        assert [int(k) for k in keys[order]] == [k for k, _ in full]
        np.testing.assert_allclose(sums[order], [v for _, v in full], rtol=0, atol=1e-12)


def test_enumeration_arguments_are_checked() -> None:
    with pytest.raises(ValueError, match="A: expected log factors that are finite or -inf"):
        rbpf.enumerate_offspring(np.array([[0.0, np.nan]]), 4)
    with pytest.raises(ValueError, match=r"A: expected \(B, N_z\) log factors"):
        rbpf.enumerate_best(np.zeros((0, 2)), 4)
    with pytest.raises(ValueError, match="limit: expected an integer >= 1"):
        rbpf.enumerate_best(np.zeros((2, 2)), 0)
    with pytest.raises(
        ValueError, match="would return 1073741824 situation vectors; expected at most"
    ):
        rbpf.enumerate_offspring(np.zeros((30, 2)), 2**30)


def test_select_top_is_the_prune_step() -> None:
    logw = np.array([0.1, -np.inf, 0.5, 0.5, -1.0])
    assert rbpf.select_top(logw, 3) == [2, 3, 0]  # heaviest first, ties by index
    assert rbpf.select_top(logw, 10) == [2, 3, 0, 4]  # -inf never kept
    rng = np.random.default_rng(2)
    w = rng.normal(size=500)
    assert rbpf.select_top(w, 50) == list(np.argsort(-w, kind="stable")[:50])
    with pytest.raises(ValueError, match="logw: expected log weights that are finite or -inf"):
        rbpf.select_top(np.array([0.0, np.nan]), 1)
    with pytest.raises(ValueError, match="M: expected an integer >= 1"):
        rbpf.select_top(w, 0)


def test_parallel_merge_equals_the_serial_one() -> None:
    rng = np.random.default_rng(9)
    n = 20000
    keys = rng.integers(0, 64, n).astype(np.uint64)  # few situations: many groups with members
    means = rng.normal(scale=3.0, size=(2, n))
    logw = rng.normal(size=n)
    logw[::97] = -np.inf
    serial, n1 = rbpf.merge_greedy(keys, means, logw, 0.05)
    for threads in [2, 3]:
        par, n2 = rbpf.merge_greedy(keys, means, logw, 0.05, threads=threads)
        np.testing.assert_array_equal(par, serial)
        assert n2 == n1
    assert n1 > 100  # it merged
    with pytest.raises(ValueError, match="keys: expected values below 2"):
        rbpf.merge_greedy(keys + np.uint64(2**32), means, logw, 0.05, threads=2)
    with pytest.raises(ValueError, match="with_pairs: not available with threads > 1"):
        rbpf.merge_greedy(keys, means, logw, 0.05, with_pairs=True, threads=2)
    with pytest.raises(ValueError, match="threads: expected an integer >= 1"):
        rbpf.merge_greedy(keys, means, logw, 0.05, threads=0)


def test_predict_columns_is_predict_per_column() -> None:
    for s in [sim.H1(), sim.H2()]:
        m = s.measurements
        rng = np.random.default_rng(1)
        x = rng.normal(scale=300.0, size=(s.state_dim, 17))
        z = m.predict_columns(x, 0.25)
        assert z.shape == (m.rows, 17)
        for k in range(17):
            np.testing.assert_allclose(z[:, k], m.predict(x[:, k], 0.25), rtol=1e-14, atol=1e-12)
        with pytest.raises(ValueError, match=r"X: expected shape \("):
            m.predict_columns(np.zeros((s.state_dim + 1, 3)))


def test_snapshot_baselines_give_their_solver() -> None:
    h2 = sim.H2()
    chen = snapshot.Chen(h2.measurements)
    los = chen.solver
    assert los.unknowns == chen.unknowns == 3 and los.has_clock  # RTOA: position and clock bias
    d = h2.draw("default", 1, 0, 5)
    theta0 = np.append(d["initial_mean"][:2], d["initial_mean"][2])
    fix = los.solve(d["y"][0], theta0)
    assert fix.converged
    mle = snapshot.MleLos(h2.measurements)
    mle.reset(theta0)
    np.testing.assert_allclose(mle.solve(d["y"][0])["theta"], fix.theta, atol=1e-6)
