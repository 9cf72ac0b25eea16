"""Rng jumps and the particle filter's BatchRng: lane derivation, ranges, distributions."""

import platform

import numpy as np
import pytest
from scipy import stats

from nlosloc.core import BatchRng, Rng


def test_jump_changes_state_and_clears_nothing_else():
    a, b = Rng(11), Rng(11)
    assert a.state() == b.state()
    a.jump()
    assert a.state() != b.state()
    # a jump is a fixed map of the state: generators with equal states stay equal after it
    b.jump()
    assert a.state() == b.state()
    assert [a() for _ in range(5)] == [b() for _ in range(5)]


def test_batch_lanes_are_the_parent_jumped_l_plus_one_times():
    parent = Rng(5, 2)
    before = parent.state()
    words = BatchRng(parent).bits(16)
    assert words.dtype == np.uint64 and words.shape == (64,)
    assert parent.state() == before  # the parent is not advanced
    for lane in range(4):
        ref = Rng(5, 2)
        for _ in range(lane + 1):
            ref.jump()
        assert [int(w) for w in words[lane::4]] == [ref() for _ in range(16)]


def test_batch_uniforms_and_normals_are_distributed_as_claimed():
    g = BatchRng(Rng(9))
    u = g.uniforms(200_000)
    assert u.shape == (200_000,)
    assert 0.0 < u.min() and u.max() < 1.0
    # (k + 1/2) 2^-52: every value is an odd multiple of 2^-53
    k = u[:1000] * 2.0**53
    np.testing.assert_array_equal(k, np.round(k))
    assert np.all(np.round(k) % 2 == 1)
    assert stats.kstest(u, "uniform").pvalue > 1e-3
    z = g.normals(200_000)
    assert stats.kstest(z, "norm").pvalue > 1e-3
    assert abs(z.mean()) < 5 / np.sqrt(z.size)
    assert abs(z.var() - 1.0) < 5 * np.sqrt(2 / z.size)
    # the ziggurat tail beyond R = 3.654 has the normal's mass (5-sigma binomial band)
    p = 2 * stats.norm.sf(3.6541528853610088)
    n_tail = int(np.sum(np.abs(z) > 3.6541528853610088))
    assert abs(n_tail - p * z.size) < 5 * np.sqrt(p * z.size) + 1
    single = [g.uniform() for _ in range(100)]
    assert all(0.0 < x < 1.0 for x in single)
    assert isinstance(g(), int)


def test_batch_is_reproducible_and_rejects_bad_sizes():
    np.testing.assert_array_equal(BatchRng(Rng(3)).normals(1001), BatchRng(Rng(3)).normals(1001))
    g = BatchRng(Rng(3))
    with pytest.raises(ValueError, match="n: expected a multiple of 4"):
        g.uniforms(6)
    with pytest.raises(ValueError, match="n: expected 0 <= n"):
        g.normals(-1)
    with pytest.raises(ValueError, match="n_quads"):
        g.bits(-2)
    assert g.uniforms(0).shape == (0,)


def test_batch_avx2_refills_give_the_same_draws():
    """use_avx2(True) moves the refills to AVX2 registers where the CPU has AVX2: the same words,
    uniforms and normals as the default refills, from the same parent, whatever is drawn between."""
    narrow, wide = BatchRng(Rng(21, 4)), BatchRng(Rng(21, 4))
    assert not narrow.uses_avx2
    wide.use_avx2(True)
    try:
        with open("/proc/cpuinfo") as f:
            has_avx2 = any(line.startswith("flags") and " avx2" in line for line in f)
    except OSError:
        has_avx2 = False
    assert wide.uses_avx2 == (has_avx2 and platform.machine() == "x86_64")
    for n in (1, 63, 64, 65, 1000, 4097):
        np.testing.assert_array_equal(narrow.normals(n), wide.normals(n))
        np.testing.assert_array_equal(narrow.uniforms(4 * n), wide.uniforms(4 * n))
        np.testing.assert_array_equal(narrow.bits(n), wide.bits(n))
        assert narrow.uniform() == wide.uniform() and narrow() == wide()
    assert narrow.save_state() == wide.save_state()  # the flag is not part of the state
    wide.use_avx2(False)
    assert not wide.uses_avx2
    with pytest.raises(TypeError, match="on"):
        wide.use_avx2(1)
