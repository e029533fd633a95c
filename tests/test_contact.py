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

from frictionlab.core.errors import DatasetError, SceneError
from frictionlab.io.dataset import load_dataset
from frictionlab.physics import mdr
from frictionlab.physics.contact import (
    Material,
    MindlinCompliance,
    MindlinDeresiewiczCompliance,
    Pair,
    chi,
    contact_radius,
    hertz_force,
    mindlin_stiffness,
    rigid_psi2,
)
from frictionlab.solve import rebound
from frictionlab.solve.outcome import OutcomeScene, SpeedLaw, predict_outcomes

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


def ball(model="rigid", normal="hertz", shear=None, damping=0.01, pair=PAIR, inertia_factor=0.4, e=E):
    n = ({"model": "hertz", "modulus": pair.modulus, "contact_time": None, "restitution": SpeedLaw(e)}
         if normal == "hertz" else
         {"model": "half-sine", "modulus": None, "contact_time": SpeedLaw(12.8e-6, V, -0.2), "restitution": SpeedLaw(e)})
    area = {"model": "hertz", "peak": None} if normal == "hertz" else {"model": "half-sine", "peak": SpeedLaw(0.133e-6, V, 0.8)}
    effects = {"spin", "slip-coupling"}
    comp = None
    if model == "mindlin":
        comp = MindlinCompliance(shear or pair.shear, damping, 1e-9 * R)
    elif model == "mindlin-deresiewicz":
        comp = MindlinDeresiewiczCompliance(shear or pair.shear)
    if comp is not None:
        effects.add("compliance")
    return OutcomeScene(mass=M, radius=R, normal=n, area=area, effects=frozenset(effects), compliance=comp,
                        materials=pair, friction=MU, inertia_factor=inertia_factor)


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


# --- Mindlin-Deresiewicz with microslip by the Method of Dimensionality Reduction (frictionlab.physics.mdr) -----
A_FIXED, N_FIXED = 1e-4, 50.0  # contact radius [m] and normal force [N] of the quasi-static checks
USTAR = 3 * MU * N_FIXED / (2 * 8 * PAIR.shear * A_FIXED)  # displacement of gross slip: 3 mu N / (2 k_t)


def test_mdr_reproduces_cattaneo_mindlin_under_constant_normal_force():
    """Monotone tangential loading: F = mu N (1 - (1 - w/u*)^(3/2)), u* = 3 mu N / (2 * 8 G* a)."""
    w = np.linspace(0.0, 1.2 * USTAR, 121)
    F = mdr.tangential_force(np.full(w.shape, A_FIXED), np.full(w.shape, N_FIXED), w, PAIR.shear, MU)
    exact = MU * N_FIXED * (1 - np.clip(1 - w / USTAR, 0, None) ** 1.5)
    np.testing.assert_allclose(F, exact, atol=2e-3 * MU * N_FIXED)
    tiny = mdr.tangential_force([A_FIXED], [N_FIXED], [1e-6 * USTAR], PAIR.shear, MU)[0] / (1e-6 * USTAR)
    assert tiny == pytest.approx(8 * PAIR.shear * A_FIXED, rel=1e-9)  # initial stiffness: Mindlin's 8 G* a
    np.testing.assert_allclose(F[w >= USTAR], MU * N_FIXED, rtol=1e-12)  # gross slip at the Coulomb limit


def test_mdr_reproduces_the_mindlin_deresiewicz_hysteresis_loop():
    """Unloading from w* < u* to -w* and reloading: F = F* - 2 mu N (1 - (1 - (w* - w)/(2 u*))^(3/2)) on the way
    down (Mindlin and Deresiewicz 1953; Johnson, Contact Mechanics, eq. 7.60), the mirror image on the way
    back, and the loop closes."""
    wmax = 0.6 * USTAR
    up = np.linspace(0.0, wmax, 61)
    down = np.linspace(wmax, -wmax, 121)[1:]
    back = np.linspace(-wmax, wmax, 121)[1:]
    w = np.concatenate([up, down, back])
    F = mdr.tangential_force(np.full(w.shape, A_FIXED), np.full(w.shape, N_FIXED), w, PAIR.shear, MU)
    mun = MU * N_FIXED
    fstar = mun * (1 - (1 - wmax / USTAR) ** 1.5)
    exact_down = fstar - 2 * mun * (1 - (1 - (wmax - down) / (2 * USTAR)) ** 1.5)
    exact_back = -fstar + 2 * mun * (1 - (1 - (back + wmax) / (2 * USTAR)) ** 1.5)
    np.testing.assert_allclose(F[len(up):len(up) + len(down)], exact_down, atol=2e-3 * mun)
    np.testing.assert_allclose(F[len(up) + len(down):], exact_back, atol=2e-3 * mun)
    assert F[-1] == pytest.approx(fstar, abs=2e-3 * mun)
    # energy dissipated per cycle (Johnson eq. 7.61, W = 9 mu^2 P^2 (2 - nu) / (10 G a) [...], with the
    # contact's stiffness 8 G a / (2 - nu) = k_t): the loop is traversed clockwise, work done on the contact > 0
    area = np.trapezoid(F[len(up) - 1:], w[len(up) - 1:])
    assert area == pytest.approx(9 * 8 * mun**2 / (10 * 8 * PAIR.shear * A_FIXED) *
                                  (1 - (1 - fstar / mun) ** (5 / 3) - 5 * fstar / (6 * mun) *
                                   (1 + (1 - fstar / mun) ** (2 / 3))), rel=2e-2)


