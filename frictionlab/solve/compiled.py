"""Optional compiled sliding phases (numba) for the built-in laws' closed-form families.

``frictionlab.solve.vecrk`` integrates any law that broadcasts, in numpy; this module integrates the same
sliding phases, scene by scene in one compiled loop, for the cases whose right-hand side it knows:

  law     a built-in law (``frictionlab.laws``) whose ``form(p)`` is a closed-form family:
          ``NormalAreaRateForm`` F = sign(u) (a N + c dA/dt), or ``AreaSlipForm`` F = k A u;
  scene   rigid impact or incline: states v, or v, omega, theta (spin, slip coupling, gravity), no
          tangential compliance, no growth area, no law states; area model half-sine or constant,
          normal-force model half-sine, weight or constant (each only where the law reads it).

Everything else (plugin laws, laws with memory, other models) stays on the numpy engine: numba is an
optional dependency (``pip install 'frictionlab[fast]'``), never needed by a law plugin. ``prepare``
says whether a batch is served; ``Prepared.integrate`` returns a ``vecrk.Result`` as
``vecrk.integrate`` does (the same scaled problem, scipy's tableaus passed in as arrays, the same step
control, initial step, breaks, zero-slip event on the dense output, dense outputs on the same grid;
its Y in the states' units), so the same steps and the same numbers, bitwise where numpy's sine is
libm's and the law's force is its form's expression; ``tests/test_compiled.py`` checks every output
against the numpy engine to 1e-12. The kernel's right-hand side ``_rhs`` is the built-in
forms' derivatives as ``Plan.derivatives`` computes them (branch slip included); it is the one place
physics is written here, and the tests check it against ``Plan.derivatives``.

``scatter_stuck`` does the bookkeeping of ``batchstick.fill_stuck`` (which outputs a stuck phase owns, and
writing them) in one compiled pass for the same batches; the stuck states themselves come from
``solvers.stick.stuck_states``.

Counting: ``nfev`` counts the evaluations each scene made (the numpy engine also counts the dense-output
stages it evaluates for every active scene of a step in which any needed them). Serial (CPU time is the
measure); compiled on first use and cached on disk (``cache=True``).
"""
from __future__ import annotations

import importlib.util
import math
import warnings

import numpy as np

from ..core.errors import SolverError
from . import vecrk
from .compiled_codes import (
    A_OR_K,
    AREA_CONST,
    AREA_PEAK,
    AREA_PHI,
    AREA_TC,
    BREAK_AREA,
    BREAK_NORMAL,
    CONSTANT,
    DRIVE,
    FORM_AS,
    FORM_NAR,
    HALF_SINE,
    INERTIA,
    MASS,
    NCOL,
    NONE,
    NORMAL_CONST,
    NORMAL_PEAK,
    NORMAL_PHI,
    NORMAL_TC,
    NOT_FINITE,
    OK,
    RADIUS,
    TOO_MANY,
    UNDERFLOW,
    VANISH,
    C,
)

_status = None  # None: not checked yet; True: usable; else why not


def available() -> bool:
    """numba importable and the kernel module loads, checked once per process (the first batch that could
    use it imports numba). A numba that fails to import (one built for another numpy, say) warns once and
    leaves every batch to the numpy engine."""
    global _status
    if _status is None:
        if importlib.util.find_spec("numba") is None:
            _status = "numba is not installed"
        else:
            try:
                from . import compiled_kernel  # noqa: F401  (imports numba; compiles on first call only)
                _status = True
            except Exception as exc:  # numba's import fails in many ways; none may stop a batch
                _status = f"{type(exc).__name__}: {exc}"
                warnings.warn(f"frictionlab: numba is installed but does not import ({_status}); batches use the "
                              "numpy engine", RuntimeWarning, stacklevel=2)
    return _status is True


def _area_code(model):
    from ..physics.scene import ConstantArea, HalfSineArea

    return {HalfSineArea: HALF_SINE, ConstantArea: CONSTANT}.get(type(model))


def _normal_code(model):
    from ..physics.scene import ConstantNormal, HalfSineNormal, WeightNormal

    return {HalfSineNormal: HALF_SINE, WeightNormal: CONSTANT, ConstantNormal: CONSTANT}.get(type(model))


