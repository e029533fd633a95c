"""Hertz-Mindlin contact from material data, rebound observables, and the Psi2-Psi1 theory checks.

Rigid-body Coulomb theory of an oblique sphere impact in MBF's normalized angles: the contact point
slides throughout for Psi1 >= 2 chi (1 + e), Psi2 = (Psi1 - 2 chi (1 + e)) / e, else it rolls, Psi2 = 0.
With tangential compliance the contact point reverses at small Psi1 (Psi2 < 0; Maw, Barber and
Fawcett 1976).
"""
from __future__ import annotations

import math

import attrs
import numpy as np
import pytest

from frictionlab.contact import (Material, MindlinCompliance, Pair, chi, contact_radius, hertz_force,
                                 mindlin_stiffness, rigid_psi2)
from frictionlab.dataset import load_dataset
from frictionlab.errors import DatasetError, SceneError
from frictionlab.outcome import OutcomeScene, SpeedLaw, predict_outcomes
from frictionlab import rebound

ALUMINA, GLASS = Material(380e9, 0.23), Material(70e9, 0.25)
PAIR = Pair(ALUMINA, GLASS)
R = 2.5e-3
M = 4000.0 * 4.0 / 3.0 * math.pi * R**3
MU, E, V = 0.092, 0.98, 3.9


def test_effective_moduli_follow_the_formulas():
    E1, n1, E2, n2 = 380e9, 0.23, 70e9, 0.25
    assert PAIR.modulus == pytest.approx(1 / ((1 - n1**2) / E1 + (1 - n2**2) / E2), rel=1e-14)
    G1, G2 = E1 / (2 * (1 + n1)), E2 / (2 * (1 + n2))
    assert PAIR.shear == pytest.approx(1 / ((2 - n1) / G1 + (2 - n2) / G2), rel=1e-14)
    like = Pair(Material(200e9, 0.3), Material(200e9, 0.3))
    assert like.stiffness_ratio == pytest.approx(2 * (1 - 0.3) / (2 - 0.3), rel=1e-14)
    # MBF's example: a thin diametral slice of a sphere (k^2 = r^2/2) with nu = 0.28 has chi = 1.2558
    slice_ratio = Pair(Material(1e9, 0.28), Material(1e9, 0.28)).stiffness_ratio
    assert chi(slice_ratio, inertia_factor=0.5) == pytest.approx(1.2558, abs=1e-4)
    delta = 1e-6
    a = contact_radius(delta, R)
    assert a == pytest.approx(math.sqrt(R * delta))
    # k_t / k_n: dF_n/d(delta) = 2 E* a, so 8 G* a / (2 E* a) is the stiffness ratio
    kn = 2 * PAIR.modulus * a
    assert mindlin_stiffness(a, PAIR.shear) / kn == pytest.approx(PAIR.stiffness_ratio, rel=1e-12)
    assert (hertz_force(delta * 1.000001, PAIR.modulus, R) - hertz_force(delta, PAIR.modulus, R)) / (1e-6 * delta) \
        == pytest.approx(kn, rel=1e-5)


def ball(model="rigid", normal="hertz", shear=None, damping=0.01):
    n = ({"model": "hertz", "modulus": PAIR.modulus, "contact_time": None, "restitution": SpeedLaw(E)}
         if normal == "hertz" else
         {"model": "half-sine", "modulus": None, "contact_time": SpeedLaw(12.8e-6, V, -0.2), "restitution": SpeedLaw(E)})
    area = {"model": "hertz", "peak": None} if normal == "hertz" else {"model": "half-sine", "peak": SpeedLaw(0.133e-6, V, 0.8)}
    effects = {"spin", "slip-coupling"}
    comp = None
    if model == "mindlin":
        comp = MindlinCompliance(shear or PAIR.shear, damping, 1e-9 * R)
        effects.add("compliance")
    return OutcomeScene(mass=M, radius=R, normal=n, area=area, effects=frozenset(effects), compliance=comp,
                        materials=PAIR, friction=MU)


