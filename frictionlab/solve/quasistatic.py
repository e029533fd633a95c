"""The quasi-static rate-and-state spring-slider in the field's own variables: the fast path of ``simulate``
and of the velocity-step fit (``inference.velstep.fit``).

For the built-in one-state rate-and-state laws (aging, slip, PRZ, Nagata) on a spring-slider without mass, the
general plan (``solve.plan``) differentiates the force numerically at every right-hand-side call. Here the slider is
written as the rate-and-state literature writes it (Marone 1998; rsfmodel): m = mu - mu_ss(V1) and
psi = ln(V1 theta / Dc) (PRZ: ln(V1 theta / (2 Dc))), in um and s, with V0 = V1 (the first load-point velocity)
and steady state there at t = 0, integrated by a compiled implicit method with its analytic Jacobian through every step and hold of the
load point (``quasistatic_kernel``), optionally with the forward sensitivities of m to (a, b, Dc, k) (and to
Nagata's c).

The friction is the log form mu = mu0 + a ln(V/V0) + b ln(V0 theta/Dc) (V0 = 1 um/s, the law's mu0), equal to
the laws' regularized form a asinh(V/(2 V0) exp(psi/a)) to relative exp(-2 mu/a) (1e-50 at laboratory
values): the tests hold the two paths together.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from ..core.errors import SolverError
from ..physics.spring import runaway_message

#: Built-in laws served here, by name: the kernel's evolution-law code (``quasistatic_kernel.AGING``, ``SLIP``,
#: ``PRZ``, ``NAGATA``; the kernel, which imports numba, is loaded on the first solve).
LAWS = {"rate-state-aging": 0, "rate-state-slip": 1, "rate-state-prz": 2, "rate-state-nagata": 3}
LAW_NAMES = {code: name for name, code in LAWS.items()}
#: The laws the velocity-step fit serves (``inference.velstep.fit``): the kernel's sensitivities cover all their
#: parameters, (mu0, a, b, Dc) and Nagata's c.
FITTED = frozenset({"rate-state-aging", "rate-state-slip", "rate-state-prz", "rate-state-nagata"})
#: Law parameters beyond (mu0, a, b, Dc) with a sensitivity column, by law code (after a, b, Dc, k).
EXTRA = {LAWS["rate-state-nagata"]: ("c",)}
#: Reference slip rate V0 of the laws' mu0 [um/s] (frictionlab/laws/rate_state.py: 1e-6 m/s).
V0_UM = 1.0
#: A quasi-static slider has run away once its slip rate exceeds this multiple of the fastest load point
#: (``solve.plan.QUASI_STATIC_LIMIT``; the same limit on both paths).
RUNAWAY = 1e3
UM = 1e-6  # m per um


def applies(law, scene) -> str:
    """'' if the fast path integrates ``law`` on ``scene``, else why not (one phrase)."""
    from ..physics.normal import ConstantNormal

    if law.name not in LAWS or not type(law).__module__.startswith("frictionlab.laws."):
        return f"law '{law.name}' is not a built-in rate-and-state law"
    if getattr(scene, "kind", None) != "spring-slider" or scene.spring is None:
        return "not a spring-slider"
    if scene.spring.inertial:
        return "the slider has a mass"
    if not scene.spring.velocities[0] > 0:
        return "the load point starts at rest (no steady state to start from)"
    if not isinstance(scene.normal, ConstantNormal):
        return "the normal force is not constant"
    return ""


@attrs.frozen(eq=False)
class Load:
    """A load-point history in laboratory units: segment start times [s] (from 0) and velocities [um/s]."""

    times: np.ndarray
    velocities: np.ndarray
    vmax: float = attrs.field(init=False)  # the fastest load-point velocity [um/s]

    def __attrs_post_init__(self):
        object.__setattr__(self, "vmax", float(np.max(self.velocities)))

    @classmethod
    def of(cls, spring) -> "Load":
        return cls(np.asarray(spring.times, dtype=float), np.asarray(spring.velocities, dtype=float) / UM)

    @property
    def V1(self) -> float:
        return float(self.velocities[0])

    def displacement(self, t) -> np.ndarray:
        """Load-point displacement [um] at times t [s] from the schedule, 0 at t = 0."""
        edges = np.append(self.times, np.inf)
        x_at = np.concatenate([[0.0], np.cumsum(np.diff(self.times) * self.velocities[:-1])])
        t = np.asarray(t, dtype=float)
        i = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, len(self.times) - 1)
        return x_at[i] + self.velocities[i] * (t - self.times[i])


@attrs.frozen
class Solution:
    """m = mu - mu_ss(V1) [-] and psi = ln(V1 theta/Dc) [-] at the requested times; ``S``: dm/d(a, b, Dc, k) with
    Dc in um and k in 1/um, then dm/d of the law's ``EXTRA`` parameters (None unless asked); ``steps``: accepted
    steps."""

    m: np.ndarray
    psi: np.ndarray
    S: np.ndarray | None
    steps: int


def solve(law_code: int, a: float, b: float, Dc_um: float, k_um: float, load: Load, t, rtol: float = 1e-8,
          sensitivities: bool = False, law: str = "", c: float = 0.0) -> Solution:
    """Integrate the quasi-static slider (laboratory units: Dc [um], k [1/um]; c: Nagata's constant) from steady
    sliding at V1 and return m and psi at the sorted times t [s] >= 0. A slider that runs away or a failed
    integration raises SolverError."""
    from . import quasistatic_kernel as kernel

    t = np.ascontiguousarray(t, dtype=float)
    n = t.size
    m, psi = np.empty(n), np.empty(n)
    S = np.empty((n, 4 + len(EXTRA.get(law_code, ())))) if sensitivities else np.empty((0, 4))
    stats = np.zeros(5)
    vmax = RUNAWAY * load.vmax
    status = kernel.integrate(law_code, float(a), float(b), float(Dc_um), float(k_um), float(c), load.V1, load.times,
                              load.velocities, t, float(rtol), float(rtol) * float(a), bool(sensitivities), vmax,
                              m, psi, S, stats)
    if status != kernel.OK:
        raise SolverError(_failure(status, stats, (law_code, a, b, Dc_um, k_um, float(c)), load, law or LAW_NAMES[law_code]))
    return Solution(m, psi, S if sensitivities else None, int(stats[0]))


def _failure(status: int, stats, slider: tuple, load: Load, law: str) -> str:
    """The message of a failed integration; ``slider``: (law code, a, b, Dc [um], k [1/um], c) as integrated."""
    from . import quasistatic_kernel as kernel

    _, a, b, Dc_um, k_um, _ = slider

    t = float(stats[3])
    if status == kernel.TOO_MANY_STEPS:
        return f"quasi-static slider: more than {kernel.MAX_STEPS} steps by t = {t:.6g} s"
    j = int(np.searchsorted(load.times, t, side="right")) - 1
    before = load.velocities[j - 1] if j >= 1 else load.V1
    stepped = j >= 1 and load.velocities[j] > before > 0  # a re-slide from a hold has no step ratio to search
    if status == kernel.RUNAWAY:
        largest = _largest_step(slider, load, j, t) if stepped else None
        return runaway_message(law, float(stats[4]) * UM, t, load.velocities * UM, {"a": a, "b": b, "Dc": Dc_um * UM},
                               k_um / UM, RUNAWAY, load.times, None if largest is None else largest * UM)
    where = f"(a, b, Dc, k = {a:g}, {b:g}, {Dc_um:g} um, {k_um:g} 1/um)"
    if not stepped:
        return f"quasi-static slider: the step size fell to round-off at t = {t:.6g} s, at the load-point velocity " \
               f"{load.velocities[j]:.3g} um/s {where}"
    works = _largest_step(slider, load, j, t)
    return (f"quasi-static slider: the load point's step at t = {load.times[j]:g} s from {before:.3g} to "
            f"{load.velocities[j]:.3g} um/s (a factor {load.velocities[j] / before:.3g}) is beyond what the slider "
            f"can be integrated through (its step size fell to round-off at t = {t:.6g} s) {where}; "
            + (f"from {before:.3g} um/s, steps up to about {works:.2g} um/s integrate here: " if works else "")
            + "use a smaller step, or several smaller ones")


def _largest_step(slider: tuple, load: Load, j: int, t_fail: float, tries: int = 10) -> float | None:
    """The largest velocity [um/s] (to about 1.2 times, in log steps) that segment ``j`` of ``load`` may step to
    from the velocity before it and integrate through to a little past ``t_fail`` [s]; None if even a small step
    does not. Only on the way to an error: a few short integrations."""
    from . import quasistatic_kernel as kernel

    code, a, b, Dc_um, k_um, c = slider
    before = load.velocities[j - 1]
    t0 = float(load.times[j])

    def integrates(v: float) -> bool:
        vel = load.velocities[:j + 1].copy()
        vel[j] = v
        end = t0 + max(2.0 * (t_fail - t0), 50.0 * a / (k_um * v))  # past the slider's response to the step
        trial = Load(load.times[:j + 1].copy(), vel)
        status = kernel.integrate(code, float(a), float(b), float(Dc_um), float(k_um), c, trial.V1, trial.times,
                                  trial.velocities, np.array([end]), 1e-8, 1e-8 * float(a), False,
                                  RUNAWAY * trial.vmax, np.empty(1), np.empty(1), np.empty((0, 4)), np.zeros(5))
        return status == kernel.OK

    lo, hi = math.log(before), math.log(load.velocities[j])
    if not integrates(math.exp(lo + 0.01 * (hi - lo))):
        return None
    lo += 0.01 * (hi - lo)
    for _ in range(tries):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if integrates(math.exp(mid)) else (lo, mid)
    return math.exp(lo)


def steady_friction(p, V1_um: float) -> float:
    """mu_ss at V1 [um/s] of the law parameters p (SI; mu0 at V0 = 1 um/s)."""
    return p["mu0"] + (p["a"] - p["b"]) * math.log(V1_um / V0_UM)


def simulate(law, scene, p, t, rtol: float = 1e-10):
    """A Trajectory of ``law`` (built-in rate-and-state) on the quasi-static spring-slider ``scene`` at times t,
    law parameters p in SI (the same columns as the general path: v = u the slip rate, force = mu N, load = mu,
    the state theta [s])."""
    from ..physics.trajectory import Trajectory

    t = np.asarray(t, dtype=float)
    load = Load.of(scene.spring)
    k_um = scene.spring.stiffness * UM
    sol = solve(LAWS[law.name], p["a"], p["b"], p["Dc"] / UM, k_um, load, t, rtol, law=law.name, c=p.get("c", 0.0))
    V = load.V1 * np.exp((sol.m - p["b"] * sol.psi) / p["a"]) * UM
    mu = steady_friction(p, load.V1) + sol.m
    N = scene.normal(t)
    theta = law.STEADY * p["Dc"] / (load.V1 * UM) * np.exp(sol.psi)
    for name, arr in (("slip rate", V), ("friction", mu), ("state", theta)):
        if not np.isfinite(arr).all():
            raise SolverError(f"quasi-static slider: the {name} became NaN or infinite for law '{law.name}' with {dict(p)}")
    return Trajectory(t=t, u=V, v=V.copy(), omega=np.zeros(t.size), theta=np.zeros(t.size), force=mu * N, N=N,
                      load=mu, solver="ode", law=law.name, info={"method": "SDIRK4", "rtol": rtol, "steps": sol.steps},
                      law_states={"theta": theta})


def compile_kernel() -> None:
    """Compile the slider's kernel here, or load it from numba's cache, with the one type signature ``solve``
    calls it with (a tiny history solved with sensitivities): a pool forked after this inherits it compiled,
    instead of each worker compiling it again."""
    load = Load(np.array([0.0, 1.0]), np.array([1.0, 10.0]))
    solve(LAWS["rate-state-nagata"], 0.01, 0.012, 10.0, 0.01, load, np.array([0.5, 1.5, 2.0]), sensitivities=True,
          c=1.0)
