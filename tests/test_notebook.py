"""Results a notebook user can look at: .plot() on Dataset, Trajectory, FitResult and Comparison (returning
the Axes or Figure, taking ax=), the HTML views, "fits?" beside every fit, and one display unit per quantity
rounded to its error."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import frictionlab as fl  # noqa: E402
from frictionlab.core.display import param_text, rounded  # noqa: E402
from frictionlab.inference.fitting.result import ParamResult  # noqa: E402


@pytest.fixture(scope="module")
def incline():
    return fl.load_dataset("incline-oil-a100")


@pytest.fixture(scope="module")
def comparison(incline):
    return fl.compare(laws=["wear", "coulomb"], datasets=[incline, "impact-golf-v28", "kharaz2001-spin"],
                      equivalence=False, transfer=False)


def test_dataset_plot_draws_its_column_in_the_files_units(incline):
    ax = incline.plot()
    assert ax.get_xlabel() == "time [s]" and ax.get_ylabel() == "velocity v [m/s]"
    golf = fl.load_dataset("impact-golf-v28")
    fig, own = plt.subplots()
    assert golf.plot(y="omega", ax=own) is own and own.get_ylabel() == "spin omega [rpm]"
    assert own.get_xlabel() == "time [us]"  # the file's time unit
    np.testing.assert_allclose(own.lines[0].get_ydata(), golf.columns["omega"] * 60 / (2 * np.pi))
    assert fl.load_dataset("kharaz2001-spin").plot().get_xlabel() == "incidence [deg]"
    plt.close("all")


def test_trajectory_plot_and_view(incline):
    tr = fl.simulate("couette", incline, {"h": "20 um"})
    ax = tr.plot(y="v")
    np.testing.assert_allclose(ax.lines[0].get_ydata(), tr.v)
    with pytest.raises(KeyError, match="no series 'spin'"):
        tr.plot(y="spin")
    html = tr._repr_html_()
    assert "<table" in html and "couette" in html and "m/s" in html
    plt.close("all")


def test_dataset_view(incline):
    html = incline._repr_html_()
    assert "incline-oil-a100" in html and "synthetic" in html and "<th>sigma</th>" in html


def test_fit_plot_returns_a_figure_of_data_fit_and_residuals(incline):
    r = fl.fit("wear", incline)
    fig = r.plot()
    top, res = fig.axes
    assert res.get_ylabel() == "residual / sigma" and len(top.lines) >= 1
    d = r.per_dataset[0]
    np.testing.assert_allclose(res.lines[0].get_ydata(), d.residual / d.target.sigma)  # times are sorted already
    fig2, ax = plt.subplots()
    assert r.plot(ax=ax) is ax
    assert "fits? yes" in ax.get_legend().get_texts()[0].get_text()
    plt.close("all")


def test_a_poor_fit_says_so_in_every_view(incline):
    r = fl.fit("coulomb", incline)  # Coulomb cannot level off: reduced chi-square in the hundreds
    assert r.stats.redchi > 50 and r.goodness.fits is False
    html = r._repr_html_()
    assert "<th>fits?</th>" in html and "<td>no (" in html
    fig, ax = plt.subplots()
    assert "fits? no" in r.plot(ax=ax).get_legend().get_texts()[0].get_text()
    plt.close("all")


def test_comparison_plot_one_column_per_group(comparison):
    fig = comparison.plot()
    assert len(fig.axes) == 6  # three groups: data and fits, residuals
    titles = [a.get_title() for a in fig.axes[:3]]
    assert titles == ["incline-oil: incline-oil-a100", "impact-golf: impact-golf-v28", "kharaz2001: kharaz2001-spin"]
    fig2, axes = plt.subplots(1, 3)
    assert comparison.plot(ax=axes) is axes
    with pytest.raises(ValueError, match="3 dataset groups need 3 axes"):
        comparison.plot(ax=axes[:2])
    plt.close("all")


def test_comparison_view_has_a_fits_column(comparison):
    html = comparison._repr_html_()
    assert "<th>fits?</th>" in html
    assert "<td>yes</td>" in html and "<td>no (" in html


def test_one_display_unit_per_quantity_rounded_to_its_error():
    small = ParamResult("Dc", "Dc", "law", 3.973e-4, 1.12e-5, "m", True, 1e-5, 1e-9, 1.0, ("x",), shown="um")
    large = ParamResult("Dc", "Dc", "law", 1.013e-3, 3.1e-5, "m", True, 1e-5, 1e-9, 1.0, ("x",), shown="um")
    assert small.text() == "Dc = 397 ± 11 µm" and large.text() == "Dc = 1013 ± 31 µm"
    assert param_text(1760.0, 48.0, "1/m", "1/um") == "0.001760 ± 0.000048 1/µm"
    assert rounded(1.7851e6, 2.13e4) == ("1.785e6", "0.021e6") and rounded(0.09251, 0.0094) == ("0.0925", "0.0094")


def test_a_fitted_film_thickness_is_shown_in_micrometres(incline):
    r = fl.fit("couette", incline)
    assert r.params["h"].shown == "um"
    assert "µm" in r.summary() and "µm" in repr(r) and "µm" in r._repr_html_()
    spring = fl.get_law("rate-state-aging").spec("Dc")
    assert spring.display == "um"
