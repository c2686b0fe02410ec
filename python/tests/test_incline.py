"""The README's incline snippet, run as written, against the closed form.

A brick on a ramp steeper than its friction angle slides with a = g (sin ψ − tan φ cos ψ).
Tolerance 3 %, as the Rust doc-test of the same run (src/lib.rs): the brick is set on the ramp
without damping, so it bounces on its joint for the whole run (the normal force swings between
0 and over three times the weight, period about 3 ms); central difference distorts a contact
that opens and closes, and at the default step (half the critical one) the mean acceleration
comes out about 1.4 % high. At a fifth of the critical step it is within 0.5 %, which the second
test checks at 1 %: the error is the time step's, not the law's.
"""

import contextlib
import io
import math

import numpy as np

import voussoir as vs

SNIPPET = """
import math, numpy as np, voussoir as vs
psi, g = math.radians(35), 9.81
m = vs.Model(gravity=(g * math.sin(psi), 0.0, -g * math.cos(psi)))
m.set_joint_law(0, 0, vs.CoulombSlip.dry(kn=1e9, ks=1e9, friction_deg=30.0))
m.set_damping("none")
m.add_cuboid("ramp", (-1.0, -0.5, -0.1), (3.0, 0.5, 0.0), density=2500.0, fixed=True)
b = m.add_cuboid("brick", (0.0, -0.1, 0.0), (0.2, 0.1, 0.1), density=2500.0)
m.run_until_time(0.3)
v = np.asarray(m.velocities())          # shape (2, 3)
print(v[b][0] / 0.3)                     # ≈ g (sin 35° − tan 30° cos 35°)
"""

PSI, G, PHI = math.radians(35), 9.81, math.radians(30)
EXPECTED = G * (math.sin(PSI) - math.tan(PHI) * math.cos(PSI))


def test_snippet_as_written():
    out = io.StringIO()
    scope: dict = {}
    with contextlib.redirect_stdout(out):
        exec(compile(SNIPPET, "<snippet>", "exec"), scope)
    a = float(out.getvalue().strip())
    assert abs(a - EXPECTED) < 0.03 * EXPECTED, (a, EXPECTED)
    assert scope["v"].shape == (2, 3)
    assert scope["b"] == 1 and isinstance(scope["b"], int)


def test_smaller_step_closer():
    m = vs.Model(gravity=(G * math.sin(PSI), 0.0, -G * math.cos(PSI)), safety=0.2)
    m.set_joint_law(0, 0, vs.CoulombSlip.dry(kn=1e9, ks=1e9, friction_deg=30.0))
    m.set_damping("none")
    m.add_cuboid("ramp", (-1.0, -0.5, -0.1), (3.0, 0.5, 0.0), density=2500.0, fixed=True)
    b = m.add_cuboid("brick", (0.0, -0.1, 0.0), (0.2, 0.1, 0.1), density=2500.0)
    r0 = m.rotation_matrices()[b]
    m.run_until_time(0.3)
    a = m.velocities()[b, 0] / m.time
    assert abs(a - EXPECTED) < 0.01 * EXPECTED, (a, EXPECTED)
    # It slides straight down the slope: no sideways motion, hardly any rocking. The friction
    # at its base tilts it on its (undamped) joint by about 2e-5 rad, about which it rocks at
    # some 1,800 rad/s, so its angular velocity swings through ±0.1 rad/s (at 0.3 s it may be
    # anywhere in that range): the tilt is what stays small.
    assert abs(m.velocities()[b, 1]) < 1e-9
    turned = m.rotation_matrices()[b] @ r0.T
    tilt = math.acos(min(1.0, (np.trace(turned) - 1.0) / 2.0))
    assert tilt < 2e-4, tilt
