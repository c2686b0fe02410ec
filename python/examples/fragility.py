"""Seismic fragility of the reference arch on Dask (voussoir.study, voussoir.fragility).

    python python/examples/fragility.py                  # 3 records x 5 PGA levels, a few minutes on 2 cores
    python python/examples/fragility.py --records 20     # more records, the same levels
    python python/examples/fragility.py --levels 1,2,3   # other levels (PGA in g)
    python python/examples/fragility.py --scheduler tcp://host:8786   # on a cluster

Each run shakes the arch's abutments along the span with a synthetic Kanai-Tajimi record
(seeded, so that every run is reproducible) scaled to the PGA; a run collapses when a voussoir
drops by half the ring thickness. The study is kept case by case in out/fragility/ (rerun the
command to resume it); the fitted lognormal curve is written to out/fragility/fragility.svg and
the table to out/fragility/table.csv.
"""

import argparse
import os

import voussoir as vs
from voussoir import fragility


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=3)
    ap.add_argument("--levels", default="1.0,1.5,2.0,2.5,3.0", help="PGA levels (g), comma separated")
    ap.add_argument("--duration", type=float, default=6.0, help="record length (s)")
    ap.add_argument("--out", default="out/fragility")
    ap.add_argument("--scheduler", default=None, help="a Dask scheduler address (default: a local cluster)")
    a = ap.parse_args()
    client = None
    if a.scheduler:
        from distributed import Client

        client = Client(a.scheduler)
    levels = [float(v) for v in a.levels.split(",")]
    table, fit = fragility.arch_fragility(
        a.records, levels, store=a.out, client=client, duration=a.duration
    )
    print(table.to_string(index=False))
    if fit is None:
        print("every run collapsed, or none did: no fragility curve (widen --levels)")
    else:
        print(f"median {fit['median']:.3f} g, beta {fit['beta']:.3f}")
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "fragility.svg"), "w", encoding="utf-8") as f:
        f.write(fragility.svg(table, fit))


if __name__ == "__main__":
    main()
