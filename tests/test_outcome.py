"""Impact outcomes: one impact per row, rebound spin, tangential restitution and rebound angle.

Rigid sphere (I = 2 m r^2 / 5) with slip coupling and Coulomb friction, half-sine normal impulse
P = m v_n (1 + e): the contact point stops slipping iff mu P >= (2/7) m v_t, i.e.
tan(theta) <= (7/2) mu (1 + e). Then v_t2 = 5 v_t / 7, omega_2 = 5 v_t / (7 r), e_T = 0.
Otherwise v_t2 = v_t - mu (1 + e) v_n, omega_2 = 5 mu (1 + e) v_n / (2 r),
e_T = -(1 - (7/2) mu (1 + e) v_n / v_t).
"""
from __future__ import annotations

import filecmp
import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import beta

import frictionlab as fl
from frictionlab.core.errors import DatasetError, SceneError
from frictionlab.io.datagen import outcome as gen
from frictionlab.physics.scene import Compliance
from frictionlab.solve.outcome import (
    HertzPulse,
    OutcomeScene,
    SpeedLaw,
    hertz_shape,
    predict_outcomes,
)

M, R = 0.0459, 0.02135
SPEEDS = np.repeat([20.0, 40.0], 7)
INC = np.radians(np.tile([5.0, 15.0, 30.0, 45.0, 55.0, 65.0, 80.0], 2))


def half_sine(e=0.78, tc=450e-6, **kw):
    return OutcomeScene(mass=M, radius=R, normal={"model": "half-sine", "modulus": None,
                                                  "contact_time": SpeedLaw(tc), "restitution": SpeedLaw(e)}, **kw)


def rigid_coulomb(speed, inc, mu, e, ref="normal"):
    along, across = (np.sin, np.cos) if ref == "normal" else (np.cos, np.sin)
    vt, vn = speed * along(inc), speed * across(inc)
    grip = np.tan(inc if ref == "normal" else math.pi / 2 - inc) <= 3.5 * mu * (1 + e)
    v2 = np.where(grip, 5 * vt / 7, vt - mu * (1 + e) * vn)
    w2 = np.where(grip, 5 * vt / (7 * R), 5 * mu * (1 + e) * vn / (2 * R))
    et = np.where(grip, 0.0, -(1 - 3.5 * mu * (1 + e) * vn / vt))
    angle = np.arctan2(v2, e * vn) if ref == "normal" else np.arctan2(e * vn, v2)
    return grip, w2, et, angle


@pytest.mark.parametrize("solver", ["exact", "ode"])
def test_rigid_coulomb_outcomes_and_grip_slip_transition(solver):
    mu, e = 0.25, 0.78
    out = predict_outcomes("coulomb", half_sine(e), {"mu": mu}, solver, speed=SPEEDS, incidence=INC)
    grip, w2, et, angle = rigid_coulomb(SPEEDS, INC, mu, e)
    assert grip.any() and (~grip).any()  # both regimes are in the sweep
    assert np.array_equal(out["rolled"], grip)
    assert np.allclose(out["rebound_spin"], w2, rtol=1e-8)
    assert np.allclose(out["tangential_cor"], et, rtol=1e-8, atol=1e-9)
    assert np.allclose(out["rebound_angle"], angle, rtol=1e-8)
    assert np.all(out["tangential_cor"] <= 1e-9)  # a rigid ball never reverses its contact point
    assert set(out) >= {"rebound_spin", "tangential_cor", "rebound_angle", "contact_time", "restitution", "rolled"}


def test_angle_from_the_surface():
    """30 deg from the surface is 60 deg from the normal; the rebound angle is measured likewise."""
    mu, e = 0.25, 0.78
    inc_surface = math.pi / 2 - INC
    out = predict_outcomes("coulomb", half_sine(e, angle_reference="surface"), {"mu": mu}, "exact",
                           speed=SPEEDS, incidence=inc_surface)
    ref = predict_outcomes("coulomb", half_sine(e), {"mu": mu}, "exact", speed=SPEEDS, incidence=INC)
    assert np.allclose(out["rebound_spin"], ref["rebound_spin"], rtol=1e-12)
    assert np.allclose(out["rebound_angle"], math.pi / 2 - ref["rebound_angle"], rtol=1e-12)


