"""Seismic fragility: synthetic ground motions, the reference arch shaken at its base, and
lognormal fragility curves fitted by maximum likelihood.

- ``kanai_tajimi(seed, ...)``: a reproducible synthetic accelerogram, white noise filtered by the
  Kanai–Tajimi ground filter and shaped by an envelope, scaled to a unit peak.
- ``arch_case(record, pga_g, ...)``: one run of the reference arch (``build.arch``) on abutments
  shaken along the span by a record scaled to ``pga_g``; collapse or not, peak drift, residual
  displacement.
- ``fit_lognormal(intensity, collapsed)``: the median and dispersion of
  ``P(collapse | IM) = Φ(ln(IM / θ) / β)`` by maximum likelihood (Baker 2015, "Efficient
  analytical fragility function fitting using dynamic structural analysis").
- ``arch_fragility(records, levels, ...)``: the N × M study on Dask (``voussoir.study``) and its fit.
- ``svg(table, fit)``: the fragility curve and the observed fractions as an SVG document.
"""

from __future__ import annotations

import math
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

__all__ = ["kanai_tajimi", "load_record", "arch_case", "fit_lognormal", "arch_fragility", "svg", "COLLAPSE_DROP_M"]

#: A run collapses when a voussoir's centroid has dropped by more than half the ring thickness
#: (0.1 m of the reference arch's 0.2 m), the rule of the impact benchmark.
COLLAPSE_DROP_M = 0.1


def kanai_tajimi(
    seed: int,
    *,
    duration: float = 10.0,
    dt: float = 0.005,
    omega_g: float = 15.6,
    zeta_g: float = 0.6,
    rise: float = 1.5,
    strong: float = 5.0,
    decay: float = 0.6,
) -> Tuple[np.ndarray, np.ndarray]:
    """A synthetic accelerogram ``(times, accelerations)`` with a unit peak.

    Gaussian white noise ``w`` (numpy's PCG64 from ``seed``) drives the Kanai–Tajimi filter, a
    soil column as an oscillator of frequency ``omega_g`` (rad/s; 15.6 for firm ground) and
    damping ``zeta_g`` (0.6): ``x'' + 2 ζ_g ω_g x' + ω_g² x = −w``, whose absolute acceleration
    ``2 ζ_g ω_g x' + ω_g² x`` is the ground's; integrated exactly for a piecewise-linear ``w``
    (the oscillator's state-transition matrix over ``dt``). The envelope rises as ``(t/rise)²``,
    holds 1 until ``strong``, then decays as ``exp(−decay (t − strong))``. The result is scaled
    so that ``max |a| = 1``: multiply by the peak ground acceleration you want.
    """
    if not (duration > 0 and dt > 0 and omega_g > 0 and 0 < zeta_g < 1):
        raise ValueError("kanai_tajimi: duration, dt, omega_g must be positive and zeta_g in (0, 1)")
    n = int(round(duration / dt)) + 1
    t = np.arange(n) * dt
    w = np.random.Generator(np.random.PCG64(seed)).standard_normal(n)
    # Exact discrete propagation of z = (x, x') under x'' = −2ζω x' − ω² x − w, with w held
    # over each step (zero-order hold): z_{k+1} = A z_k + B w_k.
    wd = omega_g * math.sqrt(1 - zeta_g**2)
    e = math.exp(-zeta_g * omega_g * dt)
    c, s = math.cos(wd * dt), math.sin(wd * dt)
    a11 = e * (c + zeta_g * omega_g / wd * s)
    a12 = e * s / wd
    a21 = -(omega_g**2) * e * s / wd
    a22 = e * (c - zeta_g * omega_g / wd * s)
    # Response to a unit constant forcing −1: x → −1/ω² in steady state.
    b1 = -(1 - a11) / omega_g**2
    b2 = -(-a21) / omega_g**2
    x = np.zeros(n)
    v = np.zeros(n)
    for k in range(n - 1):
        x[k + 1] = a11 * x[k] + a12 * v[k] + b1 * w[k]
        v[k + 1] = a21 * x[k] + a22 * v[k] + b2 * w[k]
    acc = 2 * zeta_g * omega_g * v + omega_g**2 * x
    envelope = np.where(t < rise, (t / rise) ** 2, np.where(t <= strong, 1.0, np.exp(-decay * (t - strong))))
    acc = acc * envelope
    return t, acc / np.abs(acc).max()