def test_rigid_coulomb_limit_matches_the_closed_form_on_both_branches():
    inc = np.radians(np.linspace(2.0, 80.0, 25))
    o = predict_outcomes("coulomb", ball(normal="half-sine"), {"mu": MU}, "exact", speed=V, incidence=inc)
    expected = rigid_psi2(o["psi1"], chi(PAIR.stiffness_ratio), E)
    edge = 2 * chi(PAIR.stiffness_ratio) * (1 + E)
    assert (o["psi1"] < edge).sum() >= 5 and (o["psi1"] > edge).sum() >= 5  # both branches sampled
    np.testing.assert_allclose(o["psi2"], expected, atol=1e-9 * o["psi1"].max())
    # the same observables in experimenters' terms: rolling gives v_t2/v_t1 = 5/7
    rolling = o["psi1"] < edge
    np.testing.assert_allclose(o["cm_tangential_cor"][rolling], 5 / 7, rtol=1e-9)
    np.testing.assert_allclose(o["normal_cor"], E)


def test_impulse_and_energy_balance_of_a_compliant_impact():
    """Angular momentum about the contact point is conserved (friction acts there); friction and the
    spring's damper can only take tangential kinetic energy away."""
    inc = np.radians([8.0, 20.0, 45.0])
    o = predict_outcomes("coulomb", ball("mindlin"), {"mu": MU}, "ode", speed=V, incidence=inc, rtol=1e-9)
    inertia = 0.4 * M * R**2
    L1 = M * R * o["tangential_speed"]
    L2 = M * R * o["rebound_speed_t"] + inertia * o["rebound_spin"]
    np.testing.assert_allclose(L2, L1, rtol=1e-7)
    K1 = 0.5 * M * o["tangential_speed"] ** 2
    K2 = 0.5 * M * o["rebound_speed_t"] ** 2 + 0.5 * inertia * o["rebound_spin"] ** 2
    assert np.all(K2 <= K1 * (1 + 1e-9))


def test_compliance_reverses_the_contact_point_at_small_psi1():
    inc = np.radians([12.0, 20.0])  # Psi1 about 2 and 3.4: rigid theory rolls (Psi2 = 0)
    comp = predict_outcomes("coulomb", ball("mindlin"), {"mu": MU}, "ode", speed=V, incidence=inc, rtol=1e-9)
    rigid = predict_outcomes("coulomb", ball(), {"mu": MU}, "ode", speed=V, incidence=inc, rtol=1e-9)
    assert np.all(comp["psi1"] < 2 * chi(PAIR.stiffness_ratio) * (1 + E))
    np.testing.assert_allclose(rigid["psi2"], 0.0, atol=1e-6)
    assert np.all(comp["psi2"] < -0.1)  # the contact point leaves moving backwards ...
    assert np.all(comp["contact_rebound_angle"] < 0)
    assert np.all(comp["rebound_spin"] > rigid["rebound_spin"])  # ... so the ball spins faster than rolling


def test_stiff_compliance_tends_to_the_rigid_sphere():
    inc = np.radians([10.0, 25.0, 50.0])
    rigid = predict_outcomes("coulomb", ball(), {"mu": MU}, "ode", speed=V, incidence=inc, rtol=1e-9)
    errs = []
    for factor in (1.0, 1e3):
        comp = predict_outcomes("coulomb", ball("mindlin", shear=PAIR.shear * factor, damping=0.2), {"mu": MU}, "ode",
                                speed=V, incidence=inc, rtol=1e-9)
        errs.append(np.max(np.abs(comp["rebound_spin"] / rigid["rebound_spin"] - 1)))
    assert errs[0] > 0.05  # real compliance matters at 10 deg ...
    assert errs[1] < 0.02 < errs[0]  # ... and a 1000x stiffer contact is nearly rigid


# --- published measurements, predicted from the stated friction coefficient and material data ---------
@pytest.fixture(scope="module")
def kharaz_spin():
    ds = load_dataset("kharaz2001-spin")
    return ds, rebound.stated_predictions(ds)


