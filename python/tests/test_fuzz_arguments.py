"""Fuzzing of the Python argument conversion (issue 33): the model's methods called with
hostile values (negative and huge ints, NaN, infinities, strings, wrong lengths, endless
iterables, arbitrary objects) in a seeded random order. The property: each call returns or
raises an ordinary ``Exception`` (never a Rust panic, which PyO3 raises as a
``BaseException``, never an abort or a hang), and the model stays usable: it saves a
checkpoint that loads.

``VOUSSOIR_FUZZ_SEED`` and ``VOUSSOIR_FUZZ_CALLS`` (default 3000) reproduce or lengthen a run.
"""

import itertools
import math
import os
import random

import numpy as np

import voussoir as vs
from conftest import block_on_base


def hostile_values():
    return [
        None, True, -1, 0, 1, 2, 7, 2**31, 2**63, 10**30, -(10**30), 0.5, -0.0, math.nan, math.inf, -math.inf,
        1e308, 1e-320, "", "x", "fixed", "free", "z", "magnitude", "energy", "kinetic", [], [1.0, 2.0],
        (0.0, 0.0, 1.0), (1, 2, 3, 4), [math.nan] * 3, [1e308] * 3, b"\x00", object(), {},
        {"translation": ["free", "fixed", 0.5]}, {"rotation": [1, 2]}, {"bad": 1},
        np.zeros((2, 2)), np.array([1.0, 2.0, 3.0]), np.array([np.nan, 0.0, 0.0]),
        vs.LinearElastic(1e8, 1e8),
    ]


def pick(rng):
    if rng.random() < 0.05:
        return itertools.count()  # an endless iterable, fresh each time
    return rng.choice(hostile_values())


CALLS = [
    ("set_fixity", 2, ()),
    ("set_load", 1, ("force", "moment")),
    ("set_velocity", 2, ("angular_velocity",)),
    ("set_prescribed_velocity", 2, ()),
    ("block", 1, ()),
    ("reaction", 1, ()),
    ("contact_wrench", 1, ()),
    ("add_monitor", 2, ("block", "point", "component", "a", "b", "term")),
    ("set_joint_law", 3, ()),
    ("joint_law", 2, ()),
    ("add_cuboid", 4, ("material", "fixed", "velocity", "angular_velocity")),
    ("add_polyhedron", 3, ("faces", "material", "fixed")),
    ("set_damping", 1, ("alpha", "ratio", "frequency", "mass", "stiffness")),
    ("add_blocks", 1, ()),
]


def test_hostile_arguments_raise_exceptions_not_panics():
    seed = int(os.environ.get("VOUSSOIR_FUZZ_SEED", "33"))
    calls = int(os.environ.get("VOUSSOIR_FUZZ_CALLS", "3000"))
    rng = random.Random(seed)
    model = block_on_base()
    model.run_steps(2)
    outcomes = {"returned": 0, "raised": 0}
    for k in range(calls):
        name, positional, keywords = rng.choice(CALLS)
        args = [pick(rng) for _ in range(positional)]
        kwargs = {kw: pick(rng) for kw in keywords if rng.random() < 0.3}
        try:
            getattr(model, name)(*args, **kwargs)
            outcomes["returned"] += 1
        except Exception:  # noqa: BLE001 - any ordinary exception is a fine answer
            outcomes["raised"] += 1
        except BaseException as e:  # a Rust panic (pyo3 PanicException) or worse
            raise AssertionError(f"call {k} (seed {seed}): {name}(*{args!r}, **{kwargs!r}) -> {e!r}") from e
    print(f"python arguments: {calls} calls, {outcomes}, seed {seed}")
    assert outcomes["raised"] > 0 and outcomes["returned"] > 0
    text = model.to_checkpoint_string()
    vs.Model.from_checkpoint_string(text)
