"""The reference arch's benchmarks from Python, in cheap settings (coarse sub-contacts, a large
servo increment, a short impact run): what is checked is the shape of the results, which must
be the command line's summary.json entries, and that the numbers are physical."""

import pytest

import voussoir as vs

# Keys of a case of arch_static's summary.json (arch/src/cli/arch_static.rs, CaseSummary).
STATIC_KEYS = {
    "label", "loading", "servo", "friction_deg", "kn_pa_per_m", "ks_pa_per_m", "rate_m_per_s",
    "mode", "width_m", "plate", "joint_friction_deg", "peak_load_kn", "peak_load_kn_per_m", "raw_peak_load_kn",
    "disp_at_peak_mm", "rate_convergence", "end_disp_mm", "end_load_kn",
    "settle_unbalanced_ratio", "mechanism", "joints_at_peak", "joints_at_end", "steps", "dt_s",
    "subcontacts", "wall_s",
}
# Keys of a setup of arch_impact's summary.json (arch/src/cli/arch_impact.rs, GroupSummary).
IMPACT_KEYS = {
    "name", "label", "kind", "guide", "base", "release", "node_rule", "mass_kg", "height_m", "v0_m_per_s",
    "contact_speed_m_per_s", "impact_energy_j", "kn_pa_per_m", "damping_ratio", "width_m",
    "first_peak_disp_m", "max_disp_m", "spread_max_disp_m", "median_max_disp_m", "spread_first_peak_disp_m",
    "max_rise_m", "max_rise_time_s", "max_velocity_m_per_s", "max_accel_m_per_s2",
    "max_impact_force_n", "max_impactor_drift_m", "max_impactor_rotation_rad", "collapsed",
    "collapsed_runs", "runs_count", "collapse_time_s", "energy", "steps", "dt_s", "wall_s",
    "runs", "experiment",
}


def test_arch_static_cheap():
    # The default servo increment, 20 µm: five times that (100 µm in one step into the loading
    # plate's seated joint, 6 kN at kn 4 GPa/m) kicks voussoir 5 off the plate.
    r = vs.scenarios.arch_static(per_edge=5, servo_increment=2e-5, max_displacement=0.003, convergence_check=True)
    assert set(r) == STATIC_KEYS | {"curve"}
    assert r["label"] == "baseline" and r["loading"] == "servo" and r["mode"] == "large"
    assert r["servo"] == {"increment": 2e-5, "max_unbalanced_ratio": 1e-3}
    assert r["ks_pa_per_m"] == pytest.approx(0.4 * r["kn_pa_per_m"])
    assert 0.5 < r["peak_load_kn"] < 5.0
    assert r["rate_convergence"]["checked"] is True
    assert len(r["joints_at_peak"]) == 14
    curve = r["curve"]
    assert len(curve["displacement_mm"]) == len(curve["load_kn"]) > 5
    assert max(curve["load_kn"]) == pytest.approx(r["raw_peak_load_kn"])


def test_arch_static_parameters():
    soft = vs.scenarios.arch_static(
        friction_deg=35.0, kn=2e9, width=0.2, mode="small", per_edge=5, servo_increment=1e-4,
        max_displacement=0.002, label="mine",
    )
    assert (soft["label"], soft["friction_deg"], soft["kn_pa_per_m"], soft["width_m"], soft["mode"]) == (
        "mine", 35.0, 2e9, 0.2, "small")
    assert soft["ks_pa_per_m"] == pytest.approx(0.8e9)
    with pytest.raises(vs.VoussoirError, match="increment"):
        vs.scenarios.arch_static(servo_increment=-1.0)
    with pytest.raises(vs.VoussoirError, match="mode"):
        vs.scenarios.arch_static(mode="medium")
    with pytest.raises(vs.VoussoirError, match="plate"):
        vs.scenarios.arch_static(plate="glued")


def test_arch_static_plate_held_restrains_the_loaded_voussoir():
    # Held (its whole velocity prescribed, the paper's "fix velocity"), the plate holds voussoir
    # 5 horizontally through their joint's friction: a higher capacity than rolling (3.44 against
    # 2.79 kN at 15 per edge to 12 mm, docs/benchmarks/arch-static.md).
    quick = dict(per_edge=5, max_displacement=0.004)
    rolling = vs.scenarios.arch_static(**quick)
    held = vs.scenarios.arch_static(plate="held", **quick)
    assert (rolling["plate"], held["plate"]) == ("rolling", "held")
    assert held["peak_load_kn"] > 1.1 * rolling["peak_load_kn"]