def test_rigid_model_predicts_measured_spin_from_30_to_60_deg(kharaz_spin):
    ds, pred = kharaz_spin
    inc = np.degrees(ds.columns["incidence"])
    band = (inc >= 30) & (inc <= 60)
    assert band.sum() >= 3
    rel = pred["rigid"][band] / ds.columns["rebound_spin"][band] - 1
    assert np.all(np.abs(rel) < 0.10), rel


def test_compliant_model_predicts_measured_spin_below_30_deg(kharaz_spin):
    """Within 15 % at 11 and 21 deg, where the rigid model is 20 and 30 % low."""
    ds, pred = kharaz_spin
    inc = np.degrees(ds.columns["incidence"])
    y = ds.columns["rebound_spin"]
    band = (inc > 8) & (inc < 30)
    assert band.sum() == 2
    assert np.all(np.abs(pred["mindlin"][band] / y[band] - 1) < 0.15)
    assert np.all(np.abs(pred["rigid"][band] / y[band] - 1) > 0.15)


@pytest.mark.xfail(strict=True, reason="at 6.1 deg the Mindlin model (Thornton's history simplification) "
                   "predicts 67 rad/s against 136 measured: not met")
def test_compliant_model_predicts_measured_spin_at_6_deg(kharaz_spin):
    ds, pred = kharaz_spin
    i = int(np.argmin(ds.columns["incidence"]))
    assert abs(pred["mindlin"][i] / ds.columns["rebound_spin"][i] - 1) < 0.15


def test_measured_datasets_are_labelled_and_selectable():
    for name, obs in (("kharaz2001-spin", "rebound_spin"), ("kharaz2001-tangential-cor", "cm_tangential_cor"),
                      ("kharaz2001-contact-angle", "contact_rebound_angle")):
        ds = load_dataset(name)
        assert ds.provenance.kind == "measured" and ds.observable == obs
        assert "Kharaz" in ds.provenance.source and "@" in ds.provenance.source  # repo path @ commit
        assert ds.scene.friction == 0.092 and ds.scene.materials == PAIR
        out = predict_outcomes("coulomb", ds, {"mu": MU}, "exact")
        assert np.all(np.isfinite(out[obs]))


# --- strict [scene] tables -----------------------------------------------------------------------------
def _outcome_toml(tmp_path, scene_extra: str) -> str:
    (tmp_path / "o.csv").write_text("speed,incidence,rebound_spin\n3.9,20,500\n3.9,40,550\n")
    (tmp_path / "o.toml").write_text(f"""
name = "o"
kind = "impact-outcome"
observable = "rebound_spin"
[columns]
speed = "m/s"
incidence = "deg"
rebound_spin = "rad/s"
[noise]
rebound_spin = "5 rad/s"
[provenance]
kind = "synthetic"
source = "test"
command = "pytest"
[scene]
mass = "0.26 g"
radius = "2.5 mm"
{scene_extra}
""")
    return str(tmp_path / "o.toml")


@pytest.mark.parametrize("extra, match", [
    ('impact_speed = "3 m/s"\n[scene.normal]\nmodel = "hertz"\nmodulus = "60 GPa"\nrestitution = 0.9',
     r"unknown key\(s\) \['impact_speed'\]; known: .*materials"),
    ('[scene.normal]\nmodel = "hertz"\nmodulus = "60 GPa"\nrestitution = 0.9\n[scene.compliance]\nmodel = "mindlin"\n'
     'stiffness = "1 N/m"', r"\[scene.compliance\] with model 'mindlin' has unknown key\(s\) \['stiffness'\]"),
    ('[scene.normal]\nmodel = "hertz"\nrestitution = 0.9\n[scene.materials]\nball_young = "380 GPa"\n'
     'ball_poisson = 0.23\nsurface_young = "70 GPa"\nsurface_poisson = 0.25\ncolour = "red"',
     r"\[scene.materials\] has unknown key\(s\) \['colour'\]; known: ball_poisson"),
    ('[scene.normal]\nmodel = "hertz"\nrestitution = 0.9\n[scene.materials]\nball_young = "380 GPa"\n'
     'ball_poisson = 0.7\nsurface_young = "70 GPa"\nsurface_poisson = 0.25', r"Poisson ratio must be in"),
    ('[scene.normal]\nmodel = "hertz"\nmodulus = "60 GPa"\nrestitution = 0.9\n[scene.compliance]\nmodel = "mindlin"',
     r"scene.compliance\] is missing 'shear_modulus'"),
])
def test_unknown_or_bad_scene_keys_are_one_line_errors(tmp_path, extra, match):
    with pytest.raises(DatasetError, match=match) as info:
        load_dataset(_outcome_toml(tmp_path, extra))
    assert "\n" not in str(info.value)


