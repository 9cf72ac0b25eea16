#!/usr/bin/env python3
"""Two-thread speed-up of the RBPF benchmarks, measured in lockstep or in interleaved pairs.

On a shared 2-vCPU machine the time per step drifts by up to 2x within seconds, and each vCPU on
its own. The default method (--method lockstep) runs nlosloc-micro's BM_RbpfPaired: 1-thread
filters pinned to CPU 0 and to CPU 1 and a 2-thread filter (thread 0 on CPU 0, its worker on CPU 1)
step the same track in rotating blocks (64 steps additive, 16 augmented), so all three see the same
host; its speed-up is the mean 1-thread time over the 2-thread time. --method pairs runs BM_Rbpf
on 1 thread and on 2 back to back (each --min-time seconds) and takes their ratio. Either way the
median over rounds is the speed-up.

--ceiling adds, in every round, BM_SplitCeiling in lockstep: a synthetic step of the same length and
the same eight exchanges between the cores whose work divides exactly in two, with no line shared
between the threads (the host's and the pool's ceiling for the filter's speed-up) and with every
line from the other core (each phase updates the lines the other core updated last).

--concurrent adds, in every round of each case, BM_RbpfConcurrent in lockstep: two 1-thread
filters of that case stepped at the same time, one per CPU, against one alone. Nothing passes
between them. With each thread's rate summed, their throughput ratio is what the host's two CPUs
give this filter's work, which no 2-thread filter can beat (a host whose CPUs slow each other down
caps it below 2); timed to each block's join, the slower of the pair sets it, as it would a split
into fixed halves.

    python3 bench/tools/rbpf_speedup.py [--micro build/test/bench/nlosloc-micro] [--rounds 6]
        [--method lockstep|pairs] [--case reordered:1/M:128/augmented:0 ...] [--min-time 1]
        [--ceiling] [--concurrent]

Standard library only. Prints one line per round and a summary per case.
"""

import argparse
import json
import re
import statistics
import subprocess
import sys

# rRBPF-128 (additive, augmented) and cRBPF-128 (M = 2 propagated, 128 UKF runs; additive)
DEFAULT_CASES = [
    "reordered:1/M:128/augmented:0",
    "reordered:1/M:128/augmented:1",
    "reordered:0/M:2/augmented:0",
]
# BM_RbpfPaired's registered block lengths (bench/micro_rbpf.cpp)
PAIRED_BLOCK = {"0": 64, "1": 16}


