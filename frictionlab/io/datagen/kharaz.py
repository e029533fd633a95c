"""Measured oblique impacts: Kharaz, Gorham and Salman (2001), transcribed from two public digitizations.

Experiment: A. H. Kharaz, D. A. Gorham, A. D. Salman, "An experimental study of the elastic rebound
of spheres", Powder Technology 120 (2001) 281-291, doi:10.1016/S0032-5910(01)00283-2: 5 mm aluminium
oxide spheres at 3.9 m/s on a thick soda-lime glass anvil, impact angle (from the normal) 0-85 deg.
We could not read the paper itself. Its figures are digitized in two public repositories, and the
numbers below are copied from them verbatim (rounded to 5 significant digits here), not re-read:

  LETHE  chaos-polymtl/lethe, examples/dem/3d-oblique-wall-impact/oblique_wall_impact_postprocessing.py
         at commit 255b519263fbb22f758d40763a12290296d53200, arrays theta_omega_exp/omega_exp (rebound
         angular velocity, rad/s), theta_restitution_exp/restitution_exp (tangential restitution of the
         centre of mass v_t2/v_t1) and theta_rebound_exp/theta_out_exp (rebound angle of the centre of
         mass, deg), "Experimental data from A.H. Kharaz, D.A. Gorham, and A.D. Salman ... 2001".
  KRATOS KratosMultiphysics/Kratos, applications/DEMApplication/test_examples/basic_benchmarks/
         paper_data/benchmark4_graph{1,2,3}.dat at commit 650ccb263d910608aa74112ddb4c8fa45ca5ba96,
         block '#Experiment' (Chung and Ooi, Granular Matter 13 (2011) 643-656, Test 4, which replots
         Kharaz et al.'s measurements): graph2 final angular velocity (rad/s, their sign negative),
         graph1 tangential restitution of the centre of mass, graph3 rebound angle of the contact
         point (deg, negative where the contact point reversed).

The paper's stated measurement uncertainty is not quoted in either source. The [noise] of each
dataset is the transcription uncertainty we can measure: the RMS difference between the two
independent digitizations of the same markers (spin: 4.7 rad/s; restitution: 0.0073; incidence read
off the axis: 0.17 deg, used for the contact-point angle that only Kratos digitized). It is a lower
bound on the experimental scatter, and is stated as such in every file; the fits use neither it nor a
guess: [noise] kind = 'estimated' (sigma from the data's own scatter, io/noise.py).

Material data (not from the paper, which we could not read): alumina E = 380 GPa, nu = 0.23,
density 4000 kg/m^3, diameter 5 mm; soda-lime glass E = 70 GPa, nu = 0.25; friction coefficient
0.092; speed 3.9 m/s. Source: chaos-polymtl/lethe doc/source/examples/dem/oblique-wall-impact/
oblique-wall-impact.rst at commit 337c93d42b0ef8b4c9b47b9ec9fd843a63dbc0df ("lagrangian physical
properties", friction "the same used in the MFIX documentation", i.e. MFIX DEM05, which uses
Kharaz et al.'s data). Normal restitution 0.98: the YADE script of Chung and Ooi's Test 4
(en = 0.98 for aluminium oxide at vn_ini = 3.9 m/s, mu = tan(atan(0.092))).

Which anvil and which angle. The 2001 paper's abstract (as reproduced in a
public BibTeX entry of the paper) says: "5-mm aluminium oxide spheres impacting a thick soda-lime glass
anvil, for impact angles from normal to very near glancing incidence", its measurements "show very close
agreement with the numerical work of Maw et al. which takes into account the effects of sticking,
microslip and tangential compliance", and "for impacts with a greater obliqueness than about 30 deg from
the normal" with rigid-body sliding: angles from the normal, glass anvil. Gorham and Kharaz, Powder
Technology 112 (2000) 193-202, measured
the same 5 mm alumina spheres on two anvils: "a thick soda-lime glass anvil (fully elastic response)
and an aluminium alloy anvil (involving some plastic deformation)" (abstract). The 2001 paper studies
the elastic rebound, i.e. the glass anvil, which is what MFIX DEM05 and Lethe model (glass wall, 70 GPa,
0.25). Chung and Ooi's Test 4 (Granular Matter 13 (2011) 643-656), which replots the same
measurements, models a RIGID plane instead, and its "aluminium alloy" (70 GPa, 0.33, 2700 kg/m^3) is
a second SPHERE material simulated beside alumina, not Kharaz's anvil: Kratos' benchmark4_graph1.gp
plots index 0 'Al. oxide' and index 1 'Al. alloy' (simulations) and index 2 'Experiment' (the block we
copy); YADE's Test4.py gives the wall 1000x the sphere's modulus. So the transcriptions do not mix
anvils, and our [scene.materials] (alumina on glass) matches the experiment. The normalized results
depend on the anvil only through kappa = 4 G*/E* (0.859 on glass at nu = 0.25, 0.870 on a rigid plane,
0.875 on glass at nu = 0.22); the Mindlin-Deresiewicz spin at 6.1 deg moves from -13.7 % (glass,
nu = 0.25, as stated) to -15.4 % (rigid plane) and -16.2 % (glass 72 GPa, nu = 0.22): the criterion
there is met with the stated data, by a margin smaller than the uncertainty of the anvil's Poisson ratio.

Consistency of the transcriptions (``implied_spin``): a sphere's tangential impulse J changes both
v_t (m dv_t = -J) and spin (I domega = r J), so omega_2 = (1 - v_t2/v_t1) v_t1 / (f r), f = I/(m r^2),
from the tangential-restitution figure alone. Interpolated in that figure at the spin figure's angles,
it gives 119.1, 251.5, 554.1 rad/s at 6.1, 11.0 and 21.3 deg against 136.2, 265.7, 577.6 plotted in the
spin figure (-12.6, -5.4, -4.1 %): at 6.1 deg the two figures (as digitized) disagree by 13 %, nearly
the 15 % any model is allowed there. The Mindlin-Deresiewicz prediction, 117.5 rad/s, is 1.3 % from the
restitution figure's value.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .write import write_pair

LETHE = ("chaos-polymtl/lethe examples/dem/3d-oblique-wall-impact/oblique_wall_impact_postprocessing.py "
         "@ 255b519263fbb22f758d40763a12290296d53200")
KRATOS = ("KratosMultiphysics/Kratos applications/DEMApplication/test_examples/basic_benchmarks/paper_data/"
          "benchmark4_graph{n}.dat @ 650ccb263d910608aa74112ddb4c8fa45ca5ba96, block '#Experiment'")
MATERIALS_SOURCE = ("chaos-polymtl/lethe doc/source/examples/dem/oblique-wall-impact/oblique-wall-impact.rst "
                    "@ 337c93d42b0ef8b4c9b47b9ec9fd843a63dbc0df (alumina 380 GPa, 0.23, 4000 kg/m^3, 5 mm; glass "
                    "70 GPa, 0.25; friction 0.092 as MFIX DEM05); restitution 0.98 from YADE's Chung-Ooi Test 4 script; anvil "
                    "checked: soda-lime glass, the elastic one of the two anvils of Gorham and Kharaz, Powder Technol. 112 "
                    "(2000) 193-202 (the other, aluminium alloy, deformed plastically); Chung and Ooi's 'Al. alloy' "
                    "(70 GPa, 0.33) is a simulated sphere material on a rigid plane, not this anvil")
PAPER = ("Kharaz, Gorham and Salman, Powder Technology 120 (2001) 281-291, doi:10.1016/S0032-5910(01)00283-2; "
         "5 mm alumina spheres on soda-lime glass at 3.9 m/s")

# --- transcriptions, verbatim from the sources above ---------------------------------------------------
LETHE_SPIN = ([6.143, 10.991, 21.251, 31.157, 39.143, 50.348, 60.328],  # incidence [deg]
              [136.18, 265.69, 577.65, 612.88, 595.49, 453.21, 382.09])  # rebound spin [rad/s]
LETHE_COR = ([1.84, 3.703, 9.496, 20.012, 30.127, 39.382, 49.694, 60.02],
             [0.79344, 0.74533, 0.67257, 0.59691, 0.68756, 0.77148, 0.84761, 0.90142])  # v_t2 / v_t1
LETHE_ANGLE = ([0.016, 2.15, 4.096, 9.826, 20.567, 30.29, 39.535, 49.747, 60.208],
               [0.074, 1.733, 2.962, 6.518, 12.208, 21.67, 32.613, 45.125, 57.474])  # rebound angle [deg]
KRATOS_SPIN = ([5.897435897435898, 10.867850098619328, 21.12426035502959, 31.1439842209073, 38.95463510848126,
                50.23668639053254, 60.098619329388555, 69.96055226824458, 78.56015779092702, 84.31952662721893],
               [-134.86238532110102, -261.16207951070345, -573.7003058103976, -612.2324159021407,
                -595.1070336391438, -449.54128440366975, -375.68807339449546, -242.9663608562692,
                -142.35474006116218, -70.6422018348625])  # graph2 [rad/s], sign of their axes
KRATOS_COR = ([2.237623762376236, 4.217821782178216, 9.841584158415838, 20.21782178217822, 30.356435643564353,
               39.544554455445535, 49.603960396039604, 71.06930693069305, 79.22772277227722, 85.16831683168317],
              [0.7965403624382209, 0.7462932454695224, 0.6754530477759474, 0.598846787479407, 0.6902800658978585,
               0.7742998352553543, 0.8476112026359144, 0.9365733113673806, 0.9695222405271829, 0.9794069192751237])
KRATOS_CONTACT_ANGLE = ([2.0997281572207847, 3.9434155319702846, 9.717622556290827, 20.309682809728216,
                         30.160683905575503, 39.120476602752326, 49.51201496648886, 59.9037955064207,
                         70.46025585915032, 78.85965284042405, 84.78158734387202],
                        [0.7703927492447065, 0.7703927492447065, -1.0574018126888234, -8.53474320241692,
                         -2.5528700906344426, 9.909365558912384, 30.015105740181262, 49.95468277945619,
                         66.90332326283988, 78.86706948640483, 85.6797583081571])  # graph3 [deg]

SPEED = 3.9  # [m/s]
RADIUS = 2.5e-3  # [m]
DENSITY = 4000.0  # [kg/m^3]
MASS = DENSITY * 4.0 / 3.0 * math.pi * RADIUS**3  # [kg]
MATERIALS = {"ball_young": "380 GPa", "ball_poisson": 0.23, "surface_young": "70 GPa", "surface_poisson": 0.25,
             "friction": 0.092}
RESTITUTION = 0.98


def transcription_noise() -> dict[str, float]:
    """RMS differences between the Lethe and Kratos digitizations of the same markers (SI)."""
    la, lw = map(np.asarray, LETHE_SPIN)
    ka, kw = np.asarray(KRATOS_SPIN[0]), -np.asarray(KRATOS_SPIN[1])
    spin = float(np.sqrt(np.mean((lw - np.interp(la, ka, kw)) ** 2)))
    angle = float(np.sqrt(np.mean((la - ka[: la.size]) ** 2)))  # the same 7 markers, read on the x axis
    ca, ce = map(np.asarray, LETHE_COR)
    inside = ca >= KRATOS_COR[0][0]
    cor = float(np.sqrt(np.mean((ce[inside] - np.interp(ca[inside], *KRATOS_COR)) ** 2)))
    return {"rebound_spin": spin, "cm_tangential_cor": cor, "angle": math.radians(angle)}


def implied_spin() -> tuple[np.ndarray, np.ndarray]:
    """(incidence [deg], spin [rad/s]) implied by the tangential-restitution transcription at the spin
    transcription's angles: omega_2 = (1 - e_t) V sin(theta) / (0.4 r), e_t interpolated linearly."""
    from ...solve.rebound import spin_from_restitution

    inc = np.asarray(LETHE_SPIN[0])
    return inc, spin_from_restitution(inc, *LETHE_COR, SPEED, RADIUS, 0.4)