def test_mdr_impacts_balance_impulse_and_lose_energy_only_to_slip():
    inc = np.radians([3.0, 8.0, 20.0, 45.0])
    o = predict_outcomes("coulomb", ball("mindlin-deresiewicz"), {"mu": MU}, speed=V, incidence=inc)
    inertia = 0.4 * M * R**2
    np.testing.assert_allclose(M * R * o["rebound_speed_t"] + inertia * o["rebound_spin"],
                               M * R * o["tangential_speed"], rtol=1e-12)  # angular momentum about the contact point
    K1 = 0.5 * M * o["tangential_speed"] ** 2
    K2 = 0.5 * M * o["rebound_speed_t"] ** 2 + 0.5 * inertia * o["rebound_spin"] ** 2
    assert np.all(K2 <= K1 * (1 + 1e-9)) and np.all(K2 > 0.5 * K1)
    # converged in springs and steps: 4x of each changes the spin by less than 0.1 %
    fine = attrs.evolve(ball("mindlin-deresiewicz"), compliance=MindlinDeresiewiczCompliance(PAIR.shear, 1600))
    steps = mdr.STEPS_PER_PERIOD
    try:
        mdr.STEPS_PER_PERIOD = 4 * steps
        f = predict_outcomes("coulomb", fine, {"mu": MU}, speed=V, incidence=inc)
    finally:
        mdr.STEPS_PER_PERIOD = steps
    np.testing.assert_allclose(f["rebound_spin"], o["rebound_spin"], rtol=1e-3)


def test_mdr_tends_to_the_rigid_sphere_when_stiff_and_to_gross_slip_at_large_psi1():
    inc = np.radians([10.0, 25.0, 50.0])
    rigid = predict_outcomes("coulomb", ball(), {"mu": MU}, "ode", speed=V, incidence=inc, rtol=1e-10)
    real = predict_outcomes("coulomb", ball("mindlin-deresiewicz"), {"mu": MU}, speed=V, incidence=inc)
    stiff = predict_outcomes("coulomb", ball("mindlin-deresiewicz", shear=1e3 * PAIR.shear), {"mu": MU},
                             speed=V, incidence=inc)
    assert np.max(np.abs(real["rebound_spin"] / rigid["rebound_spin"] - 1)) > 0.2  # compliance matters at 10 deg
    np.testing.assert_allclose(stiff["rebound_spin"], rigid["rebound_spin"], rtol=0.01)
    # sliding throughout (Psi1 beyond 2 chi (1 + e)): the compliant contact joins the rigid closed form
    assert real["psi1"][2] > 2 * chi(PAIR.stiffness_ratio) * (1 + E)
    assert real["rebound_spin"][2] == pytest.approx(rigid["rebound_spin"][2], rel=1e-6)


def test_mdr_psi2_against_psi1_has_the_features_maw_barber_and_fawcett_found():
    """MBF (1976), Fig. 1, thin diametral slice (chi = 1.2558, nu = 0.28, k^2 = r^2/2, e = 1): 'Psi2 is negative
    for low values of Psi1', and gross slip throughout extends beyond the rigid theory's Psi1 = 4 chi, joining
    the rigid line Psi2 = Psi1 - 4 chi at large Psi1."""
    like = Pair(Material(380e9, 0.28), Material(380e9, 0.28))
    sc = ball("mindlin-deresiewicz", pair=like, inertia_factor=0.5, e=1.0)
    x = chi(like.stiffness_ratio, 0.5)
    inc = np.radians(np.linspace(0.5, 45.0, 40))
    o = predict_outcomes("coulomb", sc, {"mu": MU}, speed=V, incidence=inc)
    low = (o["psi1"] > 0.1) & (o["psi1"] < 4.0)
    assert low.sum() >= 10 and np.all(o["psi2"][low] < 0)
    assert o["psi2"].min() < -1.0  # a strong reversal, as in MBF's figure
    far = o["psi1"] > 4 * x * 1.3
    assert far.sum() >= 5
    np.testing.assert_allclose(o["psi2"][far], o["psi1"][far] - 4 * x, atol=1e-6 * o["psi1"].max())
    # for the Kharaz sphere (chi = 1.50) the same: reversal at Psi1 about 2 to 3.4, where the rigid sphere rolls
    k = predict_outcomes("coulomb", ball("mindlin-deresiewicz"), {"mu": MU}, speed=V, incidence=np.radians([12.0, 20.0]))
    assert np.all(k["psi2"] < -0.5) and np.all(k["contact_rebound_angle"] < 0)


