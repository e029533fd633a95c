"""Rebound of elastic spheres: rigid and compliant predictions from stated material data, the
Psi2-Psi1 curves of Maw, Barber and Fawcett, and predicted-against-measured tables for measured
impact-outcome datasets. Nothing here fits: the friction coefficient is the one the source states.
"""
from __future__ import annotations

import io

import attrs
import numpy as np

from ..physics.contact import (
    MindlinCompliance,
    MindlinDeresiewiczCompliance,
    chi,
    rigid_psi2,
)
from .outcome import OutcomeScene, predict_outcomes, rows_of

#: The tangential models compared by default: rigid sphere (slip, then roll) and Mindlin-Deresiewicz
#: compliance with microslip. 'mindlin' (the one-state simplification) is available by name.
MODELS = ("rigid", "mindlin-deresiewicz")
LABELS = {"rigid": "rigid", "mindlin": "Mindlin (one-state)", "mindlin-deresiewicz": "Mindlin-Deresiewicz"}


def variant(scene: OutcomeScene, model: str, damping_ratio: float = 0.01) -> OutcomeScene:
    """The scene as a Hertz contact from its materials (E*, restitution kept), with a rigid tangential
    contact ('rigid'), Mindlin-Deresiewicz compliance with microslip ('mindlin-deresiewicz', frictionlab.physics.mdr)
    or the one-state Mindlin simplification ('mindlin'), G* from the materials."""
    if scene.materials is None:
        raise ValueError("a prediction from material data needs [scene.materials]")
    normal = {**scene.normal, "model": "hertz", "modulus": scene.materials.modulus, "contact_time": None}
    hertz = attrs.evolve(scene, normal=normal, area={"model": "hertz", "peak": None})
    if model == "rigid":
        return attrs.evolve(hertz, compliance=None, effects=scene.effects - {"compliance"})
    if model == "mindlin-deresiewicz":
        comp = MindlinDeresiewiczCompliance(scene.materials.shear)
    elif model == "mindlin":
        comp = MindlinCompliance(scene.materials.shear, damping_ratio, 1e-9 * scene.radius)
    else:
        raise ValueError(f"unknown tangential model {model!r}; known: rigid, mindlin, mindlin-deresiewicz")
    return attrs.evolve(hertz, compliance=comp, effects=scene.effects | {"compliance"})


def stated_predictions(dataset, models=MODELS) -> dict[str, np.ndarray]:
    """Each model's prediction of the dataset's observable (SI), Coulomb friction at the stated mu."""
    scene = dataset.scene
    if scene.friction is None:
        raise ValueError(f"dataset '{dataset.name}' states no friction coefficient ([scene.materials] friction)")
    rows = rows_of(dataset)
    out = {}
    for model in models:
        o = predict_outcomes("coulomb", variant(scene, model), {"mu": scene.friction}, "ode",
                             speed=rows["speed"], incidence=rows["incidence"], spin=rows["spin"], rtol=1e-8)
        out[model] = o[dataset.observable]
    return out


def spin_from_restitution(incidence, cor_incidence, cor, speed, radius: float, inertia_factor: float = 0.4):
    """Rebound spin [rad/s] implied by a centre-of-mass tangential restitution e_t = v_t2/v_t1 measured at
    ``cor_incidence`` (same units as ``incidence``, from the normal), linearly interpolated at ``incidence``
    [deg]: the tangential impulse J gives m dv_t = -J and I domega = r J, so for no inbound spin
    omega_2 = (1 - e_t) V sin(theta) / (f r), f = I / (m r^2). A check between two published figures."""
    inc = np.asarray(incidence, dtype=float)
    et = np.interp(inc, np.asarray(cor_incidence, dtype=float), np.asarray(cor, dtype=float))
    return (1.0 - et) * np.asarray(speed, dtype=float) * np.sin(np.radians(inc)) / (inertia_factor * radius)


def consistency(spin_ds, cor_ds) -> np.ndarray | None:
    """Spin implied by ``cor_ds`` (centre-of-mass tangential restitution) at ``spin_ds``'s rows, when both
    come from one experiment (same group, one speed, no inbound spin); else None."""
    if (spin_ds.observable != "rebound_spin" or cor_ds.observable != "cm_tangential_cor" or not spin_ds.group
            or spin_ds.group != cor_ds.group or "spin" in spin_ds.columns):
        return None
    speeds = np.concatenate([spin_ds.columns["speed"], cor_ds.columns["speed"]])
    if np.ptp(speeds) > 1e-9 * np.max(speeds):
        return None
    s = spin_ds.scene
    return spin_from_restitution(np.degrees(spin_ds.columns["incidence"]), np.degrees(cor_ds.columns["incidence"]),
                                 cor_ds.columns["cm_tangential_cor"], spin_ds.columns["speed"], s.radius,
                                 s.inertia_factor)


