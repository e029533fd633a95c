"""One grammar for the command line: --version, global options anywhere, lists one way, help with
examples, dataset templates that load, readable 'datasets show', honest series output, umask permissions."""
import os
import stat

import pytest

from frictionlab import __version__, load_dataset
from frictionlab.cli import COMMANDS, build_parser, main

LAWS_FILE = '''
from frictionlab import register_law
from frictionlab.laws.coulomb import Coulomb


@register_law
class Coulomb2(Coulomb):
    name = "coulomb-{where}"
'''


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"frictionlab {__version__}"


@pytest.mark.parametrize("where", ["before", "after", "both"])
def test_global_options_before_or_after_the_command(tmp_path, capsys, where):
    from frictionlab import unregister_law

    f = tmp_path / f"my_laws_{where}.py"
    f.write_text(LAWS_FILE.format(where=where))
    argv = {"before": ["--load", str(f), "laws", "--brief"], "after": ["laws", "--brief", "--load", str(f)],
            "both": ["--quiet", "laws", "--load", str(f), "--brief", "--debug"]}[where]
    try:
        assert main(argv) == 0
    finally:
        unregister_law(f"coulomb-{where}")
    assert f"coulomb-{where}" in capsys.readouterr().out
    args = build_parser().parse_args(["--load", "a.py", "laws", "--load", "b.py", "--quiet"])
    assert (args.load, args.sub_load, args.quiet, args.sub_quiet) == (["a.py"], ["b.py"], False, True)


def test_lists_are_repeated_options_or_commas_everywhere():
    parse = build_parser().parse_args
    a = parse(["compare", "--laws", "wear,coulomb", "--data", "x.toml,y", "--solver", "exact,series"])
    b = parse(["compare", "--laws", "wear", "--laws", "coulomb", "--data", "x.toml", "--data", "y",
               "--solver", "exact", "--solver", "series"])
    assert (a.laws, a.data, a.solver) == (b.laws, b.data, b.solver) == (["wear", "coulomb"], ["x.toml", "y"],
                                                                       ["exact", "series"])
    c = parse(["simulate", "couette", "d", "--param", "eta=0.1 Pa s,h=80 um", "--param", "x=1"])
    assert c.param == ["eta=0.1 Pa s", "h=80 um", "x=1"]
    d = parse(["fit", "area-rate", "a", "b", "--local", "mu,eta_prime"])
    assert d.local == ["mu", "eta_prime"]


@pytest.mark.parametrize("argv", [[c] for c in COMMANDS] + [["datasets", a] for a in ("list", "show", "template", "import",
                                                                                      "rebuild")])
