"""The reference arch's quasi-static test from Python: load–displacement curve of the baseline
(Pulatsu, Gonen & Lourenço 2021; docs/benchmarks/arch-static.md).

    python python/examples/arch.py            # the baseline, as the command line runs it
    python python/examples/arch.py --quick    # coarse and fast (seconds), for a first look

Plots the curve with matplotlib if it is installed (arch_static.png, or arch_static_quick.png for
the quick run, so that it does not overwrite the full run's), else prints the table.
"""

import sys

import voussoir as vs

EXPERIMENT_PEAK_KN = 2.71


def main() -> None:
    quick = "--quick" in sys.argv
    # Coarse joints, the default servo: five times its 20 µm increment is a 6 kN kick into the
    # plate's seated joint (docs/benchmarks/arch-static.md), not a quasi-static load.
    options = dict(per_edge=5, max_displacement=0.006) if quick else {}
    r = vs.scenarios.arch_static(**options)
    curve = r["curve"]
    print(
        f"{r['label']}: peak {r['peak_load_kn']:.3f} kN at {r['disp_at_peak_mm']:.2f} mm "
        f"(experiment {EXPERIMENT_PEAK_KN} kN); {r['steps']} steps in {r['wall_s']:.1f} s"
    )
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"{'displacement [mm]':>18} {'load [kN]':>10}")
        for d, f in zip(curve["displacement_mm"], curve["load_kn"]):
            print(f"{d:18.3f} {f:10.3f}")
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(curve["displacement_mm"], curve["load_kn"], label=f"model, φ = {r['friction_deg']}°")
    ax.axhline(EXPERIMENT_PEAK_KN, color="gray", linestyle="--", label="experiment peak")
    ax.set_xlabel("plate displacement [mm]")
    ax.set_ylabel("load [kN]")
    ax.set_title("Arch under a quarter-span load")
    ax.legend()
    fig.tight_layout()
    name = "arch_static_quick.png" if quick else "arch_static.png"
    fig.savefig(name, dpi=120)
    print(f"wrote {name}")


if __name__ == "__main__":
    main()
