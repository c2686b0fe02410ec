"""Mortared joints that crack and soften by their fracture energies (``MortarJoint``): a block
pulled off its base dissipates G_f·A whatever the sub-contact count, the fracture work is its own
energy term, bad parameters are named, and scenes and checkpoints carry the law."""

import pytest

import voussoir as vs

KN, KS = 1e11, 4e10
FT, G_I = 2e5, 2.0  # Pa, J/m²: the crack runs over G_I/FT = 10 µm
AREA = 0.2 * 0.2


def mortar(**kwargs):
    spec = dict(
        residual_friction_deg=30.0,
        tensile_strength=FT,
        mode_i_fracture_energy=G_I,
        cohesion=3e5,
        mode_ii_fracture_energy=10.0,
    )
    spec.update(kwargs)
    return vs.MortarJoint(KN, KS, 35.0, **spec)


def driven(per_edge, law, vz, steps):
    """A 0.2 m square block bonded to a fixed base by ``law`` and driven straight along z at
    ``vz`` (m/s; 1e-4 s steps) for ``steps`` steps."""
    m = vs.Model(subcontacts_per_edge=per_edge, time_step=1e-4)
    m.set_damping("none")
    m.set_joint_law(0, 0, law)
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    v = (0.0, 0.0, vz)
    m.add_cuboid(
        "block",
        (-0.1, -0.1, 0),
        (0.1, 0.1, 0.1),
        2500.0,
        fixed={"translation": list(v), "rotation": ["fixed"] * 3},
        velocity=v,
    )
    m.run_steps(steps)
    return m


def pulled_off(per_edge, law=None):
    """The block driven straight up at 1 mm/s (1e-7 m a step) by 0.6 mm: the crack runs
    through."""
    return driven(per_edge, law or mortar(), 1e-3, 6000)


@pytest.mark.parametrize("per_edge", [5, 15, 30])
def test_a_block_pulled_off_dissipates_g_f_a_at_any_density(per_edge):
    """Mode I: the fracture energy consumed is G_f^I·A within 1 % (measured to 1e-6) at 5, 15
    and 30 sub-contacts per edge; it is the ``fracture`` term of the energies, counted in
    ``accounted``; the work it took to pull the block off is the same."""
    m = pulled_off(per_edge)
    e = m.energies()
    assert e["fracture"] == pytest.approx(G_I * AREA, rel=1e-2)
    assert abs(e["friction"]) < 1e-3 * G_I * AREA
    work = e["boundary_work"] + e["gravity_work"] + e["initial_kinetic"] - e["kinetic"]
    assert work == pytest.approx(G_I * AREA, rel=1e-2)
    assert e["accounted"] == pytest.approx(
        e["kinetic"] + e["elastic"] + e["friction"] + e["fracture"] + e["damping"], rel=1e-12
    )
    assert abs(e["balance_error"]) < 1e-3 * G_I * AREA
    # Cracked through: the joint carries nothing.
    assert abs(m.contacts()["normal_force"]).max() == 0.0


def test_linear_softening_and_other_laws_book_no_fracture():
    """Linear softening dissipates the same G_f·A; a CoulombSlip joint that fails books its
    (brittle) loss as friction, none as fracture."""
    m = pulled_off(15, mortar(softening="linear"))
    assert m.energies()["fracture"] == pytest.approx(G_I * AREA, rel=1e-2)
    c = pulled_off(15, vs.CoulombSlip(KN, KS, 35.0, 30.0, cohesion=3e5, tensile_strength=FT))
    e = c.energies()
    assert e["fracture"] == 0.0 and e["friction"] > 0.0


def test_parameters_are_checked_and_named():
    with pytest.raises(vs.VoussoirError, match="mode_i_fracture_energy"):
        vs.MortarJoint(KN, KS, 35.0, tensile_strength=FT)
    with pytest.raises(vs.VoussoirError, match="mode_ii_fracture_energy"):
        vs.MortarJoint(KN, KS, 35.0, cohesion=1e5)
    with pytest.raises(vs.VoussoirError, match="mode_i_fracture_energy"):
        mortar(mode_i_fracture_energy=-1.0)
    with pytest.raises(vs.VoussoirError, match="tensile_strength"):
        mortar(tensile_strength=float("nan"))
    with pytest.raises(vs.VoussoirError, match="residual_friction_angle"):
        mortar(residual_friction_deg=95.0)
    with pytest.raises(vs.VoussoirError, match="dilatancy_angle"):
        vs.MortarJoint(KN, KS, 35.0, dilatancy_deg=10.0)
    with pytest.raises(vs.VoussoirError, match="normal_stiffness"):
        vs.MortarJoint(-1.0, KS, 35.0)
    with pytest.raises(vs.VoussoirError, match="softening"):
        mortar(softening="cubic")
    # A brittle joint (no fracture energy) is allowed, and a dry one needs nothing more.
    assert mortar(mode_i_fracture_energy=0.0).mode_i_fracture_energy == 0.0
    dry = vs.MortarJoint(KN, KS, 30.0)
    assert (dry.tensile_strength, dry.cohesion, dry.softening) == (0.0, 0.0, "exponential")