def test_speed_dependent_contact_time_and_restitution():
    s = OutcomeScene(mass=M, radius=R, normal={"model": "half-sine", "modulus": None,
                                               "contact_time": SpeedLaw(450e-6, 30.0, -0.2),
                                               "restitution": SpeedLaw(0.78, 30.0, 0.0, -0.004)})
    out = predict_outcomes("coulomb", s, {"mu": 0.3}, "exact", speed=np.array([10.0, 30.0, 60.0, 400.0]),
                           incidence=np.radians([30.0, 30.0, 30.0, 30.0]))
    vn = np.array([10.0, 30.0, 60.0, 400.0]) * math.cos(math.radians(30))
    assert np.allclose(out["contact_time"], 450e-6 * (vn / 30.0) ** -0.2, rtol=1e-14)
    assert np.allclose(out["restitution"], np.clip(0.78 - 0.004 * (vn - 30.0), 0, 1), rtol=1e-14)
    assert out["restitution"][-1] == 0.0  # kept within [0, 1]


def test_the_tabulated_hertz_shape_is_the_dense_solution():
    """The Hermite interpolants between the knots against scipy's dense output of the same solve."""
    from frictionlab.solve import hertzshape

    s_end, dense = hertzshape.solution()
    s = np.linspace(0.0, s_end, 100_003)
    (y, dy), (y_ref, dy_ref) = hertzshape.many(s), dense(s)
    assert np.abs(y - y_ref).max() < 1e-13 and np.abs(dy - dy_ref).max() < 1e-10
    assert hertzshape.end() == pytest.approx(hertzshape.exact_end(), rel=1e-11)
    assert hertzshape.at(float(s[777])) == (y[777], dy[777])


def test_hertz_pulse():
    s_end, y, dy = hertz_shape()
    assert s_end == pytest.approx(0.8 * beta(0.4, 0.5), rel=1e-11)  # 2 int_0^1 dy / sqrt(1 - y^(5/2))
    assert float(y(s_end / 2)) == pytest.approx(1.0, rel=1e-10)  # peak indentation delta_m at mid-contact
    modulus, e, vn = 5e7, 0.78, 20.0
    scene = OutcomeScene(mass=M, radius=R, normal={"model": "hertz", "modulus": modulus, "contact_time": None,
                                                   "restitution": SpeedLaw(e)}, area={"model": "hertz", "peak": None})
    imp = scene.impact(vn, 1e-9)  # nearly head-on
    K = 4 / 3 * modulus * math.sqrt(R)
    dm = (5 * M * vn**2 / (4 * K)) ** 0.4
    assert imp.contact_time == pytest.approx(s_end * dm / vn, rel=1e-12)
    impulse = quad(lambda t: float(imp.scene.normal(t)), 0, imp.contact_time, epsabs=0, epsrel=1e-10, limit=200)[0]
    assert impulse == pytest.approx(M * vn * (1 + e), rel=1e-6)
    A, dA = imp.scene.area(np.array([imp.contact_time / 2, 0.0]))
    assert A[0] == pytest.approx(math.pi * R * dm, rel=1e-10) and dA[0] == pytest.approx(0, abs=1e-6 * math.pi * R * vn)
    assert dA[1] == pytest.approx(math.pi * R * vn, rel=1e-10)
    # coulomb with a Hertz force: the same rigid-sphere outcomes (they depend on the impulse only)
    out = predict_outcomes("coulomb", scene, {"mu": 0.25}, "ode", speed=SPEEDS, incidence=INC)
    grip, w2, et, angle = rigid_coulomb(SPEEDS, INC, 0.25, e)
    assert np.allclose(out["rebound_spin"], w2, rtol=1e-7)
    # the wear law reads the Hertz contact area
    wear = predict_outcomes("wear", scene, {"lam": 1e6}, "ode", speed=SPEEDS, incidence=INC)
    assert np.all(np.isfinite(wear["rebound_spin"])) and np.all(wear["rebound_spin"] > 0)


