"""A wall on a shaking table, driven by an accelerogram read from a CSV file, with a plot.

    python python/examples/seismic_csv.py                    # writes and uses a synthetic record
    python python/examples/seismic_csv.py --record my.csv    # time [s], acceleration [g] columns

The record (a CSV file with a header line: time in s, ground acceleration in g) is read with
``voussoir.TimeHistory.from_csv(..., scale=9.81)`` and drives the table block along x
(``Model.set_base_motion``); the wall of dry-stacked blocks on it (φ 35°, 5 % Rayleigh damping
at 5 Hz) is followed for the record's length. The top block's displacement relative to the
table and the table's acceleration are written to out/seismic/history.csv and plotted to
out/seismic/seismic.png (matplotlib) or out/seismic/seismic.svg (without it).
"""

import argparse
import csv
import math
import os

import numpy as np

import voussoir as vs
from voussoir import fragility


def synthetic_record(path, pga_g=0.35, duration=4.0, seed=3):
    """A Kanai–Tajimi record (voussoir.fragility) scaled to ``pga_g``, written as CSV in g."""
    times, acc = fragility.kanai_tajimi(seed, duration=duration)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time [s]", "acceleration [g]"])
        for t, a in zip(times, acc):
            w.writerow([f"{t:.5f}", f"{pga_g * a:.6f}"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--record", default=None, help="CSV: time [s], acceleration [g] (default: a synthetic one)")
    ap.add_argument("--out", default="out/seismic")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    record = a.record or os.path.join(a.out, "record.csv")
    if a.record is None:
        synthetic_record(record)
    ground = vs.TimeHistory.from_csv(record, time_column=0, value_column=1, scale=9.81)

    m = vs.Model()
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(1e9, 4e8, 35.0))
    blocks = vs.build.running_bond_wall(bricks_per_course=4, courses=6, brick=(0.3, 0.15, 0.1))
    ids = m.add_blocks(blocks)
    table, top = ids[0], ids[-1]
    m.run_to_equilibrium(1e-5, 500_000)
    m.set_damping("rayleigh", ratio=0.05, frequency=5.0)
    m.set_base_motion(table, x=ground)
    t0, x0 = m.time, m.positions()[:, 0].copy()
    rows = []

    def sample(step, time):
        x = m.positions()[:, 0] - x0
        rows.append((time - t0, ground.value_at(time - t0) / 9.81, x[table], x[top] - x[table]))

    m.run_until_time(t0 + ground.end, callback=sample, every=50, progress=True)
    with open(os.path.join(a.out, "history.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time [s]", "ground acceleration [g]", "table displacement [m]", "top relative displacement [m]"])
        w.writerows(rows)
    t, ag, xt, rel = (np.array(c) for c in zip(*rows))
    peak = float(np.max(np.abs(rel)))
    print(f"record {record}: {ground.end:.2f} s, PGA {np.max(np.abs(ground.values)) / 9.81:.3f} g")
    print(f"top block relative to the table: peak {1e3 * peak:.2f} mm, residual {1e3 * rel[-1]:.2f} mm")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
        ax1.plot(t, ag, color="#0072B2")
        ax1.set_ylabel("ground acceleration [g]")
        ax2.plot(t, 1e3 * rel, color="#D55E00")
        ax2.set_ylabel("top block, relative [mm]")
        ax2.set_xlabel("time [s]")
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "seismic.png"), dpi=120)
        print(f"plot: {os.path.join(a.out, 'seismic.png')}")
    except ImportError:
        # Without matplotlib: the two curves as an SVG polyline plot.
        w_, h_ = 640, 360
        def poly(y, top_, colour):
            span = max(float(np.max(np.abs(y))), 1e-12)
            pts = " ".join(f"{40 + (w_ - 60) * ti / t[-1]:.1f},{top_ + 70 - 60 * yi / span:.1f}" for ti, yi in zip(t, y))
            return f'<polyline fill="none" stroke="{colour}" points="{pts}"/>'
        svg = (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w_}" height="{h_}">'
               f'<text x="40" y="15">ground acceleration [g], peak {np.max(np.abs(ag)):.3f}</text>{poly(ag, 20, "#0072B2")}'
               f'<text x="40" y="185">top block relative [mm], peak {1e3 * peak:.2f}</text>{poly(rel, 190, "#D55E00")}</svg>')
        with open(os.path.join(a.out, "seismic.svg"), "w") as f:
            f.write(svg)
        print(f"plot: {os.path.join(a.out, 'seismic.svg')}")


if __name__ == "__main__":
    main()
