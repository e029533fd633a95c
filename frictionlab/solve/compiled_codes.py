"""Numbers shared by ``frictionlab.solve.compiled`` and its numba kernel ``compiled_kernel`` (no imports)."""

#: Columns of the per-scene constants (``compiled.Prepared.cols``).
(MASS, RADIUS, INERTIA, DRIVE, VANISH, A_OR_K, C, AREA_PEAK, AREA_PHI, AREA_TC, AREA_CONST, NORMAL_PEAK, NORMAL_PHI,
 NORMAL_TC, NORMAL_CONST, BREAK_AREA, BREAK_NORMAL) = range(17)
NCOL = 17
#: Model codes.
NONE, HALF_SINE, CONSTANT = 0, 1, 2
FORM_NAR, FORM_AS = 0, 1  # NormalAreaRateForm, AreaSlipForm
#: Kernel status codes per scene.
OK, UNDERFLOW, TOO_MANY, NOT_FINITE = 0, 1, 2, 3
