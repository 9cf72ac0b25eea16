"""nlosloc-bench --first-run, end to end (run by ctest: bench_first_run).

Runs H1's MLE-LOS on runs 0..2 at once and as the chunks {0} and {1, 2}; the per-step RMSE of the
JSON files must join: 3 rmse_all^2 = rmse_0^2 + 2 rmse_12^2 (RMSE_k = sqrt(mean over runs of e^2)).
Then the refusals: a first run past 2^64 - 1 - (runs - 1) and a negative one exit with code 2 and a
message naming --first-run.

Usage: python3 bench_first_run.py NLOSLOC_BENCH WORKDIR
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path


def run(bench: str, *args: str) -> subprocess.CompletedProcess[str]:
    cmd = [bench, "run", "H1", "-e", "MLE-LOS", "--steps", "60", "--seed", "4", "--quiet", *args]
    return subprocess.run(cmd, capture_output=True, text=True, check=False)


def rmse(bench: str, out: Path, *args: str) -> tuple[list[float], dict, str]:
    p = run(bench, "--json", str(out), *args)
    if p.returncode != 0:
        sys.exit(f"{args}: exit {p.returncode}\n{p.stdout}\n{p.stderr}")
    doc = json.loads(out.read_text())
    cases = doc["results"]
    if len(cases) != 1:
        sys.exit(f"{args}: expected one case, got {list(cases)}")
    (case,) = cases.values()
    return case["estimators"]["MLE-LOS"]["rmse"], doc["config"], p.stdout


def main() -> None:
    bench, work = sys.argv[1], Path(sys.argv[2])
    work.mkdir(parents=True, exist_ok=True)
    all3, cfg_all, _ = rmse(bench, work / "all.json", "--runs", "3")
    first, cfg_first, _ = rmse(bench, work / "first.json", "--runs", "1")
    tail, cfg_tail, text = rmse(bench, work / "tail.json", "--runs", "2", "--first-run", "1")
    if (cfg_all["first_run"], cfg_first["first_run"], cfg_tail["first_run"]) != (0, 0, 1):
        sys.exit(
            f"config first_run: {cfg_all['first_run']}, {cfg_first['first_run']}, "
            f"{cfg_tail['first_run']}"
        )
    if "2 runs (runs 1..2) x 60 steps" not in text:
        sys.exit(f"the table does not name the runs 1..2:\n{text}")
    if not len(all3) == len(first) == len(tail) == 60:
        sys.exit(f"rmse lengths {len(all3)}, {len(first)}, {len(tail)}: expected 60")
    worst = 0.0
    for a, f, t in zip(all3, first, tail):
        joined = math.sqrt((f * f + 2.0 * t * t) / 3.0)
        worst = max(worst, abs(joined - a) / max(a, 1e-12))
    if worst > 1e-9:
        sys.exit(f"chunks do not join: worst relative RMSE difference {worst:.3e}")
    if max(abs(f - t) for f, t in zip(first, tail)) < 1e-6:
        sys.exit("run 0 and runs 1..2 have the same RMSE: --first-run was not applied")

    for args, expect in (
        (
            ("--runs", "2", "--first-run", "18446744073709551615"),
            "--first-run: expected --first-run + --runs - 1 <= 18446744073709551615, got "
            "18446744073709551615 with --runs 2",
        ),
        (
            ("--runs", "1", "--first-run", "-1"),
            "--first-run: expected a decimal integer >= 0, got -1",
        ),
    ):
        p = run(bench, *args)
        if p.returncode != 2 or expect not in p.stderr:
            sys.exit(f"{args}: exit {p.returncode}, expected 2 and '{expect}'\n{p.stderr}")
    print(f"chunks join (worst relative RMSE difference {worst:.1e}); refusals name --first-run")


if __name__ == "__main__":
    main()