def load_record(path, *, time_column: int = 0, value_column: int = 1) -> Tuple[np.ndarray, np.ndarray]:
    """A user's accelerogram from a CSV file (a header line, then numbers; the columns are
    chosen by index), as ``(times from 0, accelerations with a unit peak)``, ready to be scaled
    to a PGA as the synthetic records are. The units of the file do not matter (only the shape
    is kept); raises ``ValueError`` for a record without motion and ``VoussoirError`` (a
    ``ValueError``) for a malformed file, with the line."""
    import voussoir as vs

    h = vs.TimeHistory.from_csv(path, time_column=time_column, value_column=value_column, scale=1.0)
    t, a = np.asarray(h.times, dtype=float), np.asarray(h.values, dtype=float)
    peak = float(np.max(np.abs(a)))
    if peak == 0.0:
        raise ValueError(f"record {path}: every acceleration is zero")
    return t - t[0], a / peak


def arch_case(
    record,
    pga_g: float,
    *,
    duration: float = 6.0,
    friction_deg: float = 30.5,
    kn: float = 4e9,
    damping_ratio: float = 0.02,
    subcontacts_per_edge: int = 7,
) -> Dict[str, Any]:
    """The reference arch (``build.arch()``: 1.2 m span, 0.4 m rise, 0.2 m ring) on abutments
    shaken along the span by ``kanai_tajimi(record, duration=duration)`` (``record`` an int,
    the seed) or by the accelerogram of the CSV file ``record`` (a path: ``load_record``, its
    own length) scaled to ``pga_g`` (in g), dry joints (``friction_deg``, ``kn``, ks = 0.4 kn), stiffness-proportional
    damping ``damping_ratio`` at 5 Hz. Returns ``collapsed`` (a voussoir's centroid dropped by
    more than ``COLLAPSE_DROP_M``; the run stops then), ``peak_drift_m`` (the largest
    horizontal displacement of a voussoir's centroid relative to the abutments),
    ``residual_m`` (the same at the end) and ``time_s``."""
    import voussoir as vs

    m = vs.Model(gravity=(0.0, -9.81, 0.0), subcontacts_per_edge=subcontacts_per_edge)
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(kn, 0.4 * kn, friction_deg))
    ids = m.add_blocks(vs.build.arch())
    abutments = [ids[0], ids[-1]]
    voussoirs = ids[1:-1]
    m.set_damping("local", alpha=0.8)
    m.run_to_equilibrium(1e-5, 200_000)
    m.set_damping("rayleigh_stiffness", ratio=damping_ratio, frequency=5.0)
    if isinstance(record, (int, np.integer)):
        t, a = kanai_tajimi(int(record), duration=duration)
    else:
        t, a = load_record(record)
        duration = float(t[-1])
    history = vs.TimeHistory(t.tolist(), (a * pga_g * 9.81).tolist())
    for b in abutments:
        m.set_base_motion(b, x=history)
    start = m.positions()
    t0 = m.time
    peak = 0.0
    collapsed = False

    def watch(step, time):
        nonlocal peak, collapsed
        p = m.positions()
        base = p[abutments[0]][0] - start[abutments[0]][0]
        drift = np.abs(p[voussoirs, 0] - start[voussoirs, 0] - base).max()
        peak = max(peak, float(drift))
        if (start[voussoirs, 1] - p[voussoirs, 1]).max() > COLLAPSE_DROP_M:
            collapsed = True
            return False
        return None

    m.run_until_time(t0 + duration, callback=watch, every=200)
    watch(0, 0)
    p = m.positions()
    base = p[abutments[0]][0] - start[abutments[0]][0]
    residual = float(np.abs(p[voussoirs, 0] - start[voussoirs, 0] - base).max())
    return {"collapsed": bool(collapsed), "peak_drift_m": peak, "residual_m": residual, "time_s": m.time - t0}


def _phi(z: np.ndarray) -> np.ndarray:
    return 0.5 * (1.0 + np.vectorize(math.erf)(z / math.sqrt(2.0)))


