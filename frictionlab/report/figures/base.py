"""What every report figure shares: the Agg backend, PNG bytes at one DPI, law colours and line styles,
legend labels, and which fits are one curve. Display units: rpm, deg, us/ms/s, N."""
from __future__ import annotations

import io

import numpy as np

LAW_COLORS = {"coulomb": "#7f7f7f", "area-rate": "#d95f02", "wear": "#1b9e77", "couette": "#7570b3"}
EXTRA_COLORS = ["#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#1f78b4"]
DPI = 110
#: Two fits are one curve when they differ by at most this fraction of the noise at every data point.
SAME_CURVE = 1e-3


def _plt():
    from ...core.display import pyplot

    return pyplot()


def _png(fig) -> bytes:
    """The figure as PNG bytes at DPI. A layout engine (constrained layout) is run here, at the
    saving DPI, and then switched off: savefig would otherwise draw the whole figure once more
    (without rendering) just to run it. The same bytes as a plain savefig (tests/test_report.py)."""
    buf = io.BytesIO()
    engine = fig.get_layout_engine()
    if engine is not None:
        fig.set_dpi(DPI)
        engine.execute(fig)
        fig.set_layout_engine(None)
    fig.savefig(buf, format="png", dpi=DPI)
    _plt().close(fig)
    return buf.getvalue()


def _style(law: str, solver: str, i: int) -> dict:
    color = LAW_COLORS.get(law, EXTRA_COLORS[i % len(EXTRA_COLORS)])
    ls = "--" if solver == "series" else "-"
    return {"color": color, "ls": ls, "lw": 1.8}


def _label(f, rows, laws=None, under=()) -> str:
    """'wear = couette [exact], ΔAIC 1.2' (the ranking row that holds the law, merged or not), and the
    candidates drawn under this curve (``under``: 'lies over coulomb [exact]')."""
    r = next((r for r in rows if f.law in (r.members or (r.law,)) and r.solver == f.solver), None)
    extra = f", ΔAIC {r.delta_aic:.1f}" if r is not None and r.rank is not None else ""
    name = " = ".join(laws or [f.law])
    if r is not None and len(r.members) > 1:  # the ranking's merged candidate: its name, its members not repeated
        name = r.law
        under = [u for u in under if u not in {f"{m} [{f.solver}]" for m in r.members}]
    hidden = f" (hides {', '.join(under)})" if under else ""
    return f"{name} [{f.solver}]{extra}{hidden}"


def wrapped(text: str, width_in: float, fontsize: float) -> str:
    """``text`` broken into lines that fit a figure ``width_in`` inches wide at ``fontsize`` points."""
    import textwrap

    return "\n".join(textwrap.wrap(text, max(20, int(width_in * 72 / (0.55 * fontsize)))))


#: A curve is hidden under another when they differ by less than this fraction of the plotted span everywhere.
HIDDEN = 4e-3


def visible_curves(curves, span: float) -> list[tuple[object, list[str], list[str]]]:
    """(fit, laws, hidden) for the curves of ``distinct_curves`` that can be seen: a curve within HIDDEN x
    ``span`` of an earlier one at every data point is not drawn, and is named in that one's legend entry."""
    out: list[tuple[object, list[str], list[str]]] = []
    for f, laws in curves:
        m = f.per_dataset[0].model
        for g, _, hidden in out:
            mg = g.per_dataset[0].model
            if mg.shape == m.shape and np.all(np.abs(mg - m) <= HIDDEN * span):
                hidden.append(f"{' = '.join(laws)} [{f.solver}]")
                break
        else:
            out.append((f, laws, []))
    return out


def draw_fit(ax, f, obs: str, t, tf: float, uf: float, label: str, **style):
    """The fit ``f``'s ``obs`` as a dense curve over the span of the data times ``t`` (s), scaled by tf and uf;
    a stiff law whose dense curve exceeds the solver's budget draws its fitted points instead."""
    from ...core.errors import FrictionLabError

    d = f.per_dataset[0]
    try:
        tr = d.trajectory(f.law, np.linspace(float(t[0]), float(t[-1]), 300))
        ax.plot(tr.t * tf, tr[obs] * uf, label=label, zorder=3, **style)
    except FrictionLabError:
        ax.plot(t * tf, d.model * uf, label=label, zorder=3, **style)


def same_curve(a, b) -> bool:
    """Whether two fits of one dataset with one solver predict the same curve at every data point (within
    SAME_CURVE sigma): laws of one functional form, or a law whose extra term has no effect there."""
    if a.solver != b.solver or len(a.per_dataset) != len(b.per_dataset):
        return False
    for da, db in zip(a.per_dataset, b.per_dataset):
        if da.model.shape != db.model.shape or not np.all(np.abs(da.model - db.model) <= SAME_CURVE * da.target.sigma):
            return False
    return True


def distinct_curves(fits) -> list[tuple[object, list[str]]]:
    """(representative fit, the laws whose fits are that same curve, simplest first) for successful fits, in order."""
    out: list[tuple[object, list[str]]] = []
    for f in fits:
        if not f.ok:
            continue
        for rep, laws in out:
            if same_curve(rep, f):
                laws.append(f.law)
                break
        else:
            out.append((f, [f.law]))
    return [(f, simplest_first(laws)) for f, laws in out]


def simplest_first(laws) -> list[str]:
    """Laws of one curve in the order the ranking names them ('wear = couette'): fewest parameters first,
    then by name (inference.ranking.merge_identical), so each merged candidate has one spelling."""
    from ...physics.registry import get_law

    def key(law):
        try:
            return (len(get_law(law).params), law)
        except Exception:  # a law no longer registered: by name after the others
            return (1 << 30, law)
    return sorted(set(laws), key=key)


def is_png(data: bytes) -> bool:
    return data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 100
