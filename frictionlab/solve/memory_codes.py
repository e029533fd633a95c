"""Numbers shared by ``frictionlab.solve.memoryrhs`` and its numba kernel ``memory_kernel`` (no imports)."""

#: Law codes.
LUGRE, DAHL, RS_AGING, RS_SLIP, DAHL_SLID, RS_PRZ = 0, 1, 2, 3, 4, 5
#: Normal-force model codes.
NORMAL_CONSTANT, NORMAL_HALF_SINE = 0, 1
#: Entries of the phase's constants C (``memoryrhs.Phase.C``).
(LAW, IL, IW, ITH, ILOAD, COUPLED, SPIN, RADIUS, INERTIA, MASS, DRIVE, STIFFNESS, NORMAL, NORMAL_VALUE, NORMAL_PHI,
 NORMAL_TC, DIRECTION, TINY, TSCALE, MAXCALLS, CALLS, BAD, STOP_T, SENSE, S0, STRICT) = range(26)
NC = 26
#: Values of C[BAD]: a value was not finite, the calls passed the cap, the slip turned (DAHL_SLID).
NOT_FINITE, TOO_MANY, TURNED = 1, 2, 3
#: Rate-and-state's reference speed V0 [m/s] (frictionlab/laws/rate_state.py).
V0 = 1e-6
