"""numba's ``njit`` with its on-disk cache where numba imports (a dependency); elsewhere the plain function, which
computes the same numbers, slower. Importing this module imports numba: import it where compiled code is used."""
try:
    import numba

    jit = numba.njit(cache=True, fastmath=False, error_model="numpy")
    COMPILED = True
except Exception:  # pragma: no cover - numba is a dependency; a broken install falls back to Python
    def jit(fn):
        return fn

    COMPILED = False