def run_micro(micro, name, min_time):
    """Google Benchmark's JSON entry of the benchmark called `name` (exact)."""
    out = subprocess.run(
        [
            micro,
            f"--benchmark_filter=^{re.escape(name)}$",
            f"--benchmark_min_time={min_time}",
            "--benchmark_format=json",
        ],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    # No match: Google Benchmark writes nothing to stdout.
    for b in json.loads(out)["benchmarks"] if out.strip() else []:
        if b["name"] == name:
            if b.get("error_occurred"):
                raise RuntimeError(f"{name}: {b.get('error_message', 'error')}")
            return b
    raise RuntimeError(f"no result for {name}; is it registered in {micro}?")


def lockstep_result(micro, name, min_time, *extra):
    """(1-thread us, the mean of its two CPUs; 2-thread us; speed-up; then the counters named in
    extra) of a benchmark timed by time_lockstep (bench/micro_rbpf.cpp), from its counters."""
    b = run_micro(micro, name, min_time)
    return (0.5 * (b["t1_cpu0_us"] + b["t1_cpu1_us"]), b["t2_us"], b["speedup"]) + tuple(
        b[key] for key in extra
    )


def spread(values, kind):
    """A summary's "median (min, max, rounds)" of per-round ratios."""
    return (
        f"{statistics.median(values):.3f} (min {min(values):.3f}, max {max(values):.3f}, "
        f"{len(values)} {kind} rounds)"
    )


def parse_case(case):
    """The key:value pairs of a --case; ValueError naming it unless reordered and M are there."""
    pairs = [p.split(":") for p in case.split("/")]
    if any(len(p) != 2 or not p[0] or not p[1] for p in pairs):
        raise ValueError(f"--case {case}: expected key:value pairs joined by '/'")
    parts = dict(pairs)
    missing = [k for k in ("reordered", "M") if k not in parts]
    if missing:
        raise ValueError(f"--case {case}: missing {', '.join(missing)} (e.g. reordered:1/M:128)")
    return parts


def paired_name(case, bench):
    """The name of BM_RbpfPaired's (or BM_RbpfConcurrent's) run of a BM_Rbpf case."""
    parts = parse_case(case)
    aug = parts.get("augmented", "0")
    if aug not in PAIRED_BLOCK:
        raise ValueError(f"--case {case}: augmented must be 0 or 1")
    return (
        f"{bench}/reordered:{parts['reordered']}/M:{parts['M']}/augmented:{aug}"
        f"/block:{PAIRED_BLOCK[aug]}/real_time"
    )


def lockstep(micro, case, min_time):
    """(1-thread us, 2-thread us, speed-up) of BM_RbpfPaired for a BM_Rbpf case."""
    return lockstep_result(micro, paired_name(case, "BM_RbpfPaired"), min_time)


def concurrent(micro, case, min_time):
    """(1-thread us, speed-up of two 1-thread filters at once with their rates summed, and timed
    to each block's join) of BM_RbpfConcurrent for a BM_Rbpf case."""
    name = paired_name(case, "BM_RbpfConcurrent")
    t1, _, rates, joined = lockstep_result(micro, name, min_time, "speedup_joined")
    return t1, rates, joined


# BM_SplitCeiling's cases: 7 phases (eight exchanges, as a reordered step that merges), each core
# keeping its lines (cross:0) or the halves swapped at every phase (cross:1)
CEILING_CASES = {"no shared line": 0, "every line from the other core": 1}


# BM_RbpfConcurrent's two measures of the pair: its rates summed (what the CPUs give), and its wall
# time to each block's join (the slower of the two sets it)
CONCURRENT_LABELS = ("rates summed", "to the join")


def ceiling(micro, min_time):
    """{label: (1-thread us, 2-thread us, speed-up)} of BM_SplitCeiling's two cases."""
    return {
        label: lockstep_result(
            micro, f"BM_SplitCeiling/phases:7/cross:{cross}/block:64/real_time", min_time
        )
        for label, cross in CEILING_CASES.items()
    }


def time_per_step_us(micro, case, threads, min_time):
    """Real time per iteration (us) of BM_Rbpf/<case, threads:T>, from Google Benchmark's JSON."""
    parts = case.split("/")
    name = "BM_Rbpf/" + "/".join(parts[:2] + [f"threads:{threads}"] + parts[2:]) + "/real_time"
    b = run_micro(micro, name, min_time)
    return b["real_time"] * {"ns": 1e-3, "us": 1.0, "ms": 1e3}[b["time_unit"]]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--micro", default="build/test/bench/nlosloc-micro")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--case", action="append", help="BM_Rbpf arguments but threads (repeatable)")
    ap.add_argument(
        "--min-time", type=float, default=None, help="seconds per benchmark run (1; lockstep 4)"
    )
    ap.add_argument("--method", choices=["lockstep", "pairs"], default="lockstep")
    ap.add_argument("--ceiling", action="store_true", help="also BM_SplitCeiling, each round")
    ap.add_argument(
        "--concurrent",
        action="store_true",
        help="also BM_RbpfConcurrent (two 1-thread filters at once), each round of each case",
    )
    a = ap.parse_args()
    if a.rounds < 1:
        ap.error("--rounds: expected >= 1")
    min_time = a.min_time if a.min_time is not None else (4.0 if a.method == "lockstep" else 1.0)
    if not min_time > 0:
        ap.error("--min-time: expected > 0")
    for case in a.case or []:
        try:
            parse_case(case)
        except ValueError as e:
            ap.error(str(e))
    ceilings = {label: [] for label in CEILING_CASES}
    for case in a.case or DEFAULT_CASES:
        ratios, t1s, t2s = [], [], []
        both = {label: [] for label in CONCURRENT_LABELS}
        for r in range(a.rounds):
            if a.concurrent:
                t1, *pair = concurrent(a.micro, case, min_time)
                for label, ratio in zip(CONCURRENT_LABELS, pair):
                    both[label].append(ratio)
                print(
                    f"{case} round {r + 1}, two 1-thread filters at once ({t1:.1f} us alone): "
                    + ", ".join(f"{lb} {x:.3f}" for lb, x in zip(CONCURRENT_LABELS, pair)),
                    flush=True,
                )
            if a.ceiling:
                for label, (t1, t2, ratio) in ceiling(a.micro, min_time).items():
                    ceilings[label].append(ratio)
                    print(f"ceiling, {label}, round {r + 1}: {t1:.1f} / {t2:.1f} us = {ratio:.3f}")
            if a.method == "lockstep":
                t1, t2, ratio = lockstep(a.micro, case, min_time)
            else:
                t1 = time_per_step_us(a.micro, case, 1, min_time)
                t2 = time_per_step_us(a.micro, case, 2, min_time)
                ratio = t1 / t2
            t1s.append(t1)
            t2s.append(t2)
            ratios.append(ratio)
            print(f"{case} round {r + 1}: {t1:.1f} / {t2:.1f} us = {ratio:.3f}", flush=True)
        med1, med2 = (statistics.median(v) for v in (t1s, t2s))
        print(
            f"{case}: 1 thread {med1:.1f} us, 2 threads {med2:.1f} us, speed-up median "
            + spread(ratios, a.method)
        )
        for label, v in both.items():
            if v:
                print(
                    f"{case}: two 1-thread filters at once, {label}, throughput ratio median "
                    + spread(v, "lockstep")
                )
    for label, v in ceilings.items():
        if v:
            print(f"ceiling, {label}: speed-up median " + spread(v, "lockstep"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
