"""The spring-slider with a mass: m dv/dt = N load - F, d load/dt = k (V_lp - v) (Gu, Rice, Ruina and Tse 1984).

Quasi-static (mass 0, the default) and inertial sliders agree where both apply; with a mass, stick-slip
below k_c and the slip law's runaway after a large jump above k_c are followed instead of refused."""
from __future__ import annotations

import math

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.core.errors import DatasetError, SolverError
from frictionlab.io.datagen.springslider import TRUTH
from frictionlab.physics.scene import ConstantNormal, Scene, SpringLoad

RS = dict(TRUTH)  # mu0 0.6, a 0.008, b 0.012, Dc 10 um: k_c = 400 /m
K_C = (RS["b"] - RS["a"]) / RS["Dc"]
N = 1e4
MASS = 1e4  # [kg]: m V^2 / (N a Dc) ~ 1e-3, so the linear stability boundary stays at k_c


def slider(k, velocities, T, mass, times=(0.0, 1.0)):
    return Scene(kind="spring-slider", mass=1.0, u0=velocities[0], duration=T, normal=ConstantNormal(N),
                 spring=SpringLoad(k, times, velocities, mass=mass))


def test_a_light_slider_follows_the_quasi_static_one():
    t = np.linspace(0.0, 30.0, 301)
    quasi = fl.simulate("rate-state-aging", slider(5 * K_C, (1e-6, 1e-5), 30.0, 0.0), RS, t=t)
    heavy = fl.simulate("rate-state-aging", slider(5 * K_C, (1e-6, 1e-5), 30.0, 1.0), RS, t=t)
    assert np.ptp(quasi.load) > 0.01  # a real transient
    assert np.max(np.abs(heavy.load - quasi.load)) < 1e-6
    assert np.max(np.abs(heavy.v - quasi.v)) < 1e-3 * 1e-5


def _swing(law, k):
    """v / V_lp after a 5 % step on a slider with mass: (late / early amplitude of v - V_lp, late max, late min)."""
    t = np.linspace(0.0, 120.0, 2401)
    tr = fl.simulate(law, slider(k, (1e-5, 1.05e-5), 120.0, MASS), RS, t=t, rtol=1e-8)
    x = tr.v / 1.05e-5
    early, late = x[(t > 10) & (t < 40)], x[t > 90]
    return np.abs(late - 1).max() / np.abs(early - 1).max(), late.max(), late.min()


@pytest.mark.parametrize("law", ["rate-state-aging", "rate-state-slip"])
def test_with_inertia_stable_above_k_c_and_stick_slip_below(law):
    assert _swing(law, 1.2 * K_C)[0] < 0.5  # the ringing after the step dies out
    growth, hi, lo = _swing(law, 0.85 * K_C)
    assert hi > 5 and lo < 0.2  # grown into a limit cycle of fast slips and near-stops


def test_the_slip_laws_runaway_is_refused_quasi_statically_by_its_cause_and_followed_with_a_mass():
    t = np.linspace(0.0, 30.0, 301)
    with pytest.raises(SolverError) as exc:
        fl.simulate("rate-state-slip", slider(2 * K_C, (1e-5, 1e-4), 30.0, 0.0, (0.0, 5.0)), RS, t=t)
    msg = str(exc.value)
    assert "above the critical stiffness" in msg and "Gu, Rice, Ruina and Tse 1984" in msg and "mass" in msg
    t = np.concatenate([np.linspace(0.0, 5.0, 11)[:-1], np.linspace(5.0, 7.0, 20001), np.linspace(7.01, 30.0, 100)])
    tr = fl.simulate("rate-state-slip", slider(2 * K_C, (1e-5, 1e-4), 30.0, 1.0, (0.0, 5.0)), RS, t=t)
    steady = RS["mu0"] + (RS["a"] - RS["b"]) * math.log(100.0)
    assert tr.v.max() > 100 * 1e-4  # a dynamic slip event, hundreds of times the load point (0.044 m/s)...
    assert tr.load.min() < steady - 0.02  # ...that overshoots the new steady friction (to 0.540)...
    assert tr.load[-1] == pytest.approx(steady, abs=1e-6)  # ...and settles on it


def test_below_k_c_the_quasi_static_runaway_names_stick_slip():
    t = np.linspace(0.0, 200.0, 401)
    with pytest.raises(SolverError, match=r"below the critical stiffness k_c = \(b - a\)/Dc = 400 /m: stick-slip"):
        fl.simulate("rate-state-aging", slider(0.5 * K_C, (1e-5, 1.05e-5), 200.0, 0.0), RS, t=t)


def test_spring_mass_from_toml_and_its_bad_values(tmp_path):
    from frictionlab.io.dataset import load_dataset
    from frictionlab.io.template import template

    toml, csv = template("spring-slider", "ss")
    (tmp_path / "ss.csv").write_text(csv)
    (tmp_path / "ss.toml").write_text(toml.replace("# mass = ", "mass = "))
    assert load_dataset(tmp_path / "ss.toml").scene.spring.mass > 0
    (tmp_path / "ss.toml").write_text(toml.replace("# mass = \"", "mass = \"-"))
    with pytest.raises(DatasetError, match="mass"):
        load_dataset(tmp_path / "ss.toml")