def _form_codes(law, plan, form):
    """(form code, area code, normal code, a or k, c) of the law's closed-form family on this plan, or None
    where the kernel does not know the form or a model it reads."""
    from ..physics.law import AreaSlipForm

    s = plan.scene
    req = law.requires
    area = _area_code(s.area) if plan.needs_area else NONE
    normal = _normal_code(s.normal) if plan.needs_normal else NONE
    if area is None or normal is None:
        return None
    if isinstance(form, AreaSlipForm):
        if "A" not in req or area == NONE:
            return None
        return FORM_AS, area, normal, form.k, 0.0
    if "N" not in req or normal == NONE:
        return None
    if np.any(np.asarray(form.c) != 0.0) and ("dAdt" not in req or area == NONE):
        return None
    return FORM_NAR, area, normal, form.a, form.c


def _columns(plan, n, area, normal, a, c):
    """The kernel's per-scene numbers (n, NCOL): body, drive, form coefficients, contact models, breaks."""
    from .solvers.stick import vanishing_slip

    s = plan.scene
    cols = np.zeros((n, NCOL))
    spin = plan.has_spin

    def put(col, value):
        cols[:, col] = np.broadcast_to(np.asarray(value, dtype=float), (n,))

    put(MASS, s.mass)
    put(RADIUS, s.radius if spin else 0.0)
    put(INERTIA, s.inertia if spin else 1.0)
    put(DRIVE, plan.drive)
    put(VANISH, vanishing_slip(plan))
    put(A_OR_K, a)
    put(C, c)
    if area == HALF_SINE:
        put(AREA_PEAK, s.area.peak)
        put(AREA_PHI, math.pi / np.asarray(s.area.contact_time))
        put(AREA_TC, s.area.contact_time)
    elif area == CONSTANT:
        put(AREA_CONST, s.area.area)
    if normal == HALF_SINE:
        put(NORMAL_PEAK, s.normal.peak)
        put(NORMAL_PHI, math.pi / np.asarray(s.normal.contact_time))
        put(NORMAL_TC, s.normal.contact_time)
    elif normal == CONSTANT:
        put(NORMAL_CONST, s.normal.value)
    # breaks as ``batchrk.breaks`` takes them: every half-sine model's end of contact, read or not
    put(BREAK_AREA, getattr(s.area, "contact_time", np.nan))
    put(BREAK_NORMAL, getattr(s.normal, "contact_time", np.nan))
    return cols


def prepare(law, plan, p, n: int):
    """A ``Prepared`` for the n scenes of the batch view ``plan`` (arrays over scenes) and batch
    parameters p, or None where the compiled path does not serve them (numba absent, plugin law, law
    with memory, unknown scene model or state)."""
    from ..physics.law import AreaSlipForm, NormalAreaRateForm

    if not type(law).__module__.startswith("frictionlab.laws."):
        return None
    if plan.law_states or plan.scene.spring is not None:
        return None
    if plan.states not in (("v",), ("v", "omega", "theta")):
        return None
    form = law.form(p)
    if not isinstance(form, (AreaSlipForm, NormalAreaRateForm)) or not available():
        return None
    found = _form_codes(law, plan, form)
    if found is None:
        return None
    code, area, normal, a, c = found
    need_dadt = code == FORM_NAR and bool(np.any(np.asarray(c) != 0.0))
    codes = np.array([code, area, normal, int(plan.coupled), int(plan.has_spin), int(need_dadt)], dtype=np.int64)
    return Prepared(codes, _columns(plan, n, area, normal, a, c))


