"""Seismic fragility (``voussoir.fragility``): synthetic records, the maximum-likelihood fit."""

import math

import numpy as np
import pytest

from voussoir import fragility


def test_the_fit_recovers_a_known_lognormal_within_its_sampling_error():
    """Outcomes drawn from Φ(ln(x/θ)/β), θ = 0.4 g, β = 0.35, 10 levels × 100 records: the
    estimates' standard errors are about 0.02 on ln θ and 0.025 on β (Fisher information at
    these values); both within four of them. Several seeds, so that the fit is not lucky."""
    theta, beta = 0.4, 0.35
    levels = np.linspace(0.1, 1.0, 10)
    for seed in range(5):
        rng = np.random.Generator(np.random.PCG64(seed))
        x = np.repeat(levels, 100)
        p = 0.5 * (1 + np.vectorize(math.erf)(np.log(x / theta) / beta / math.sqrt(2)))
        y = rng.random(x.size) < p
        fit = fragility.fit_lognormal(x, y)
        assert abs(math.log(fit["median"] / theta)) < 4 * 0.02, (seed, fit)
        assert abs(fit["beta"] - beta) < 4 * 0.025, (seed, fit)
    with pytest.raises(ValueError, match="all outcomes"):
        fragility.fit_lognormal([0.1, 0.2], [True, True])


def test_fits_that_do_not_exist_are_refused():
    """Probe 3, F7: perfectly separated outcomes (β → 0; the search stopped at 0.025), no
    trend (β → ∞; it returned 1.6e9) and NaN intensities (NaN) each raise a ValueError that
    says why; an overlapping, increasing set still fits."""
    with pytest.raises(ValueError, match="separated.*between 0.3 and 0.4"):
        fragility.fit_lognormal([0.1, 0.2, 0.3, 0.4, 0.5], [False, False, False, True, True])
    with pytest.raises(ValueError, match="no increasing trend"):
        fragility.fit_lognormal([0.1, 0.2, 0.3, 0.4, 0.5, 0.6], [True, False, True, False, True, False])
    with pytest.raises(ValueError, match="intensity 2 is nan"):
        fragility.fit_lognormal([0.1, 0.2, math.nan, 0.4], [False, True, False, True])
    with pytest.raises(ValueError, match="booleans"):
        fragility.fit_lognormal([0.1, 0.2, 0.3], [0, 2, 1])
    fit = fragility.fit_lognormal([0.1, 0.2, 0.3, 0.4, 0.5, 0.6], [False, False, True, False, True, True])
    assert 0.2 < fit["median"] < 0.5 and 0.05 < fit["beta"] < 2.0, fit


def test_synthetic_records_are_reproducible_and_shaped():
    t, a = fragility.kanai_tajimi(7)
    t2, a2 = fragility.kanai_tajimi(7)
    assert np.array_equal(a, a2) and not np.array_equal(a, fragility.kanai_tajimi(8)[1])
    assert np.abs(a).max() == pytest.approx(1.0) and t[-1] == pytest.approx(10.0)
    # The filter shapes the spectrum: averaged over 20 records and smoothed over 0.5 Hz, the
    # power peaks near the Kanai–Tajimi peak (ω_g = 15.6 rad/s, ζ_g = 0.6: about 2 Hz) and falls
    # as 1/f² beyond it (a tenth of the peak by 8 Hz).
    f = np.fft.rfftfreq(a.size, t[1] - t[0])
    power = np.mean([np.abs(np.fft.rfft(fragility.kanai_tajimi(s)[1])) ** 2 for s in range(20)], axis=0)
    width = int(0.5 / f[1])
    smooth = np.convolve(power, np.ones(width) / width, mode="same")
    peak = f[smooth.argmax()]
    assert 1.2 < peak < 3.5, peak
    assert smooth[np.searchsorted(f, 8.0)] < 0.2 * smooth.max()
    # The envelope: quiet at the start, strong in the middle.
    assert np.abs(a[t < 0.2]).max() < 0.1 < np.abs(a[(t > 2) & (t < 5)]).max()


def test_a_gently_shaken_arch_stands():
    r = fragility.arch_case(0, 0.05, duration=0.5)
    assert not r["collapsed"] and r["peak_drift_m"] < 1e-3 and r["time_s"] == pytest.approx(0.5, abs=1e-3)


def test_a_users_record_from_csv_shakes_the_arch_as_the_same_synthetic_one(tmp_path):
    """A record written to CSV (with a header) and read back through ``load_record`` drives the
    arch bit for bit as the synthetic record it came from; a record in other units is
    normalised to the same shape (within an ulp)."""
    t, a = fragility.kanai_tajimi(0, duration=0.5)

    def write(path, scale):
        with open(path, "w") as f:
            f.write("time [s],acceleration [g]\n")
            for ti, ai in zip(t, a):
                f.write(f"{float(ti)!r},{float(scale * ai)!r}\n")

    write(tmp_path / "record.csv", 1.0)
    write(tmp_path / "record_ms2.csv", 0.3 * 9.81)
    t2, a2 = fragility.load_record(tmp_path / "record.csv")
    assert np.array_equal(t2, t) and np.array_equal(a2, a)
    _, a3 = fragility.load_record(tmp_path / "record_ms2.csv")
    assert np.allclose(a3, a, rtol=0, atol=4e-16)
    mine = fragility.arch_case(str(tmp_path / "record.csv"), 0.05)
    theirs = fragility.arch_case(0, 0.05, duration=0.5)
    assert mine == theirs
    flat = tmp_path / "flat.csv"
    flat.write_text("t,a\n0,0\n1,0\n")
    with pytest.raises(ValueError, match="zero"):
        fragility.load_record(flat)
