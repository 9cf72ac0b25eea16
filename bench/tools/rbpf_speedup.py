#!/usr/bin/env python3
"""Two-thread speed-up of the RBPF benchmarks, measured in interleaved pairs.

On a shared 2-vCPU machine the time per step of one benchmark drifts by 5-10% over minutes,
so a 1-thread run and a 2-thread run minutes apart can misstate the ratio by as much. Each round
runs the 1-thread and the 2-thread benchmark back to back and takes their ratio; the median over
rounds is the speed-up.

    python3 bench/tools/rbpf_speedup.py [--micro build/test/bench/nlosloc-micro] [--rounds 6]
        [--case reordered:1/M:128/augmented:0 ...] [--min-time 1]

Standard library only. Prints one line per round and a summary per case.
"""

import argparse
import json
import re
import statistics
import subprocess
import sys

DEFAULT_CASES = ["reordered:1/M:128/augmented:0", "reordered:1/M:128/augmented:1"]


def time_per_step_us(micro, case, threads, min_time):
    """Real time per iteration (us) of BM_Rbpf/<case, threads:T>, from Google Benchmark's JSON."""
    parts = case.split("/")
    name = "BM_Rbpf/" + "/".join(parts[:2] + [f"threads:{threads}"] + parts[2:]) + "/real_time"
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
            return b["real_time"] * {"ns": 1e-3, "us": 1.0, "ms": 1e3}[b["time_unit"]]
    raise RuntimeError(f"no result for {name}; is it registered in {micro}?")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--micro", default="build/test/bench/nlosloc-micro")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--case", action="append", help="BM_Rbpf arguments but threads (repeatable)")
    ap.add_argument("--min-time", type=float, default=1.0, help="seconds per benchmark run")
    a = ap.parse_args()
    if a.rounds < 1:
        ap.error("--rounds: expected >= 1")
    for case in a.case or DEFAULT_CASES:
        ratios, t1s, t2s = [], [], []
        for r in range(a.rounds):
            t1 = time_per_step_us(a.micro, case, 1, a.min_time)
            t2 = time_per_step_us(a.micro, case, 2, a.min_time)
            t1s.append(t1)
            t2s.append(t2)
            ratios.append(t1 / t2)
            print(f"{case} round {r + 1}: {t1:.1f} / {t2:.1f} us = {t1 / t2:.3f}", flush=True)
        med1, med2, medr = (statistics.median(v) for v in (t1s, t2s, ratios))
        print(
            f"{case}: 1 thread {med1:.1f} us, 2 threads {med2:.1f} us, speed-up median {medr:.3f} "
            f"(min {min(ratios):.3f}, max {max(ratios):.3f}, {a.rounds} paired rounds)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
