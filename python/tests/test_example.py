"""python/examples/arch.py runs (the baseline static case, about 2 s) and reports its curve."""

import pathlib
import subprocess
import sys

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "arch.py"


def test_arch_example(tmp_path):
    out = subprocess.run(
        [sys.executable, str(EXAMPLE)], cwd=tmp_path, capture_output=True, text=True, timeout=300, check=True
    ).stdout
    first = out.splitlines()[0]
    assert first.startswith("baseline: peak ") and "experiment 2.71 kN" in first
    peak = float(first.split("peak ")[1].split(" kN")[0])
    assert 2.0 < peak < 3.5
    # The table, or the plot when matplotlib is installed.
    assert "load [kN]" in out or (tmp_path / "arch_static.png").exists()
