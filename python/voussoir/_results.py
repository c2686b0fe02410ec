"""Results as dicts with a short ``repr``.

The results of ``voussoir.limit``, ``Model.push_over``, ``voussoir.classify_joints``,
``Model.contacts`` and the like are plain ``dict`` subclasses (index them, iterate them,
``pandas.DataFrame`` them as before) whose ``repr`` fits on a few lines: scalars as values,
arrays as their shape, lists and nested dicts as their length.
"""

import numpy as np

__all__ = ["Result"]


def _brief(value):
    if isinstance(value, np.ndarray):
        shape = "×".join(str(n) for n in value.shape) or "scalar"
        return f"array({shape}, {value.dtype})"
    if isinstance(value, (bool, np.bool_)) or value is None:
        return repr(value)
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.6g}"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, str):
        return repr(value if len(value) <= 60 else value[:57] + "...")
    if isinstance(value, dict):
        return "{" + ", ".join(str(k) for k in list(value)[:6]) + (", ..." if len(value) > 6 else "") + "}"
    if isinstance(value, (list, tuple)):
        return f"[{len(value)} items]"
    return type(value).__name__


class Result(dict):
    """A dict of results named ``kind`` (``"LimitResult"``, ``"PushOverResult"``, ...)."""

    def __init__(self, kind, data):
        super().__init__(data)
        self.kind = kind

    def __repr__(self):
        items = ",\n".join(f"  {k}={_brief(v)}" for k, v in self.items())
        return f"{self.kind}(\n{items}\n)"

    def _repr_pretty_(self, printer, cycle):  # IPython / Jupyter
        printer.text(repr(self))

    def __reduce__(self):  # pickles (Dask) as the kind and a plain dict
        return (Result, (self.kind, dict(self)))