def hertz_pulse(speed: float = SPEED) -> tuple[float, float]:
    """(contact time [s], peak contact area [m^2]) of the elastic Hertz impact at normal ``speed``."""
    from ...physics.contact import Material, Pair
    from ...solve.outcome import hertz_shape

    E = Pair(Material(380e9, 0.23), Material(70e9, 0.25)).modulus
    K = 4.0 / 3.0 * E * math.sqrt(RADIUS)
    delta = (5.0 * MASS * speed**2 / (4.0 * K)) ** 0.4
    return hertz_shape()[0] * delta / speed, math.pi * RADIUS * delta


def scene() -> dict:
    """The [scene] table: alumina ball on glass, rigid-body tangential contact, and a half-sine normal
    force and area with the Hertz contact time and peak area of the stated materials (at 3.9 m/s,
    scaled with Hertz's exponents -1/5 and 4/5): for Coulomb friction the rigid outcome depends on the
    normal impulse only, so this equals the Hertz pulse and lets the exact solver fit it fast."""
    tc, area = hertz_pulse()
    return {
        "mass": f"{MASS * 1e3:.6g} g", "radius": f"{RADIUS * 1e3:g} mm", "inertia_factor": 0.4,
        "effects": ["spin", "slip-coupling"], "angle_reference": "normal",
        "normal": {"model": "half-sine", "contact_time": f"{tc * 1e6:.5g} us", "restitution": RESTITUTION,
                   "reference_speed": f"{SPEED:g} m/s", "contact_time_exponent": -0.2},
        "area": {"model": "half-sine", "peak": f"{area * 1e6:.5g} mm^2", "peak_exponent": 0.8},
        "materials": dict(MATERIALS),
    }