def comparison_rows(dataset) -> list[dict]:
    """Predicted against measured per row: incidence [deg], measured, each model's value and residual (SI)."""
    pred = stated_predictions(dataset)
    y = dataset.columns[dataset.observable]
    rows = []
    for i, inc in enumerate(np.degrees(dataset.columns["incidence"])):
        row = {"incidence_deg": float(inc), "measured": float(y[i])}
        for m, p in pred.items():
            row[m] = float(p[i])
            row[f"{m}_residual"] = float(p[i] - y[i])
            row[f"{m}_relative"] = float((p[i] - y[i]) / y[i]) if y[i] != 0 else float("nan")
        rows.append(row)
    return rows


def psi_curves(scene: OutcomeScene, speed: float, incidence_deg=None, models=MODELS) -> dict[str, np.ndarray]:
    """Psi1 and Psi2 of the models' spheres over incidences [deg] at ``speed`` [m/s], with the
    rigid closed form; Coulomb friction at the scene's stated mu."""
    inc = np.radians(np.linspace(1.0, 50.0, 22) if incidence_deg is None else np.asarray(incidence_deg, dtype=float))
    out = {}
    for model in models:
        o = predict_outcomes("coulomb", variant(scene, model), {"mu": scene.friction}, "ode",
                             speed=np.full(inc.shape, speed), incidence=inc, rtol=1e-8)
        out["psi1"], out[model] = o["psi1"], o["psi2"]
        e = float(np.mean(o["restitution"]))
    out["closed_form"] = rigid_psi2(out["psi1"], chi(scene.materials.stiffness_ratio, scene.inertia_factor), e)
    return out


def psi_figure(curves: dict[str, np.ndarray], measured: tuple[np.ndarray, np.ndarray] | None = None,
               title: str = "") -> bytes:
    """PNG: Psi2 against Psi1 for the rigid closed form, the rigid and Mindlin simulations, and measured points."""
    import textwrap

    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    w, h = 5.7, 4.2  # inches
    fig, ax = plt.subplots(figsize=(w, h))
    p1 = curves["psi1"]
    ax.plot(p1, curves["closed_form"], color="#7f7f7f", lw=3, alpha=0.5, label="rigid sphere, closed form")
    ax.plot(p1, curves["rigid"], color="#1b9e77", ls="--", lw=1.5, label="rigid sphere, simulated")
    if "mindlin" in curves:
        ax.plot(p1, curves["mindlin"], color="#7570b3", lw=1.2, ls=":", label="Mindlin, one-state history")
    if "mindlin-deresiewicz" in curves:
        ax.plot(p1, curves["mindlin-deresiewicz"], color="#d95f02", lw=1.8,
                label="Mindlin-Deresiewicz with microslip (MDR)")
    if measured is not None:
        inside = measured[0] <= 1.05 * np.max(p1)
        ax.plot(measured[0][inside], measured[1][inside], "ks", ms=5, label="measured")
    ax.set_xlim(0.0, 1.05 * np.max(p1))
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("Ψ1 (normalized incidence of the contact point)")
    ax.set_ylabel("Ψ2 (normalized rebound of the contact point)")
    default = "Maw-Barber-Fawcett diagram, Coulomb friction at the stated μ"
    title = textwrap.fill(title or default, 60)  # 60 characters: about the axes' width at 10 pt
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)
    # fixed margins in inches (left: tick labels and y label; top: the title's lines), so that it is drawn once
    # (bbox_inches="tight" draws it twice); the report's figures are placed the same way (figures.base.margins)
    lines = title.count("\n") + 1
    fig.subplots_adjust(left=0.72 / w, right=1 - 0.12 / w, bottom=0.5 / h, top=1 - (0.15 + 0.17 * lines) / h)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, pil_kwargs={"compress_level": 3})
    plt.close(fig)
    return buf.getvalue()


def measured_psi(dataset) -> tuple[np.ndarray, np.ndarray] | None:
    """(Psi1, Psi2) of a dataset whose observable is the contact-point rebound angle, else None."""
    if dataset.observable not in ("contact_rebound_angle", "psi2"):
        return None
    s = dataset.scene
    kappa_mu = s.materials.stiffness_ratio / s.friction
    rows = rows_of(dataset)
    vt = rows["speed"] * np.sin(rows["incidence"]) - s.radius * rows["spin"]
    psi1 = kappa_mu * vt / (rows["speed"] * np.cos(rows["incidence"]))
    y = dataset.columns[dataset.observable]
    return psi1, (kappa_mu * np.tan(y) if dataset.observable == "contact_rebound_angle" else y)
