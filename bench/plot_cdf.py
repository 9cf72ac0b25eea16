"""Draw the position-error CDFs of an ``nlosloc-bench run ... --json FILE`` result as a PNG.

Usage::

    nlosloc-bench run H2 --runs 100 --json h2.json
    python bench/plot_cdf.py h2.json h2.png [--case default] [--xmax 200] [--zoom 0.9]

``--zoom P`` adds a second panel around the P-quantile (Huerta 2009 Fig. 15 zooms around 90%).
Needs matplotlib (the ``plots`` extra) and the nlosloc package (for ``nlosloc.plots``).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("json", type=Path, help="JSON written by nlosloc-bench --json")
    ap.add_argument("png", type=Path, help="output image")
    ap.add_argument("--case", default=None, help="case to draw (default: the first)")
    ap.add_argument("--xmax", type=float, default=None, help="x-axis limit (m)")
    ap.add_argument(
        "--zoom", type=float, default=None, help="add a panel zoomed around this probability"
    )
    args = ap.parse_args(argv)
    if args.zoom is not None and not 0.0 < args.zoom < 1.0:
        ap.error(f"--zoom: expected a probability in (0, 1), got {args.zoom}")
    if args.xmax is not None and not args.xmax > 0.0:
        ap.error(f"--xmax: expected a positive limit (m), got {args.xmax}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from nlosloc import plots

    doc = json.loads(args.json.read_text(encoding="utf-8"))
    if args.case is not None and args.case not in doc["results"]:
        ap.error(
            f"--case: {args.case!r} is not in {args.json}; expected one of {list(doc['results'])}"
        )
    panels = 2 if args.zoom is not None else 1
    fig, axes = plt.subplots(1, panels, figsize=(6.5 * panels, 4.5), squeeze=False)
    plots.error_cdf_from_bench(doc, case=args.case, ax=axes[0][0], xmax=args.xmax)
    if args.zoom is not None:
        ax = axes[0][1]
        plots.error_cdf_from_bench(doc, case=args.case, ax=ax)
        case = args.case or next(iter(doc["results"]))
        xs = []
        for est in doc["results"][case]["estimators"].values():
            x, p = np.asarray(est["ecdf"]["x"]), np.asarray(est["ecdf"]["p"])
            i = int(np.searchsorted(p, args.zoom))
            xs.append(x[min(i, x.size - 1)])
        ax.set_ylim(max(0.0, args.zoom - 0.1), min(1.0, args.zoom + 0.05))
        ax.set_xlim(0.0, 1.2 * max(xs))
        ax.set_title(f"zoom around {100 * args.zoom:g}%")
    fig.tight_layout()
    fig.savefig(args.png, dpi=120)
    print(f"wrote {args.png}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