def test_every_command_has_its_own_help_with_examples(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(argv + ["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert f"usage: frictionlab {' '.join(argv)}" in out and "examples:\n  frictionlab " + argv[0] in out
    assert "Lists: repeat an option or separate values with commas" in out


@pytest.mark.parametrize("kind", ["impact", "incline", "impact-outcome", "spring-slider"])
def test_datasets_template_writes_a_pair_that_loads(kind, tmp_path, capsys):
    assert main(["datasets", "template", kind, "--name", "mine", "--out", str(tmp_path)]) == 0
    d = load_dataset(tmp_path / "mine.toml")
    assert d.kind == kind and len(d) >= 8 and d.provenance.kind == "synthetic"
    assert (tmp_path / "mine.toml").read_text().count("#") > 10  # commented
    assert main(["datasets", "template", kind, "--name", "mine", "--out", str(tmp_path)]) == 2
    assert "exists" in capsys.readouterr().err


def test_datasets_show_in_units_a_person_reads(capsys):
    assert main(["datasets", "show", "impact-golf-v28"]) == 0
    out = capsys.readouterr().out
    assert "np.float64" not in out and "Scene(" not in out
    for text in ("mass: 46 g", "radius: 21.3 mm", "peak: 130 mm^2", "contact_time: 500 µs", "noise:       none (",
                 "t_peak = 260 µs ± 10 µs", "omega_peak = 6700 rpm ± 100 rpm"):
        assert text in out
    assert main(["datasets", "show", "impact-outcome-synthetic"]) == 0
    assert "SpeedLaw(" not in capsys.readouterr().out


def test_series_output_does_not_contradict_itself(capsys):
    from frictionlab.solve.solvers.series import SeriesAccuracyWarning

    with pytest.warns(SeriesAccuracyWarning, match="b = 0.814"):  # the series says it is used beyond its range
        assert main(["simulate", "wear", "impact-golf-v28", "--param", "lam=1.81e6 Pa s/m",
                     "--solver", "series"]) == 0
    out = capsys.readouterr().out
    assert "never reached zero" not in out
    assert "truncated series' slip crosses zero at t = 286.7 µs" in out


def test_outputs_get_the_umask_permissions(tmp_path, capsys):
    old = os.umask(0o022)
    try:
        csv = tmp_path / "s.csv"
        assert main(["simulate", "wear", "impact-golf-v28", "--solver", "exact", "--out", str(csv)]) == 0
        assert stat.S_IMODE(csv.stat().st_mode) == 0o644
        assert main(["datasets", "template", "incline", "--out", str(tmp_path)]) == 0
        assert stat.S_IMODE((tmp_path / "my-data.toml").stat().st_mode) == 0o644
    finally:
        os.umask(old)


def test_quiet_silences_progress(tmp_path, capsys):
    assert main(["datasets", "template", "impact", "--name", "q", "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    argv = ["compare", "--laws", "wear", "--data", str(tmp_path / "q.toml"), "--bootstrap", "0", "--no-tolerance",
            "--jobs", "1", "--no-equivalence"]
    assert main(argv + ["--out", str(tmp_path / "r1"), "--quiet"]) == 0
    assert capsys.readouterr().err == ""
    assert main(argv + ["--out", str(tmp_path / "r2")]) == 0
    assert "compare: fit 1/" in capsys.readouterr().err


def test_compare_summary_renders_the_answers_only():
    from frictionlab.commands.compare import answer_lines
    from frictionlab.inference.verdicts.answers import Answer

    class C:
        answers = ()

    assert answer_lines(C()) == ["answers: none (the verdict layer filled no Comparison.answers); see the report's "
                                 "tables"]
    a = Answer(group="impact-golf", datasets=("a",), provenance="reconstructed", best="wear [exact]", fits=False,
               headline="no registered law describes these data", goodness="chi2 p < 1e-6", equivalence="different",
               noise_threshold="", series_vs_exact="the series' slip crosses zero at 309 us")
    C.answers = (a,)
    assert answer_lines(C())[1] == ("  impact-golf: no registered law describes these data; chi2 p < 1e-6; lambda A u "
                                    "vs mu N + mu eta' dA/dt: different; the series' slip crosses zero at 309 us")


def test_defaults_that_differ_between_the_command_line_and_the_api_are_said_in_both(capsys):
    import inspect

    from frictionlab import compare
    from frictionlab.commands.compare import BOOTSTRAP_N

    assert main(["compare", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    api = inspect.signature(compare).parameters
    assert api["bootstrap"].default == 0 != BOOTSTRAP_N and api["fit_timeout"].default is None
    assert f"--bootstrap {BOOTSTRAP_N} (API bootstrap=0)" in text and "(API fit_timeout=None)" in text
    assert f"bootstrap {BOOTSTRAP_N}" in " ".join(compare.__doc__.split()) and "case resamples" not in text


def test_the_fit_tolerance_default_is_the_librarys_and_said_beside_simulates(capsys):
    from frictionlab.commands.fit import FIT_RTOL
    from frictionlab.inference.fitting.predict import FIT_RTOL as LIBRARY

    assert FIT_RTOL == LIBRARY
    assert main(["fit", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert f"(default {LIBRARY:g}, the library's FIT_RTOL" in text and "'simulate' defaults to 1e-10" in text
