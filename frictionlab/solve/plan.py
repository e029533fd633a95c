"""The plan: the state vector and right-hand side a scene and a law actually need, and nothing else.

State components (each only when called for):
  v      body tangential velocity [m/s]                 always
  omega  spin [rad/s], theta rotation angle [rad]       effect 'spin' or 'slip-coupling'
  x      sliding length [m]                             area model 'growth' and the law uses A or dA/dt
  xi     tangential spring deflection [m]               effect 'compliance' (for 'mindlin' the
         elastic deflection S / k_t(t) of the spring force S; frictionlab.physics.contact)
  law:NAME  each internal state of a law with memory     the law declares ``states`` (law.py)

Slip u is v, or v - r omega with 'slip-coupling'; with 'compliance' it is the slip of a
massless contact patch, found from  F(u) = k xi + c (w - u),  w the rigid contact-point velocity;
the body feels the spring and damper force k xi + c (w - u), which while the patch sticks (u = 0) is
static friction up to the law's capacity. For the laws' closed-form families the patch slip is
solved by hand, otherwise by root finding. k and c are constants for model 'linear' and follow
the contact radius for 'mindlin' (``Plan.spring``).

A spring-slider (kind 'spring-slider') with a mass ([scene.spring] mass > 0) integrates
  load   the spring's force per unit normal force [-], d load/dt = k (V_lp(t) - v)
and m dv/dt = N load - F(v, s), so stick-slip can be followed. Without a mass (the default) it is
quasi-static, as in the rate-and-state literature and
rsfmodel: the block's inertia is neglected, so the spring's load per unit normal force always
equals the friction coefficient, mu = F(v, s)/N, and d mu/dt = k (V_lp(t) - v) fixes the slip rate:
    dv/dt = (k N (V_lp - v) - sum_i dF/ds_i ds_i/dt) / (dF/dv),
the partial derivatives of the law's force by central differences. This needs dF/dv > 0 at fixed
state (a direct effect: rate-and-state's a > 0, a viscous term); for a law without one (Coulomb,
Dahl) the quasi-static block has no defined slip rate and the plan says so.

``Plan.derivatives(p, t, y, direction)`` is the one right-hand side dy/dt of every integrator
(solvers.ode and the batch engine): callers never assemble slip, force and rates themselves.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from ..core.errors import SceneError, SolverError
from ..physics.law import (
    QUANTITIES,
    Contact,
    FrictionLaw,
    NormalAreaRateForm,
)
from ..physics.scene import (
    ConstantNormal,
    G,
    GrowthArea,
    HertzNormal,
    Scene,
    WeightNormal,
)
from ..physics.spring import runaway_message
from .patch import CompliantPatch

#: A quasi-static spring-slider stops with an error once the slip rate exceeds this multiple of the fastest
#: load-point velocity (a runaway, where inertia would matter: give the slider a mass to follow it).
QUASI_STATIC_LIMIT = 1e3

#: The smallest share of a spring-slider's motion its inertia may make, m k N / (dF/du)^2 at the start: below it the
#: slider's velocity relaxes over a time that much shorter than its spring loads it, a stiffness the ODE solvers
#: cannot follow (BDF and Radau integrate 1e-12 at rtol 1e-3 to 1e-10, and fail near 1e-16; LSODA fails from
#: 1e-7 to 1e-10 depending on rtol), and the motion is the quasi-static slider's to that precision.
INERTIA_FLOOR = 1e-12
#: Below this share LSODA (the default ODE method) may fail on a slider with mass; BDF and Radau do not.
LSODA_FLOOR = 1e-7

#: Prefix of a law's internal states in the plan's state vector ("law:theta" cannot clash with the spin angle).
LAW_PREFIX = "law:"


@attrs.frozen(eq=False)
class Plan(CompliantPatch):
    scene: Scene
    law: FrictionLaw
    states: tuple[str, ...]
    coupled: bool
    needs_area: bool
    needs_normal: bool
    #: Tangential acceleration of the body from gravity along the incline [m/s^2] (an array for a batch view);
    #: computed once here, since every right-hand-side evaluation reads it.
    drive: float = attrs.field(init=False)

    def __attrs_post_init__(self):
        s = self.scene
        object.__setattr__(self, "drive", G * np.sin(s.incline) if "gravity" in s.effects else 0.0)

    # -- constants ----------------------------------------------------------------

    @property
    def kappa(self) -> float:
        """d(slip)/dt per unit friction force [1/kg]: 1/m, plus r^2/I with slip coupling."""
        s = self.scene
        return 1.0 / s.mass + (s.radius**2 / s.inertia if self.coupled else 0.0)

    @property
    def has_spin(self) -> bool:
        return "omega" in self.states

    @property
    def continuous(self) -> bool:
        """Integrated in one phase through zero slip, without stick events: a law with memory (its state
        carries static friction) unless it jumps at zero slip, or a spring-slider (its drive, the
        spring, changes with the state)."""
        return (bool(self.law_states) and not self.law.jumps_at_zero_slip) or self.scene.spring is not None

    @property
    def breaks(self) -> tuple[float, ...]:
        """Times [s] at which the right-hand side jumps (load-point velocity steps)."""
        return self.scene.spring.breaks if self.scene.spring is not None else ()

    @property
    def law_states(self) -> tuple[str, ...]:
        """The plan's names of the law's internal states ("law:z", ...); () for a memoryless law."""
        return tuple(LAW_PREFIX + n for n in self.law.state_names)

    def index(self, name: str) -> int:
        return self.states.index(name)

    def initial_state(self, p=None) -> np.ndarray:
        """The state vector at t = 0; a law with memory needs its parameters ``p`` (SI) for its initial states."""
        s = self.scene
        values = {"v": s.u0 + (s.radius * s.omega0 if self.coupled else 0.0), "omega": s.omega0, "theta": 0.0,
                  "x": 0.0, "xi": 0.0}
        values.update({k: 0.0 for k in self.law_states}, load=0.0)
        y0 = np.array(np.broadcast_arrays(*[values[k] for k in self.states]), dtype=float)
        if self.law_states:
            if p is None:
                raise SceneError(f"law '{self.law.name}' on {self.scene.kind}: the initial state needs the parameters")
            y = y0.reshape(len(self.states), -1)
            u = np.broadcast_to(self.rigid_slip(y), y.shape[1:])
            c = attrs.evolve(self.contact(np.zeros(u.shape), y, u), state=None)
            init = self.law.initial_states(p, c)
            for name in self.law.state_names:
                y[self.index(LAW_PREFIX + name)] = init[name]
            y0 = y.reshape(y0.shape)
        if "load" in self.states:  # the spring starts at the friction of the initial state: no jolt at t = 0
            y0[self.index("load")] = float(self.force(p, np.zeros(1), y0[:, None], y0[:1])[0][0] / s.normal(0.0))
            self._check_inertia(p, y0)
        return y0

    def _inertia(self, p, t, y) -> tuple[float, float, float] | None:
        """(m k N / (dF/du)^2, dF/du [N s/m], k N [N/m]) of a slider with mass at state y, or None where the
        friction has no damping there."""
        sp = self.scene.spring
        c = float(self._partials(p, t, y)[0])  # the friction's damping dF/du
        K = sp.stiffness * float(self.scene.normal(t))  # the spring
        if not (c > 0 and K > 0 and math.isfinite(c)):
            return None
        return sp.mass * K / c**2, c, K

    def stiffness_note(self, p, t, y) -> str:
        """What in the scene makes an integration from state y at time t stiff, for its error ("" if nothing
        known): a slider whose inertia is below LSODA_FLOOR of its motion."""
        known = self._inertia(p, t, y) if "load" in self.states else None
        if known is None or known[0] >= LSODA_FLOOR:
            return ""
        return (f"[scene.spring] mass = {self.scene.spring.mass:.3g} kg makes the slider's inertia {known[0]:.1g} of "
                f"its motion, a stiff problem LSODA fails on from about {LSODA_FLOOR:g}: ode:BDF or ode:Radau integrate "
                f"it down to {INERTIA_FLOOR:g}, or leave the mass out (the quasi-static slider)")

    def _check_inertia(self, p, y0) -> None:
        """Refuse a slider with mass so light that its inertia is below INERTIA_FLOOR of its motion, naming the
        mass and the masses that work."""
        sp = self.scene.spring
        known = self._inertia(p, 0.0, y0)
        if known is None:
            return
        share, c, K = known
        if share < INERTIA_FLOOR:
            raise SceneError(f"[scene.spring] mass = {sp.mass:.3g} kg: the slider's inertia is {share:.1g} of its motion "
                             f"(m k N / (dF/du)^2 at the start, with dF/du = {c:.3g} N s/m at u = {float(y0[0]):.3g} "
                             f"m/s), below the {INERTIA_FLOOR:g} the ODE solvers can integrate; leave the mass out "
                             f"(the quasi-static slider, which this one is to that precision) or give at least "
                             f"{INERTIA_FLOOR * c**2 / K:.2g} kg")

    # -- contact quantities ----------------------------------------------------------
    def rigid_slip(self, y: np.ndarray) -> np.ndarray:
        """Velocity of the body's contact point relative to the surface [m/s]."""
        v = y[0]
        return v - self.scene.radius * y[self.index("omega")] if self.coupled else v

    def area(self, t, y, u) -> tuple[np.ndarray, np.ndarray]:
        """Contact area [m^2] and its rate [m^2/s] at times t for states y and slip u."""
        x = y[self.index("x")] if "x" in self.states else None
        return self.scene.area(t, x, u)

    def contact(self, t, y, u, normal=None) -> Contact:
        """The contact quantities the law requires, and only those, at times t for states y (normal: the
        normal force, when the caller has it)."""
        s = self.scene
        A = dAdt = N = None
        req = self.law.requires
        if self.needs_area:
            if "dAdt" in req or not hasattr(s.area, "value"):
                A, dAdt = self.area(t, y, u)
            else:  # the area alone, where the model offers it (half the cost of a half-sine's area and rate)
                A = s.area.value(t)
        if self.needs_normal:
            N = s.normal(t, A) if normal is None else normal
        state = ({n: y[self.index(k)] for n, k in zip(self.law.state_names, self.law_states)} or None
                 if self.law.states else None)
        dmudt = s.spring.stiffness * (s.spring.velocity(t) - y[0]) if "dmudt" in req else None
        return Contact(t=np.asarray(t, dtype=float), u=np.asarray(u, dtype=float),
                       N=N if "N" in req else None, A=A if "A" in req else None, dAdt=dAdt if "dAdt" in req else None,
                       state=state, dmudt=dmudt)

    def force(self, p, t, y, u) -> tuple[np.ndarray, Contact]:
        c = self.contact(t, y, u)
        return self.law.evaluate(p, c), c

    def derivatives(self, p, t, y, direction=0.0) -> np.ndarray:
        """dy/dt at time t [s] for state y and law parameters p (SI): THE right-hand side of every integrator.

        ``direction`` is the slip direction of the sliding phase (+1, -1; arrays for a batch), or 0
        for none: a stage that overshoots zero slip then sees vanishing slip on the phase's side
        (``stick.branch_slip``). Works on batches (y of shape (n_states, ...)).
        """
        if (not self.law.states and np.ndim(y) == 1 and np.ndim(direction) == 0 and "xi" not in self.states
                and self.scene.spring is None):
            return self._one_state(p, t, y, float(direction))
        if "xi" in self.states:
            F, u = self.patch_force(p, t, y)
            c = self.contact(np.asarray(t), y, np.asarray(u)) if self.law_states else None
        else:
            u = self.rigid_slip(y)
            if direction.any() if isinstance(direction, np.ndarray) else direction != 0:
                from .solvers.stick import branch_slip

                u = branch_slip(self, u, direction)
            F, c = self.force(p, np.asarray(t), y, np.asarray(u))
        dy = self._rates(p, t, y, F, u, c)
        if self.scene.spring is not None and not self.scene.spring.inertial:
            dy[0] = self._quasi_static_acceleration(p, t, y, dy)
        return dy

    def bound(self, p, direction: float = 0.0):
        """``derivatives`` bound to law parameters p and a scalar direction, as f(t, y) for one state vector y
        (a scalar integrator's right-hand side): the dispatch to ``_one_state`` decided once, not per call."""
        direction = float(direction)
        if not self.law.states and "xi" not in self.states and self.scene.spring is None:
            from .fastrhs import scalar_rhs
            from .solvers.stick import vanishing_slip

            tiny = float(vanishing_slip(self)) if direction != 0.0 else 0.0
            fast = scalar_rhs(self, p, direction, tiny)  # a built-in closed-form family on known models: floats
            if fast is not None:
                return fast
            normal = self._fixed_normal()
            return lambda t, y: self._one_state(p, t, y, direction, normal)
        return lambda t, y: self.derivatives(p, t, y, direction)

    def _fixed_normal(self):
        """The normal force [N] of one state vector, built once, when the scene's does not change in time (an
        incline's weight, a constant load): what the model gives at a scalar time, read-only; None otherwise."""
        if not self.needs_normal or type(self.scene.normal) not in (ConstantNormal, WeightNormal):
            return None
        N = self.scene.normal(0.0)
        N.flags.writeable = False
        return N

    def _quasi_static_acceleration(self, p, t, y, dy) -> float:
        """dv/dt of a quasi-static spring-slider: d F(v, s)/dt = k N (V_lp - v), partials by central differences."""
        s = self.scene
        v = float(y[0])
        fastest = QUASI_STATIC_LIMIT * max(s.spring.velocities)
        if abs(v) > fastest:
            raise SolverError(runaway_message(self.law.name, v, float(t), s.spring.velocities, p, s.spring.stiffness,
                                              QUASI_STATIC_LIMIT, s.spring.times))
        dF = self.slip_rate_partials(p, t, y)
        N = float(s.normal(t))
        return (s.spring.stiffness * N * (float(s.spring.velocity(t)) - v) - float(dF[1:] @ dy[1:])) / dF[0]

    def slip_rate_partials(self, p, t, y) -> np.ndarray:
        """Partials of the friction force [N] of a spring-slider's one state vector y by its slip rate
        (first, N s/m) and by each law state, by central differences; error if dF/du is not positive
        (the quasi-static block then has no slip rate for the spring's load)."""
        dF = self._partials(p, t, y)
        if not dF[0] > 0:
            s = self.scene
            raise SceneError(f"law '{self.law.name}' on a spring-slider: its force does not grow with the slip rate "
                             f"at fixed state (dF/du = {dF[0]:.3g} N s/m at u = {float(y[0]):.3g} m/s, t = "
                             f"{float(t):.6g} s, load-point velocity {float(s.spring.velocity(t)):.3g} m/s), so the "
                             "quasi-static block has no slip rate for the spring's load")
        return dF

    def _partials(self, p, t, y) -> np.ndarray:
        """``slip_rate_partials`` without its check."""
        rows = [0] + [self.index(k) for k in self.law_states]  # the slip rate and the law's states
        n = len(rows)
        v = float(y[0])
        steps = [1e-5 * abs(v) + 1e-30] + [1e-5 * (abs(float(y[i])) + 1e-3 * spec.scale)
                                           for i, spec in zip(rows[1:], self.law.states)]
        Y = np.repeat(np.asarray(y, dtype=float)[:, None], 2 * n, axis=1)
        for j, (i, h) in enumerate(zip(rows, steps)):
            Y[i, 2 * j] += h
            Y[i, 2 * j + 1] -= h
        F, _ = self.force(p, np.full(2 * n, t), Y, Y[0])
        return (F[0::2] - F[1::2]) / (2.0 * np.array(steps))

    def _one_state(self, p, t, y, direction: float, normal=None) -> np.ndarray:
        """``derivatives`` for one state vector of a memoryless law without compliance (every scalar ODE
        solve): the same arithmetic on Python floats, bitwise equal to the general path (tests check it),
        without its array bookkeeping. The law's force is checked by ``FrictionLaw.evaluate`` (the
        one-line error) only when it is not a finite number of the right shape."""
        s = self.scene
        v = float(y[0])
        u = v - s.radius * float(y[self.index("omega")]) if self.coupled else v
        if direction != 0.0 and not direction * u > 0:
            from .solvers.stick import vanishing_slip

            u = direction * float(vanishing_slip(self))
        c = self.contact(t, y, u, normal)
        try:
            f = self.law.force(p, c)
            F = float(f) if np.ndim(f) == 0 else math.nan
        except Exception:
            F = math.nan
        if not math.isfinite(F):
            F = float(self.law.evaluate(p, c))  # raises the law's one-line error, or F was right after all
        rate = {"v": self.drive - F / s.mass, "x": abs(u)}
        if self.has_spin:
            rate["omega"] = F * s.radius / s.inertia
            rate["theta"] = float(y[self.index("omega")])
        return np.array([rate[k] for k in self.states])

    def _rates(self, p, t, y, F, u, c) -> np.ndarray:
        """Time derivatives of the state for friction force F and slip u (works on batches): one output
        array, each rate written into its row (the same arithmetic as term by term)."""
        s = self.scene
        law_rates = self.law.evaluate_rates(p, c) if self.law.states else {}
        shape = np.shape(F)
        if shape != np.shape(y)[1:]:
            shape = np.broadcast_shapes(shape, np.shape(y)[1:])
        out = np.empty((len(self.states),) + shape)
        for i, name in enumerate(self.states):
            if name == "v" and "load" in self.states:  # a slider with mass: m dv/dt = N load - F
                out[i] = (s.normal(t) * y[self.index("load")] - F) / s.spring.mass
            elif name == "v":
                np.subtract(self.drive, F / s.mass, out=out[i, ...])
            elif name == "load":
                out[i] = s.spring.stiffness * (s.spring.velocity(t) - y[0])
            elif name == "omega":
                np.multiply(F, s.radius, out=out[i, ...])
                out[i] /= s.inertia
            elif name == "theta":
                out[i] = y[self.index("omega")]
            elif name == "x":
                np.abs(u, out=out[i, ...])
            elif name == "xi":
                loading = self.spring(t, y)[2] if s.compliance.model != "linear" else 0.0
                out[i] = self.rigid_slip(y) - u - loading * y[self.index("xi")]
            else:
                out[i] = law_rates[name[len(LAW_PREFIX):]]
        return out