def test_inbound_spin():
    """Backspin raises the inbound slip v_t - r omega_1; rolling on arrival leaves e_T undefined: an error."""
    s = half_sine()
    inc = np.radians([45.0])
    plain = predict_outcomes("coulomb", s, {"mu": 0.25}, "exact", speed=30.0, incidence=inc)
    back = predict_outcomes("coulomb", s, {"mu": 0.25}, "exact", speed=30.0, incidence=inc, spin=-300.0)
    assert back["rebound_spin"][0] < plain["rebound_spin"][0]
    rolling = 30.0 * math.sin(inc[0]) / R
    with pytest.raises(SceneError, match="row 1: the contact point does not slip"):
        predict_outcomes("coulomb", s, {"mu": 0.25}, "exact", speed=30.0, incidence=inc, spin=rolling)


def test_compliance_reverses_the_contact_point_at_low_incidence():
    """With a tangential spring the contact point can leave backwards: e_T > 0 (Maw, Barber and Fawcett).

    The spring is chosen so that half a tangential oscillation of the contact point (effective mass
    2m/7) fits in the contact, k = (2m/7)(pi/t_c)^2: a ball that grips early leaves with its contact
    point reversed, e_T close to 1 less the damper's loss. At glancing incidence it slides throughout
    and e_T < 0, as for a rigid ball.
    """
    tc = 450e-6
    k = (2 * M / 7) * (math.pi / tc) ** 2
    c = 2 * 0.05 * math.sqrt(k * 2 * M / 7)
    soft = half_sine(tc=tc, effects=frozenset({"spin", "slip-coupling", "compliance"}), compliance=Compliance(k, c))
    inc = np.radians([10.0, 20.0, 30.0, 75.0])
    out = predict_outcomes("coulomb", soft, {"mu": 0.35}, "ode", speed=30.0, incidence=inc)
    assert np.all(out["tangential_cor"][:3] > 0.7) and np.all(out["tangential_cor"][:3] < 1.0)
    assert out["tangential_cor"][3] < 0
    rigid = predict_outcomes("coulomb", half_sine(tc=tc), {"mu": 0.35}, "exact", speed=30.0, incidence=inc)
    assert np.allclose(rigid["tangential_cor"][:3], 0.0, atol=1e-12)
    # the reversed contact point means the ball leaves spinning faster than rolling: omega_2 r > v_t2
    assert np.all(out["rebound_spin"][:3] * R > out["rebound_speed_t"][:3])


# --- the synthetic built-in dataset ---------------------------------------------------------------
def test_synthetic_dataset_loads_in_si_with_its_truth():
    d = fl.load_dataset("impact-outcome-synthetic")
    assert d.kind == "impact-outcome" and d.observable == "rebound_spin" and len(d) == 21
    assert d.provenance.kind == "synthetic" and d.provenance.seed == gen.SEED
    assert d.provenance.truth["law"] == "coulomb" and d.provenance.truth["mu"] == 0.25
    assert d.provenance.command == "frictionlab datasets rebuild"
    assert d.columns["incidence"][0] == pytest.approx(math.radians(10))
    assert d.sigma == pytest.approx(100 * 2 * math.pi / 60)
    assert isinstance(d.scene, OutcomeScene) and d.scene.mass == pytest.approx(0.0459)
    with pytest.raises(DatasetError, match="no time column"):
        d.t