def _tableau(method):
    from .rktableau import DOP853, RK45

    cls = {"RK45": RK45, "DOP853": DOP853}[method]
    ns = cls.n_stages
    A = np.zeros((ns, ns))
    A[:, : cls.A.shape[1]] = cls.A
    if cls is DOP853:
        E = np.array([cls.E5, cls.E3])
        nk = ns + 1 + len(cls.C_EXTRA)
        AX, CX, D = np.array(cls.A_EXTRA, dtype=float), np.array(cls.C_EXTRA, dtype=float), np.array(cls.D, dtype=float)
    else:
        E = np.array(cls.E, dtype=float)[None]
        nk = ns + 1
        AX, CX, D = np.zeros((0, nk)), np.zeros(0), np.ascontiguousarray(cls.P.T, dtype=float)
    return (A, np.array(cls.B, dtype=float), np.array(cls.C, dtype=float), E, AX, CX, D, int(cls.order),
            -1.0 / (cls.error_estimator_order + 1), cls is DOP853)


class Prepared:
    """Per-scene constants of a chunk's scenes (``cols``, (n, NCOL)) and the structure codes
    (form, area model, normal model, slip coupling, spin, dA/dt needed)."""

    def __init__(self, codes, cols):
        self.codes, self.cols = codes, cols

    def integrate(self, ids, t0, y0, direction, span, scale, T, method, rtol, atol=None, out=None) -> vecrk.Result:
        """One sliding phase of scenes ``ids`` (positions in the chunk) on the scaled problem, as
        ``batchrk.slide_rk`` with ``vecrk.integrate``: t0 (n,) [s], y0 (d, n), direction (n,), span (n,) [s] and
        scale (d, n) over the whole chunk; T (n, m) the chunk's output times [s]. The Result's Y is in the
        states' units (``scaled=False``), written into ``out`` (d, k, m) when given."""
        kern = _compiled().kernel
        atol = rtol if atol is None else atol
        d, k, m = y0.shape[0], ids.size, T.shape[1]
        rel = np.linspace(0.0, 1.0, m)
        per_row = not (T.strides[0] == 0 and np.all(span[ids] == span[ids[0]]))
        grid = np.ascontiguousarray(T) if per_row else (T[0] / span[ids[0]])[None, :]  # as batchrk.scaled_grid
        Y = np.empty((d, k, m)) if out is None else out
        reached = np.empty((k, m), dtype=bool)  # every entry written
        t_event = np.full(k, np.nan)
        y_event = np.full((d, k), np.nan)
        nfev = np.zeros(k, dtype=np.int64)
        stat = np.zeros(2, dtype=np.int64)  # [status, scene] of the first failure
        Ys = [Y[min(j, d - 1)] for j in range(3)]  # each (k, m) C-contiguous: one signature for any caller
        assert all(y.flags.c_contiguous for y in Ys)
        iters = kern(*_tableau(method), self.codes, self.cols, np.ascontiguousarray(ids, dtype=np.int64), t0, y0,
                     direction, span, np.require(scale, requirements="CW"), grid, per_row, rel, float(rtol),
                     float(atol),
                     vecrk.MAX_ITERATIONS, *Ys, reached, t_event, y_event, nfev, stat)
        if stat[0] != OK:
            i = int(ids[stat[1]])
            msg = {UNDERFLOW: f"step size underflow in problem {stat[1]}",
                   TOO_MANY: f"more than {vecrk.MAX_ITERATIONS} steps; the problem is stiff or singular",
                   NOT_FINITE: f"the states became NaN or infinite in scene {i}"}[int(stat[0])]
            raise SolverError(f"batch {method}: {msg}")
        return vecrk.Result(Y, reached, t_event, y_event, nfev, int(iters), scaled=False)


def scatter_stuck(Ys, rows, Ts, t_from, t_to, done, stuck_mask, Y):
    """``compiled_kernel.scatter_stuck`` (the bookkeeping of ``batchstick.fill_stuck``) for states Y (d, n, m)."""
    d = Y.shape[0]
    _compiled().scatter_stuck(np.ascontiguousarray(Ys), np.ascontiguousarray(rows, dtype=np.int64),
                              np.ascontiguousarray(Ts), np.ascontiguousarray(t_from, dtype=float),
                              np.ascontiguousarray(t_to, dtype=float), done, stuck_mask,
                              *[Y[min(j, d - 1)] for j in range(3)])


def _compiled():
    """The kernel module (imports numba, compiles or loads the kernel on first call)."""
    from . import compiled_kernel

    return compiled_kernel
