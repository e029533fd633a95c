"""The measured velocity-step records of the steadystate routine (Giacomel et al. 2024), read where they were
placed (``../shared/data/steadystate`` beside the repository, or FRICTIONLAB_RAW_DATA): their steps as the
segmentation finds them, the three sepiolite slices joined back into one experiment (in a temporary folder,
never in the repository), and the records as datasets in every view."""
from __future__ import annotations

import numpy as np
import pytest

from frictionlab.cli import main
from frictionlab.io import external
from frictionlab.io.velstep import analyse, read_raw

FILES = {name: spec["file"] for name, spec in external.RECORDS.items()}


def _path(name: str):
    return external.locate(name)


pytestmark = pytest.mark.skipif(any(_path(n) is None for n in FILES),
                                reason="the measured records are not placed in ../shared/data/steadystate "
                                       "(or FRICTIONLAB_RAW_DATA); they are not held in the repository")


@pytest.fixture(scope="module")
def records():
    return {name: analyse(read_raw(_path(name)), name) for name in FILES}


def test_each_record_holds_one_step_at_its_displacement_kink(records):
    for name, imp in records.items():
        (st,) = imp.seg.steps
        assert st.time_se < 0.2 and all(v > 0 for v in imp.velocities), name
    basalt = records["basalt-velstep4"].seg.steps[0]
    assert abs(basalt.time - 11676.375) < 0.01  # the kink; a crossing moved to a sample lands at 11676.710
    assert records["basalt-velstep4"].velocities == pytest.approx((3e-6, 1e-5), rel=0.005)
    assert len(records["basalt-velstep4"].seg.jumps) == 4  # the servo's 1 um corrections, stitched
    for name, v in (("sepiolite-velstep1", (2e-7, 2e-6)), ("sepiolite-velstep2", (2e-6, 2e-7)),
                    ("sepiolite-velstep3", (2e-7, 2e-6))):
        assert records[name].velocities == pytest.approx(v, rel=0.002), name


def test_the_basalt_record_imports_without_a_stated_stiffness(records):
    (w,) = records["basalt-velstep4"].windows
    assert 1e3 < w.stiffness < 2e4 and "initial slope" in w.stiffness_note  # 0.001 to 0.02 1/um: a start
    assert w.b == 5849 and 0 <= w.a < 200  # to the record's end, from a steady state the data show near its start
    assert "at steady state" in w.start_note


def test_the_sepiolite_slices_joined_are_one_experiment_of_three_steps(records, tmp_path):
    """velstep1-3 overlap in time with identical rows: their union is the experiment, 0.2 -> 2 -> 0.2 -> 2 um/s,
    the first step about 2230 s after its start."""
    parts = [np.loadtxt(_path(f"sepiolite-velstep{i}"), skiprows=1) for i in (1, 2, 3)]
    rows = parts[0]
    for p in parts[1:]:
        rows = np.vstack([rows, p[p[:, 0] > rows[-1, 0]]])
    joined = tmp_path / "joined.txt"
    with open(joined, "w") as fh:
        fh.write("Time(s)\tDispl(microns)\tFriction\tEffectiveNormalstress(MPa)\n")
        np.savetxt(fh, rows, fmt="%.6f", delimiter="\t")
    imp = analyse(read_raw(joined), "sepiolite")
    assert len(imp.seg.steps) == 3 and len(imp.windows) == 3
    assert imp.seg.steps[0].time - rows[0, 0] == pytest.approx(2230, abs=1)
    assert imp.velocities == pytest.approx((2e-7, 2e-6, 2e-7, 2e-6), rel=0.002)
    for st, name in zip(imp.seg.steps[::2], ("sepiolite-velstep1", "sepiolite-velstep3")):  # the same kinks
        alone = records[name].seg.steps[0]
        assert abs(st.time - alone.time) < 4 * np.hypot(st.time_se, alone.time_se), name


def test_the_records_are_rows_of_the_datasets_list_with_source_and_license(capsys):
    assert main(["datasets"]) == 0
    out = capsys.readouterr().out
    for name in FILES:
        row = next(line for line in out.splitlines() if line.startswith(name + " "))
        assert "spring-slider" in row and "measured" in row, row
    assert main(["datasets", "show", "basalt-velstep4"]) == 0
    out = capsys.readouterr().out
    assert "license:     MIT" in out and "provenance:  measured; pgiacomel/steadystate" in out


def test_the_default_compare_fits_the_records_with_the_laws_of_their_kind():
    from frictionlab.io.dataset import available_names, load_dataset
    from frictionlab.pipeline.planning import plan_fits
    from frictionlab.pipeline.settings import default_laws_by_kind

    dss = [load_dataset(n) for n in available_names()]
    by_kind = default_laws_by_kind(d.kind for d in dss)
    plan = plan_fits(tuple(n for v in by_kind.values() for n in v), dss, None, {}, by_kind)
    fitted = {}
    for law, ds, _, _ in plan.tasks:
        fitted.setdefault(ds.name, set()).add(law)
    for name in FILES:
        assert fitted[name] == {"rate-state-aging", "rate-state-slip", "rate-state-prz", "rate-state-nagata"}, name
    assert fitted["impact-golf-v28"] == {"coulomb", "area-rate", "wear", "couette"}


def test_nagatas_fit_with_c_free_is_not_beaten_by_one_with_c_held():
    """Nagata's law nests the aging law (c = 0), and holding c is a restriction: the fit with c free must be at
    least as good (in -2 ln L) as one with c held at 0, at its default or at its upper bound. On sepiolite-velstep3
    the grid started from c's default alone ended at the upper bound, c = 20, 16 above the fit with c held at 2;
    the grid from c = 0 finds that basin (``Problem.search``)."""
    import frictionlab as fl

    ds = fl.load_dataset("sepiolite-velstep3")
    free = fl.fit("rate-state-nagata", ds)
    for c in (0.0, 2.0, 20.0):
        held = fl.fit("rate-state-nagata", ds, fixed={"c": c})
        assert free.stats.neg2loglik <= held.stats.neg2loglik + 1e-3, (c, free.value("c"), free.stats.neg2loglik,
                                                                        held.stats.neg2loglik)