def test_arch_static_joint_friction_forms_the_tests_mechanism():
    # Joints 5 and 13 at 40°, the rest at 30.5°: only joint 4 can slide, and the arch forms the
    # test's mechanism, three hinges and one slide, which carries more than the uniform arch's
    # sliding of joints 4, 5 and 13 and loses it with geometry (5.08 kN, then 2.17 kN at 12 mm
    # at 15 per edge; docs/benchmarks/arch-static.md, "The test's mechanism, forced").
    quick = dict(per_edge=5, max_displacement=0.008, stop_fraction=0.0)
    forced = vs.scenarios.arch_static(joint_friction={5: 40.0, 13: 40.0}, **quick)
    assert forced["joint_friction_deg"] == {"5": 40.0, "13": 40.0}
    assert forced["mechanism"]["at_peak"]["sliding_joints"] == [4]
    assert forced["end_load_kn"] < 0.8 * forced["peak_load_kn"]
    assert vs.scenarios.arch_static(**quick)["joint_friction_deg"] == {}
    with pytest.raises(vs.VoussoirError, match="joint index"):
        vs.scenarios.arch_static(joint_friction={14: 40.0})
    with pytest.raises(ValueError, match="joint index"):
        vs.scenarios.arch_static(joint_friction={-1: 40.0})
    with pytest.raises(vs.VoussoirError, match="friction angle of joint 5"):
        vs.scenarios.arch_static(joint_friction={5: 90.0})


def test_arch_impact_cheap():
    r = vs.scenarios.arch_impact("M60H20", duration=0.02, per_edge=5, offsets_mm=(0.25, 0.0))
    assert set(r) == IMPACT_KEYS | {"history"}
    assert r["name"] == r["label"] == "M60H20" and r["kind"] == "main"
    assert (r["guide"], r["base"], r["release"]) == ("Frame", "Sloped", "JustAbove")
    assert r["node_rule"] == "integrated"
    assert r["runs_count"] == 2 and r["runs"][0]["height_offset_m"] == 0.0
    assert r["impact_energy_j"] == pytest.approx(60.93 * 9.81 * 0.205, rel=1e-3)
    assert r["experiment"] == {"collapsed": False, "max_disp_m": 0.034, "max_velocity_m_per_s": 1.99,
                               "max_accel_m_per_s2": 1417.0}
    assert r["max_disp_m"] > 0 and not r["collapsed"]
    assert len(r["history"]["time_s"]) == len(r["history"]["disp_m"]) > 10
    assert [s["name"] for s in vs.scenarios.impact_setups()] == [
        "M80H45", "M75H45", "M75H20", "M60H20", "M60H25", "M60H30"]
    with pytest.raises(vs.VoussoirError, match="setup \"M1\""):
        vs.scenarios.arch_impact("M1")


def test_arch_impact_node_rule():
    # Node contacts integrated over the surface each node stands for (the scenario's default) or
    # at their points: the blow lands on the sloped base's face joint, so the first impact is
    # the same to round-off.
    r = vs.scenarios.arch_impact("M60H20", duration=0.02, per_edge=5)
    p = vs.scenarios.arch_impact("M60H20", duration=0.02, per_edge=5, node_rule="point")
    assert r["node_rule"] == "integrated" and p["node_rule"] == "point"
    assert r["first_peak_disp_m"] == pytest.approx(p["first_peak_disp_m"], rel=1e-6)
    with pytest.raises(vs.VoussoirError, match="node rule"):
        vs.scenarios.arch_impact("M60H20", duration=0.02, node_rule="points")


def test_arch_impact_settled_states_perturb_at_round_off():
    # Two settled states at the test's drop height: the second settled under gravity changed by
    # 1e-12 of itself; the median of two is their mean.
    r = vs.scenarios.arch_impact("M60H20", duration=0.02, per_edge=5, settled_states=2)
    assert r["runs_count"] == 2
    assert [x["settle_perturbation"] for x in r["runs"]] == [0.0, 1e-12]
    assert [x["height_offset_m"] for x in r["runs"]] == [0.0, 0.0]
    a, b = (x["max_disp_m"] for x in r["runs"])
    assert r["median_max_disp_m"] == pytest.approx(0.5 * (a + b), rel=1e-12)
    assert r["max_disp_m"] == a
    # At round-off level: the first impact agrees to far better than a micrometre.
    assert abs(a - b) < 1e-6
    for bad in (0, 17):
        with pytest.raises(vs.VoussoirError, match="settled_states"):
            vs.scenarios.arch_impact("M60H20", duration=0.02, settled_states=bad)