def make_plan(scene: Scene, law: FrictionLaw, scene_name: str = "scene") -> Plan:
    """The plan of a simulation: which contact quantities ``scene`` supplies for ``law``, and how.

    Parameters
    ----------
    scene : Scene
        The experiment (mass, slip, contact-area and normal-force models), SI.
    law : FrictionLaw
        The law to be solved on it.
    scene_name : str, default "scene"
        The name errors give the scene (a dataset's name).

    Returns
    -------
    Plan
        What `simulate` and the fits evaluate the law with.

    Raises
    ------
    PlanError
        The scene cannot supply a quantity the law requires (the message says which model to add).

    Examples
    --------
    >>> import frictionlab as fl
    >>> scene = fl.load_dataset("impact-golf-v28").scene
    >>> plan = fl.make_plan(scene, fl.get_law("wear"))
    """
    missing = set(law.requires) - scene.supplies()
    if missing:
        hint = {"N": "add a [scene.normal] model (half-sine, hertz, column or weight)",
                "A": "add a [scene.area] model (half-sine, constant, growth or column)",
                "dAdt": "add a [scene.area] model (half-sine, constant, growth or column)",
                "dmudt": "a spring-slider supplies it (its load rate k (V_lp - V)); other scenes do not"}
        what = ", ".join(f"{q} ({QUANTITIES[q].split(' [')[0]})" for q in sorted(missing))
        raise SceneError(f"law '{law.name}' needs {what}, which {scene_name} cannot supply: "
                         + "; ".join(sorted({hint[q] for q in missing if q in hint})))
    effects = scene.effects
    if scene.spring is not None and not isinstance(scene.normal, ConstantNormal):
        raise SceneError(f"{scene_name}: a spring-slider needs a constant normal force (scene.normal model 'constant')")
    if scene.spring is not None and isinstance(law.form(law.defaults()), NormalAreaRateForm):
        raise SceneError(f"law '{law.name}' on a spring-slider: its force sign(u) (a N + c dA/dt) does not grow with "
                         "the slip rate, so the quasi-static block has no slip rate for the spring's load")
    coupled = "slip-coupling" in effects
    spin = "spin" in effects or coupled
    if spin and scene.radius is None:
        raise SceneError(f"{scene_name}: effect 'spin' needs scene.radius")
    needs_normal = "N" in law.requires
    hertz = needs_normal and isinstance(scene.normal, HertzNormal)
    if hertz and scene.area is None:
        raise SceneError(f"law '{law.name}' needs N (normal force), which {scene_name} computes from the contact "
                         "area (Hertz model) but has no [scene.area] model")
    # the area is evaluated when the law reads A or dA/dt, or when a Hertz normal force reads A
    needs_area = bool({"A", "dAdt"} & set(law.requires)) or hertz
    states = ["v"]
    if spin:
        states += ["omega", "theta"]
    if needs_area and isinstance(scene.area, GrowthArea):
        states.append("x")
    if "compliance" in effects:
        if scene.compliance is None:
            raise SceneError(f"{scene_name}: effect 'compliance' needs a compliance model (linear or mindlin)")
        if scene.compliance.model == "mindlin-deresiewicz":
            raise SceneError(f"{scene_name}: compliance model 'mindlin-deresiewicz' is integrated for impact outcomes "
                             "only (frictionlab.physics.mdr); the trajectory solvers take 'linear' or 'mindlin'")
        if scene.compliance.model == "mindlin":
            if scene.area is None:
                raise SceneError(f"{scene_name}: compliance model 'mindlin' takes the contact radius from the "
                                 "contact area: add a [scene.area] model (hertz or half-sine)")
        states.append("xi")
    states += [LAW_PREFIX + n for n in law.state_names]
    if scene.spring is not None and scene.spring.inertial:
        states.append("load")
    plan = Plan(scene=scene, law=law, states=tuple(states), coupled=coupled, needs_area=needs_area,
                needs_normal=needs_normal)
    if scene.spring is not None:  # a law that cannot drive a quasi-static slider at all (Dahl: F depends on its state
        defaults = law.defaults()  # only) is refused here, not found out at every evaluation of a fit
        plan.slip_rate_partials(defaults, 0.0, plan.initial_state(defaults))
    return plan