def test_synthetic_dataset_is_the_truth_plus_its_noise():
    """Predicted with the recorded truth, each outcome's residuals look like the stated noise."""
    d = fl.load_dataset("impact-outcome-synthetic")
    pred = predict_outcomes(d.provenance.truth["law"], d, {"mu": d.provenance.truth["mu"]}, "exact")
    for col in ("rebound_spin", "tangential_cor", "rebound_angle"):
        z = (d.columns[col] - pred[col]) / d.noise[col]
        assert np.max(np.abs(z)) < 4, col
        assert 0.3 < np.mean(z**2) < 2.5, col
    # the wrong friction coefficient is far off
    off = predict_outcomes("coulomb", d, {"mu": 0.15}, "exact")
    assert np.mean(((d.y - off["rebound_spin"]) / d.sigma) ** 2) > 25


def test_generator_is_reproducible(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir(), b.mkdir()
    first, second = gen.build(a), gen.build(b)
    assert [p.name for p in first] == ["impact-outcome-synthetic.csv", "impact-outcome-synthetic.toml"]
    for p, q in zip(first, second):
        assert filecmp.cmp(p, q, shallow=False)
        assert filecmp.cmp(p, fl.io.dataset.builtin_dir() / p.name, shallow=False)


# --- errors ----------------------------------------------------------------------------------------
def test_errors_are_clear():
    with pytest.raises(DatasetError, match="impact-golf-v28' is a impact dataset|needs an impact-outcome"):
        predict_outcomes("wear", fl.load_dataset("impact-golf-v28"), {"lam": 1e6})
    with pytest.raises(SceneError, match="impact-outcome.*predict_outcomes"):
        fl.simulate("coulomb", fl.load_dataset("impact-outcome-synthetic"), {"mu": 0.3})
    with pytest.raises(SceneError, match="needs speed"):
        predict_outcomes("coulomb", half_sine(), {"mu": 0.3})
    with pytest.raises(SceneError, match="row 2: incidence must be strictly between 0 and 90"):
        predict_outcomes("coulomb", half_sine(), {"mu": 0.3}, speed=[20.0, 20.0], incidence=[0.5, 0.0])
    with pytest.raises(SceneError, match="'wear' needs A"):
        predict_outcomes("wear", half_sine(), {"lam": 1e6}, speed=[20.0], incidence=[0.5])


@pytest.mark.parametrize("old, new, match", [
    ("20,10,", "20,0,", "column 'incidence' line 3: incidence must be strictly between 0 and 90"),
    ("20,10,", "-20,10,", "column 'speed' line 3: impact speed must be positive"),
    ('observable = "rebound_spin"', 'observable = "speed"', "not an impact outcome"),
    ('model = "half-sine"\ncontact_time = "450 us"', 'model = "hertz"\ncontact_time = "450 us"', "modulus"),
    ('angle_reference = "normal"', 'angle_reference = "sideways"', "angle_reference"),
    ('restitution = 0.78', 'restitution = 1.78', "restitution must be in \\[0, 1\\]"),
    ('[scene.normal]', '[scene.nromal]', "unknown key.*nromal"),
])
def test_bad_outcome_datasets(tmp_path, old, new, match):
    src = fl.io.dataset.builtin_dir()
    for ext in ("csv", "toml"):
        text = (src / f"impact-outcome-synthetic.{ext}").read_text()
        if old in text:
            text = text.replace(old, new, 1)
        (tmp_path / f"d.{ext}").write_text(text)
    with pytest.raises(DatasetError, match=match) as err:
        fl.load_dataset(tmp_path / "d.toml")
    assert "\n" not in str(err.value)


def test_registered_predictor_fits_the_synthetic_truth(monkeypatch):
    """With the predictor registered, fitting Coulomb to the synthetic outcomes recovers mu = 0.25."""
    from frictionlab.inference.fitting import fit as fitting
    from frictionlab.inference.fitting.predict import PREDICTORS, outcome_predictor

    monkeypatch.setitem(PREDICTORS, "impact-outcome", outcome_predictor)
    r = fitting.fit("coulomb", "impact-outcome-synthetic", solver="exact")
    assert r.ok
    mu, err = r.value("mu"), r.stderr("mu")
    assert 0 < err < 0.01 and abs(mu - 0.25) < 3 * err