def test_mdr_hard_cases_are_finite_or_a_clear_error():
    sc = ball("mindlin-deresiewicz")
    free = predict_outcomes("coulomb", sc, {"mu": 0.0}, speed=V, incidence=np.radians([5.0, 60.0]))
    np.testing.assert_array_equal(free["rebound_spin"], 0.0)  # no friction, no spin, v_t kept
    np.testing.assert_allclose(free["cm_tangential_cor"], 1.0, rtol=1e-12)
    edge = predict_outcomes("coulomb", sc, {"mu": 5.0}, speed=V, incidence=np.radians([0.01, 89.9]))
    assert np.all(np.isfinite(edge["rebound_spin"])) and np.all(np.isfinite(edge["psi2"]))
    soft = predict_outcomes("coulomb", ball("mindlin-deresiewicz", shear=1.0), {"mu": MU}, speed=V,
                            incidence=np.radians([10.0]))
    assert abs(soft["rebound_spin"][0]) < 1e-3  # a 1 Pa contact passes no tangential force
    with pytest.raises(SceneError, match="so stiff a contact is rigid"):
        predict_outcomes("coulomb", ball("mindlin-deresiewicz", shear=1e20), {"mu": MU}, speed=V,
                         incidence=np.radians([10.0]))


def test_mdr_needs_a_coulomb_law_and_is_not_a_trajectory_model(tmp_path):
    with pytest.raises(SceneError, match="not of the Coulomb form"):
        predict_outcomes("wear", ball("mindlin-deresiewicz"), {"lam": 1e6}, speed=V, incidence=np.radians([10.0]))
    ds = load_dataset(_outcome_toml(tmp_path, '[scene.normal]\nmodel = "hertz"\nrestitution = 0.98\n'
                                    '[scene.compliance]\nmodel = "mindlin-deresiewicz"\nsprings = 300\n'
                                    '[scene.materials]\nball_young = "380 GPa"\nball_poisson = 0.23\n'
                                    'surface_young = "70 GPa"\nsurface_poisson = 0.25\nfriction = 0.092'))
    assert ds.scene.compliance == MindlinDeresiewiczCompliance(PAIR.shear, 300)
    out = predict_outcomes("coulomb", ds, {"mu": MU})
    assert np.all(np.isfinite(out["rebound_spin"]))
    from frictionlab.physics.registry import get_law
    from frictionlab.solve.plan import make_plan

    with pytest.raises(SceneError, match="impact outcomes only"):
        make_plan(ds.scene.impact(V, 0.3).scene, get_law("coulomb"))
    from frictionlab.solve.choice import applicable_solvers

    ok = applicable_solvers("coulomb", ds.scene)
    assert ok["ode"] is None and "frictionlab.physics.mdr" in ok["exact"]  # fits run it under the name 'ode'
    assert all("not of the Coulomb form" in why for why in applicable_solvers("wear", ds.scene).values())


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
    """Mindlin-Deresiewicz with microslip (MDR), stated mu and materials, nothing fitted: within 15 % at every
    measured angle below 30 deg (6.1, 11 and 21 deg: -13.7, +6.3, -1.7 %), where the rigid model is 20 and 30 %
    low at 11 and 21 deg."""
    ds, pred = kharaz_spin
    inc = np.degrees(ds.columns["incidence"])
    y = ds.columns["rebound_spin"]
    band = inc < 30
    assert band.sum() == 3
    assert np.all(np.abs(pred["mindlin-deresiewicz"][band] / y[band] - 1) < 0.15), pred["mindlin-deresiewicz"][band]
    assert np.all(np.abs(pred["rigid"][band & (inc > 8)] / y[band & (inc > 8)] - 1) > 0.15)


def test_compliant_model_predicts_measured_spin_at_6_deg(kharaz_spin):
    """At 6.1 deg (Psi1 = 1.0, where initial gross slip gives way to initial stick with microslip) the model
    gives 117.5 rad/s against 136 measured (-13.7 %). The same paper's tangential restitution at that angle
    implies 119.1 rad/s (frictionlab.io.datagen.kharaz.implied_spin), 1.3 % from the model: the spin marker is
    14 % above what the restitution figure implies. With nu = 0.22 for the glass the model gives -16 %."""
    ds, pred = kharaz_spin
    i = int(np.argmin(ds.columns["incidence"]))
    assert abs(pred["mindlin-deresiewicz"][i] / ds.columns["rebound_spin"][i] - 1) < 0.15