def test_the_law_reads_back_and_round_trips_through_scenes_and_checkpoints():
    law = mortar(dilatancy_deg=5.0, softening="linear")
    assert (law.friction_deg, law.residual_friction_deg, law.dilatancy_deg) == (35.0, 30.0, 5.0)
    assert (law.tensile_strength, law.mode_i_fracture_energy) == (FT, G_I)
    assert (law.cohesion, law.mode_ii_fracture_energy) == (3e5, 10.0)
    assert law.softening == "linear"
    assert "MortarJoint(" in repr(law) and law == mortar(dilatancy_deg=5.0, softening="linear")
    m = vs.Model()
    m.set_joint_law(0, 0, law)
    m.set_joint_law(0, 1, vs.CoulombSlip.dry(KN, KS, 30.0))
    assert m.joint_law(0, 0) == law
    m.add_cuboid("base", (-1, -1, -0.2), (1, 1, 0), 2500.0, fixed=True)
    m.add_cuboid("block", (-0.1, -0.1, 0), (0.1, 0.1, 0.1), 2500.0)
    m.set_load(1, force=(0.0, 0.0, 1.2e4))  # beyond f_t·A + weight: the joint cracks
    m.run_steps(40)
    assert m.energies()["fracture"] > 0.0
    back = vs.Model.from_scene_json(m.to_scene_json())
    assert back.joint_law(0, 0) == law and back.joint_law(0, 1) == m.joint_law(0, 1)
    restored = vs.Model.from_checkpoint_string(m.to_checkpoint_string())
    assert restored.energies() == m.energies()
    m.run_steps(20)
    restored.run_steps(20)
    assert restored.energies() == m.energies()
    assert (restored.positions() == m.positions()).all()


# The compression cap: f_m 2 MPa, G_c 100 N/m (Δκ = (588/481) G_c/f_m = 61 µm), residual f_m/7.
F_M, G_C = 2e6, 100.0


def pushed_in(per_edge, depth_steps=6000, law=None):
    """The block driven straight down into its base at 1 mm/s (1e-7 m a step) by 0.6 mm: the
    joint crushes through its peak far into its residual."""
    return driven(per_edge, law or mortar(cap_strength=F_M, cap_fracture_energy=G_C), -1e-3, depth_steps)


@pytest.mark.parametrize("per_edge", [5, 15])
def test_a_crushed_joint_dissipates_g_c_a_over_its_residual(per_edge):
    """Crushing, per unit area: pushed 0.6 mm in, the joint carries its residual f_m/7 over its
    area, and the fracture energy booked is A (G_c + f_m/7 κ), κ the plastic closure (the depth
    less the residual's elastic closure), within 1e-3 at 5 and 15 per edge (the exponential's
    tail is e^{-25} of G_c)."""
    m = pushed_in(per_edge)
    residual = F_M / 7.0
    assert m.contacts()["normal_force"].sum() == pytest.approx(residual * AREA, rel=1e-9)
    kappa = 0.6e-3 - residual / KN
    e = m.energies()
    assert e["fracture"] == pytest.approx(AREA * (G_C + residual * kappa), rel=1e-3)
    assert abs(e["balance_error"]) < 1e-3 * e["fracture"]


def test_the_cap_is_checked_read_back_and_round_tripped():
    with pytest.raises(vs.VoussoirError, match="cap_fracture_energy"):
        mortar(cap_strength=F_M)
    with pytest.raises(vs.VoussoirError, match="cap_fracture_energy"):
        mortar(cap_fracture_energy=G_C)
    with pytest.raises(vs.VoussoirError, match="cap_strength"):
        mortar(cap_strength=0.0, cap_fracture_energy=G_C)
    with pytest.raises(vs.VoussoirError, match="cap_shear_factor"):
        mortar(cap_strength=F_M, cap_fracture_energy=G_C, cap_shear_factor=-1.0)
    law = mortar(cap_strength=F_M, cap_fracture_energy=G_C, cap_peak_closure=2e-5)
    assert (law.cap_strength, law.cap_fracture_energy, law.cap_shear_factor, law.cap_peak_closure) == (
        F_M,
        G_C,
        9.0,
        2e-5,
    )
    assert mortar().cap_strength is None
    assert "cap_strength=2000000" in repr(law)
    m = pushed_in(5, depth_steps=1000, law=law)
    assert m.energies()["fracture"] > 0.0
    back = vs.Model.from_scene_json(m.to_scene_json())
    assert back.joint_law(0, 0) == law
    restored = vs.Model.from_checkpoint_string(m.to_checkpoint_string())
    m.run_steps(200)
    restored.run_steps(200)
    assert restored.energies() == m.energies()
