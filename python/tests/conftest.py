import math

import pytest

import voussoir as vs


def block_on_base(**model_kwargs) -> "vs.Model":
    """A 0.4 × 0.3 × 0.2 m stone block on a fixed base, dry joint φ 30.5°."""
    m = vs.Model(**model_kwargs)
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(4e9, 1.6e9, 30.5))
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2600.0, fixed=True)
    m.add_cuboid("block", (0, 0, 0), (0.4, 0.3, 0.2), 2600.0)
    return m


@pytest.fixture
def model():
    return block_on_base()


WEIGHT = 2600.0 * 0.4 * 0.3 * 0.2 * 9.81
PUSH = 0.5 * WEIGHT * math.tan(math.radians(30.5))