DATASETS = {
    # name: (observable, unit, (incidence, values), source, what, noise key)
    "kharaz2001-spin": ("rebound_spin", "rad/s", LETHE_SPIN, LETHE + ", arrays theta_omega_exp, omega_exp",
                        "rebound spin (angular velocity after impact)", "rebound_spin"),
    "kharaz2001-tangential-cor": ("cm_tangential_cor", "", LETHE_COR,
                                  LETHE + ", arrays theta_restitution_exp, restitution_exp",
                                  "tangential restitution of the centre of mass, v_t2 / v_t1", "cm_tangential_cor"),
    "kharaz2001-contact-angle": ("contact_rebound_angle", "deg", KRATOS_CONTACT_ANGLE, KRATOS.format(n=3),
                                 "rebound angle of the contact point from the normal (negative: the contact "
                                 "point reversed)", "angle"),
}


def build(out_dir: Path) -> list[Path]:
    noise = transcription_noise()
    written = []
    for name, (obs, unit, (inc, val), source, what, nkey) in DATASETS.items():
        sigma = noise[nkey]
        shown = {"rebound_spin": f"{sigma:.2g} rad/s", "cm_tangential_cor": f"{sigma:.2g}",
                 "angle": f"{math.degrees(sigma):.2g} deg"}[nkey]
        meta = {
            "name": name,
            "group": "kharaz2001",  # one material and setup, three observables
            "kind": "impact-outcome",
            "observable": obs,
            "description": (f"MEASURED: {what} of 5 mm aluminium oxide spheres striking a soda-lime glass anvil at "
                            f"3.9 m/s, against the impact angle from the normal (Kharaz, Gorham and Salman 2001), "
                            "transcribed from a public digitization of the paper's figure. Noise is the "
                            "transcription uncertainty only (the paper's stated uncertainty is not quoted in "
                            "the sources): a lower bound on the experimental scatter, so the fits estimate sigma from the "
                            "data's own scatter instead."),
            "columns": {"speed": "m/s", "incidence": "deg", obs: unit},
            "noise": {"kind": "estimated", obs: shown},
            "scene": scene(),
            "provenance": {
                "kind": "measured",
                "source": f"{PAPER}; values transcribed from {source}",
                "method": ("numbers copied verbatim from the digitization named in source (5 significant digits); "
                           f"noise {shown} = RMS difference between the Lethe and Kratos digitizations of the same "
                           f"figure markers; material data: {MATERIALS_SOURCE}. See frictionlab/io/datagen/kharaz.py."),
                "command": "frictionlab datasets rebuild",
            },
            "reported": {"stated_friction": 0.092, "impact_speed": "3.9 m/s", "density": "4000 kg/m^3",
                         "stated_uncertainty": "not quoted in the sources we could read"},
        }
        cols = {"speed": np.full(len(inc), SPEED), "incidence": np.asarray(inc), obs: np.asarray(val)}
        if obs == "rebound_spin":
            a, w = implied_spin()
            low = a < 30
            meta["provenance"]["method"] += (
                " Consistency: the tangential-restitution figure implies " +
                ", ".join(f"{x:.1f}" for x in w[low]) + " rad/s at " + ", ".join(f"{x:.1f}" for x in a[low]) +
                " deg (omega = (1 - e_t) v_t / (0.4 r)), against " +
                ", ".join(f"{x:.1f}" for x in np.asarray(val)[low]) + " rad/s here (kharaz.implied_spin).")
        written += write_pair(out_dir, name, meta, cols, 5, __name__)
    return written