def test_the_two_kharaz_figures_are_compared_by_momentum_balance(kharaz_spin):
    """omega_2 = (1 - e_t) v_t1 / (0.4 r) from the restitution figure: the spin figure's 6.1 deg marker is 12.6 %
    above it (the data's own inconsistency), and the model is within 2 % of the restitution figure there."""
    from frictionlab.io.datagen.kharaz import implied_spin

    ds, pred = kharaz_spin
    inc, w = implied_spin()
    np.testing.assert_allclose(inc, np.degrees(ds.columns["incidence"]), atol=1e-9)
    rel = w / ds.columns["rebound_spin"] - 1
    assert rel[0] == pytest.approx(-0.126, abs=0.002) and np.all(np.abs(rel[1:3]) < 0.06)
    assert abs(pred["mindlin-deresiewicz"][0] / w[0] - 1) < 0.02


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
kind = "known"
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
    ('[scene.normal]\nmodel = "hertz"\nmodulus = "60 GPa"\nrestitution = 0.9\n[scene.compliance]\n'
     'model = "mindlin-deresiewicz"\nshear_modulus = "13 GPa"\nsprings = 2.5', r"springs must be an integer"),
    ('[scene.normal]\nmodel = "hertz"\nmodulus = "60 GPa"\nrestitution = 0.9\n[scene.compliance]\nmodel = "hooke"',
     r"scene.compliance.model must be one of 'linear', 'mindlin', 'mindlin-deresiewicz'"),
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
    assert "Mindlin-Deresiewicz model is within 15 % of the measured spin at 3 of 3" in text
    assert [f.name for f in sec.figures] == ["psi2-psi1.png"]
    assert len(ctx.json["rebound_predictions"]["kharaz2001-spin"]) == 7
    assert section.build(Context(SimpleNamespace(datasets=[load_dataset("impact-outcome-synthetic")]))) is None
    assert "Consistency" not in text  # needs the same experiment's restitution
    both = section.build(Context(SimpleNamespace(datasets=[load_dataset("kharaz2001-spin"),
                                                            load_dataset("kharaz2001-tangential-cor")])))
    text = " ".join(str(payload) for _, payload in both.blocks)
    assert "implies 119.1 rad/s at 6.1 deg (-12.6 % from the measured spin)" in text


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


def test_mdr_impacts_compiled_loop_is_the_array_form():
    """mdr.impacts' compiled loop against the same Velocity Verlet written with mdr.limits and mdr.step on arrays
    (rows of different contact times, a row sliding throughout, one sticking): equal to round-off."""
    rng = np.random.default_rng(3)
    rows, steps = 5, 700
    tc = rng.uniform(20e-6, 60e-6, rows)
    t = np.linspace(0.0, 1.0, steps + 1)[None, :] * tc[:, None]
    N = 900.0 * np.sin(np.pi * t / tc[:, None])
    A = 2e-7 * np.sin(np.pi * t / tc[:, None])
    v0, w0 = np.array([0.5, 3.0, 8.0, 1.0, 0.02]), np.array([0.0, 10.0, -50.0, 0.0, 0.0])
    args = (0.3, PAIR.shear, M, R, 0.4 * M * R**2)
    v, w = mdr.impacts(t, N, A, *args, v0, w0, springs=300)
    a = np.sqrt(np.maximum(A, 0.0) / np.pi)
    x = mdr.grid(300)[None, :] * a.max(axis=1)[:, None]
    k = 8.0 * PAIR.shear * a.max(axis=1) / 300
    mu, _, mass, radius, inertia = args
    vr, wr, f, F = v0.astype(float), w0.astype(float), np.zeros(x.shape), np.zeros(rows)
    for i in range(steps):
        dt = t[:, i + 1] - t[:, i]
        vr = vr - 0.5 * dt * F / mass
        wr = wr + 0.5 * dt * F * radius / inertia
        f = mdr.step(f, (k * ((vr - radius * wr) * dt))[:, None], a[:, i + 1], mdr.limits(a[:, i + 1], N[:, i + 1], mu, x), x)
        F = f.sum(axis=1)
        vr = vr - 0.5 * dt * F / mass
        wr = wr + 0.5 * dt * F * radius / inertia
    np.testing.assert_allclose(v, vr, rtol=1e-12, atol=1e-12 * np.abs(v0).max())
    np.testing.assert_allclose(w, wr, rtol=1e-12, atol=1e-12 * np.abs(w0).max())
    assert not np.allclose(v, v0)  # the contact acted