def _neg_log_likelihood(params: np.ndarray, x: np.ndarray, y: np.ndarray) -> float:
    mu, log_beta = params
    p = _phi((np.log(x) - mu) / math.exp(log_beta))
    p = np.clip(p, 1e-300, 1 - 1e-16)
    return float(-(y * np.log(p) + (1 - y) * np.log1p(-p)).sum())


def fit_lognormal(intensity: Sequence[float], collapsed: Sequence[bool]) -> Dict[str, float]:
    """The lognormal fragility ``P(collapse | IM) = Φ(ln(IM/θ)/β)`` that maximises the
    likelihood of the observed outcomes (Baker 2015, eq. 11): ``median`` θ, ``beta`` β and
    ``log_likelihood``. Nelder–Mead on ``(ln θ, ln β)`` from the data's own moments, to a
    relative tolerance of 1e-10.

    Raises ``ValueError`` where no such fit exists: intensities not positive and finite (NaN
    included), outcomes all the same, outcomes **separated** (every collapse at an intensity at
    or above every survival: the likelihood grows without bound as β → 0, so any β the search
    stopped at would be an artefact; the message gives the interval that holds the median), or
    **no increasing trend** (collapses no more likely at higher intensities: the likelihood is
    largest as β → ∞)."""
    x = np.asarray(intensity, dtype=float)
    y = np.asarray(collapsed, dtype=float)
    if x.shape != y.shape or x.ndim != 1 or x.size < 2:
        raise ValueError("fit_lognormal: intensities and outcomes of the same length, at least two")
    if not np.isfinite(x).all() or (x <= 0).any():
        bad = int(np.flatnonzero(~(np.isfinite(x) & (x > 0)))[0])
        raise ValueError(f"fit_lognormal: intensity {bad} is {float(x[bad])}; intensities must be positive and finite")
    if not np.isin(y, (0.0, 1.0)).all():
        raise ValueError("fit_lognormal: outcomes must be booleans (collapsed or not)")
    if y.min() == y.max():
        raise ValueError("fit_lognormal: all outcomes are the same; no fragility can be fitted")
    survived_max, collapsed_min = x[y == 0].max(), x[y == 1].min()
    if survived_max <= collapsed_min:
        raise ValueError(
            "fit_lognormal: the outcomes are separated (every collapse at an intensity at or above every "
            f"survival): the median lies between {survived_max:g} and {collapsed_min:g}, and β has no "
            "maximum-likelihood value (it tends to 0); add runs between them"
        )
    if np.corrcoef(np.log(x), y)[0, 1] <= 0:
        raise ValueError(
            "fit_lognormal: collapses are no more frequent at higher intensities (no increasing trend): "
            "the likelihood is largest as β → ∞, so no fragility curve fits these outcomes"
        )
    start = np.array([np.log(x).mean(), math.log(max(np.log(x).std(), 0.1))])
    f = lambda p: _neg_log_likelihood(p, x, y)  # noqa: E731
    simplex = [start, start + [0.2, 0.0], start + [0.0, 0.2]]
    values = [f(p) for p in simplex]
    for _ in range(2000):
        order = np.argsort(values)
        simplex = [simplex[i] for i in order]
        values = [values[i] for i in order]
        if abs(values[-1] - values[0]) <= 1e-10 * (abs(values[0]) + 1e-10) and np.abs(simplex[-1] - simplex[0]).max() < 1e-8:
            break
        centroid = (simplex[0] + simplex[1]) / 2
        reflected = centroid + (centroid - simplex[2])
        fr = f(reflected)
        if fr < values[0]:
            expanded = centroid + 2 * (centroid - simplex[2])
            fe = f(expanded)
            simplex[2], values[2] = (expanded, fe) if fe < fr else (reflected, fr)
        elif fr < values[1]:
            simplex[2], values[2] = reflected, fr
        else:
            contracted = centroid + 0.5 * (simplex[2] - centroid)
            fc = f(contracted)
            if fc < values[2]:
                simplex[2], values[2] = contracted, fc
            else:
                simplex = [simplex[0] + 0.5 * (p - simplex[0]) for p in simplex]
                values = [f(p) for p in simplex]
    best = simplex[int(np.argmin(values))]
    spread = float(np.log(x).max() - np.log(x).min())
    if math.exp(best[1]) > 1e3 * spread:
        # The search ran off towards β → ∞: the trend, if any, is too weak to fit.
        raise ValueError(
            f"fit_lognormal: β ran to {math.exp(best[1]):.3g}, beyond 1000 times the spread of ln IM "
            f"({spread:.3g}): no increasing trend to fit"
        )
    return {"median": math.exp(best[0]), "beta": math.exp(best[1]), "log_likelihood": -min(values)}