def test_mindlin_from_materials_loads(tmp_path):
    ds = load_dataset(_outcome_toml(tmp_path, '[scene.normal]\nmodel = "hertz"\nrestitution = 0.98\n'
                                    '[scene.compliance]\nmodel = "mindlin"\n[scene.materials]\nball_young = "380 GPa"\n'
                                    'ball_poisson = 0.23\nsurface_young = "70 GPa"\nsurface_poisson = 0.25\n'
                                    'friction = 0.092'))
    assert ds.scene.compliance.shear == pytest.approx(PAIR.shear)
    assert ds.scene.normal["modulus"] == pytest.approx(PAIR.modulus)
    assert "compliance" in ds.scene.effects
    with pytest.raises(SceneError, match="shear"):
        MindlinCompliance(-1.0)
    assert attrs.evolve(ds.scene, friction=None).friction is None


def test_report_section_shows_predictions_and_the_criterion():
    from types import SimpleNamespace

    from frictionlab.report import Context
    from frictionlab.report import rebound as section

    ctx = Context(SimpleNamespace(datasets=[load_dataset("kharaz2001-spin")]))
    sec = section.build(ctx)
    text = " ".join(str(payload) for _, payload in sec.blocks)
    assert "rigid model is within 10 % at 3 of 3" in text
    assert "Mindlin model is within 15 % of the measured spin at 2 of 3" in text
    assert [f.name for f in sec.figures] == ["psi2-psi1.png"]
    assert len(ctx.json["rebound_predictions"]["kharaz2001-spin"]) == 7
    assert section.build(Context(SimpleNamespace(datasets=[load_dataset("impact-outcome-synthetic")]))) is None


def test_time_series_scene_takes_mindlin_from_materials():
    from frictionlab import Scene, simulate

    spec = {"mass": "0.2618 g", "radius": "2.5 mm", "u0": "1.3 m/s", "effects": ["spin", "slip-coupling"],
            "area": {"model": "half-sine", "peak": "0.13 mm^2", "contact_time": "13 us"},
            "normal": {"model": "half-sine", "contact_time": "13 us", "normal_speed": "3.67 m/s", "restitution": 0.98},
            "compliance": {"model": "mindlin"},
            "materials": {"ball_young": "380 GPa", "ball_poisson": 0.23, "surface_young": "70 GPa",
                          "surface_poisson": 0.25}}
    scene = Scene.from_spec(spec, "impact", "s.toml")
    assert scene.compliance.shear == pytest.approx(PAIR.shear) and "compliance" in scene.effects
    tr = simulate("coulomb", scene, {"mu": MU}, solver="ode", n=101)
    assert np.all(np.abs(tr.force) <= MU * tr.N * (1 + 1e-6) + 1e-12)  # the Coulomb limit holds
    assert np.any(np.diff(np.sign(tr.v - R * tr.omega)) != 0)  # the contact point reverses (stick regime)
    with pytest.raises(SceneError, match="needs a \\[scene.compliance\\] table"):
        Scene.from_spec({**{k: v for k, v in spec.items() if k != "compliance"},
                         "effects": ["spin", "compliance"]}, "impact", "s.toml")
