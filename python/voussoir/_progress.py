"""Progress of long runs (``Model.run_*(progress=True)``, ``Model.push_over``).

A bar of ``tqdm.auto`` when tqdm is installed (a text bar in a terminal, a widget in Jupyter),
otherwise one line on standard error rewritten in place at most twice a second. The run calls
``update(step, time, ratio)`` between its chunks of steps (about ten times a second) and
``close()`` at its end, also when it fails.
"""

import sys
import time as _clock

__all__ = ["RunProgress"]


class _Line:
    """A one-line text bar on standard error, for machines without tqdm."""

    def __init__(self, total, unit, desc):
        self.total, self.unit, self.desc = total, unit, desc
        self.n, self.postfix = 0, ""
        self._shown = 0.0
        self._start = _clock.monotonic()

    def update(self, delta):
        self.n += delta
        now = _clock.monotonic()
        if now - self._shown >= 0.5:
            self._shown = now
            self._draw(now)

    def set_postfix_str(self, text, refresh=False):
        self.postfix = text

    def _draw(self, now):
        elapsed = now - self._start
        if self.total:
            share = min(max(self.n / self.total, 0.0), 1.0)
            head = f"{self.desc}: {100 * share:3.0f}% {self.n:.4g}/{self.total:.4g} {self.unit}"
        else:
            head = f"{self.desc}: {self.n:.4g} {self.unit}"
        tail = f", {self.postfix}" if self.postfix else ""
        sys.stderr.write(f"\r{head} [{elapsed:.1f} s{tail}]\033[K")
        sys.stderr.flush()

    def close(self):
        self._draw(_clock.monotonic())
        sys.stderr.write("\n")
        sys.stderr.flush()


def _bar(total, unit, desc):
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return _Line(total, unit, desc)
    return tqdm(total=total, unit=unit, desc=desc, leave=True, dynamic_ncols=True)


class RunProgress:
    """The bar of one run: ``kind`` is ``"steps"`` (to step ``goal``), ``"time"`` (to the model
    time ``goal``, s), ``"equilibrium"`` (to step ``goal`` at most, the unbalanced-force ratio
    shown) or ``"push_over"`` (a travel of ``goal`` m); ``step`` and ``time`` are the model's
    at the start."""

    def __init__(self, kind, goal, step, time):
        self.kind, self.step0, self.time0 = kind, step, time
        if kind == "time":
            total, unit, desc = max(goal - time, 0.0), "s", "voussoir run"
        elif kind == "push_over":
            total, unit, desc = goal, "m", "voussoir push-over"
        elif kind == "steps":
            total, unit, desc = goal, "step", "voussoir run"
        else:
            total, unit, desc = goal, "step", "voussoir equilibrium"
        self.bar = _bar(total, unit, desc)
        self.done = 0

    def update(self, step, time, ratio):
        value = time - self.time0 if self.kind == "time" else step - self.step0
        value = min(value, self.bar.total) if self.bar.total else value  # a last step overshoots
        if value > self.done:
            self.bar.update(value - self.done)
            self.done = value
        self.bar.set_postfix_str(f"step {step}, t {time:.4g} s, ratio {ratio:.2e}", refresh=False)

    def update_travel(self, step, travel, load):
        """A push-over's progress: the driven block's travel (m) towards ``max_travel``."""
        travel = min(travel, self.bar.total)
        if travel > self.done:
            self.bar.update(travel - self.done)
            self.done = travel
        self.bar.set_postfix_str(f"step {step}, load {load:.4g} N", refresh=False)

    def close(self):
        self.bar.close()