def arch_fragility(
    records=4,
    levels: Sequence[float] = (1.0, 1.5, 2.0, 2.5, 3.0),
    *,
    store: Optional[str] = None,
    client: Any = None,
    progress: bool = True,
    **case: Any,
):
    """The seismic fragility of the reference arch: ``records`` synthetic ground motions
    (an int: seeds 0 to ``records − 1``; or a list of seeds and CSV paths, users' records)
    × ``levels`` (PGA in g; the small, thick arch rocks through
    1.5 g and falls from 2.5 g in 4 s records — measured on records 0 and 1 —, a size effect of
    rocking: its static collapse acceleration is far lower), each an ``arch_case`` (``case``:
    its keywords), run as a ``voussoir.study``; returns ``(table, fit)``, ``fit`` from
    ``fit_lognormal`` on the PGA and the collapses (None when every run collapsed or none
    did)."""
    from . import study

    chosen = list(range(records)) if isinstance(records, (int, np.integer)) else [r if isinstance(r, (int, np.integer)) else str(r) for r in records]
    cases = study.grid(record=chosen, pga_g=list(levels))
    cases = [dict(c, **case) for c in cases]
    table = study.run(arch_case, cases, store=store, client=client, progress=progress)
    ok = table[table["error"] == ""]
    try:
        fit = fit_lognormal(ok["pga_g"].to_numpy(), ok["collapsed"].astype(bool).to_numpy())
    except ValueError:
        fit = None
    return table, fit


def svg(table, fit: Optional[Dict[str, float]], *, width: int = 640, height: int = 420) -> str:
    """The fitted fragility curve and the observed collapse fraction at each level, as an SVG
    document (no plotting library needed)."""
    left, right, top, bottom = 70, 20, 30, 60
    levels = sorted(set(table["pga_g"]))
    xmax = max(levels) * 1.1
    sx = lambda v: left + (width - left - right) * v / xmax  # noqa: E731
    sy = lambda p: top + (height - top - bottom) * (1 - p)  # noqa: E731
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="13">',
        f'<rect width="{width}" height="{height}" fill="white"/>',
        f'<line x1="{left}" y1="{sy(0)}" x2="{width - right}" y2="{sy(0)}" stroke="black"/>',
        f'<line x1="{left}" y1="{sy(0)}" x2="{left}" y2="{sy(1)}" stroke="black"/>',
        f'<text x="{(width + left) / 2}" y="{height - 15}" text-anchor="middle">PGA (g)</text>',
        f'<text x="18" y="{(height) / 2}" transform="rotate(-90 18 {(height) / 2})" text-anchor="middle">P(collapse)</text>',
    ]
    for p in (0.0, 0.25, 0.5, 0.75, 1.0):
        parts.append(f'<text x="{left - 8}" y="{sy(p) + 4}" text-anchor="end">{p:.2f}</text>')
    for v in levels:
        parts.append(f'<text x="{sx(v)}" y="{sy(0) + 18}" text-anchor="middle">{v:g}</text>')
    if fit is not None:
        xs = np.linspace(xmax / 200, xmax, 200)
        ps = _phi(np.log(xs / fit["median"]) / fit["beta"])
        path = " ".join(f"{'M' if i == 0 else 'L'}{sx(x):.1f},{sy(p):.1f}" for i, (x, p) in enumerate(zip(xs, ps)))
        parts.append(f'<path d="{path}" fill="none" stroke="#1f4e9c" stroke-width="2"/>')
        parts.append(
            f'<text x="{left + 10}" y="{top + 5}">fit: median {fit["median"]:.3g} g, beta {fit["beta"]:.2f}</text>'
        )
    ok = table[table["error"] == ""]
    for v in levels:
        at = ok[ok["pga_g"] == v]
        if len(at):
            frac = float(at["collapsed"].astype(bool).mean())
            parts.append(f'<circle cx="{sx(v):.1f}" cy="{sy(frac):.1f}" r="5" fill="#c0392b"/>')
    parts.append("</svg>")
    return "\n".join(parts)
