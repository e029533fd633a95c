"""The report's figures as PNG bytes (``report.figures.base._png``: matplotlib's savefig, written by Pillow): Pillow
reads back the figure's pixels at the figure's size and resolution."""
import io

import numpy as np
import pytest
from PIL import Image

from frictionlab.report.figures import base


@pytest.mark.parametrize("inches", [(3.0, 2.0), (6.4, 4.8), (1.0, 3.3)])
def test_what_pillow_reads_back_is_the_figure_at_its_size_and_resolution(inches):
    fig = base.figure(inches)
    ax = fig.add_subplot()
    ax.plot([0.0, 1.0, 2.0], [0.0, 1.0, 0.5], color="#d95f02")
    ax.set_xlabel("time [ms]")
    data = base._png(fig)
    image = Image.open(io.BytesIO(data))
    assert image.format == "PNG"
    assert image.size == (round(inches[0] * base.DPI), round(inches[1] * base.DPI))
    assert [round(v) for v in image.info["dpi"]] == [base.DPI, base.DPI]
    fig.canvas.draw()  # the same figure drawn again: the pixels Pillow read are the canvas's
    assert np.array_equal(np.asarray(image.convert("RGBA")), np.asarray(fig.canvas.buffer_rgba()))
    assert "Software" not in image.info  # no version stamp: the bytes depend on the drawing only


def test_a_blank_figure_is_white():
    fig = base.figure((1.0, 1.0))
    image = np.asarray(Image.open(io.BytesIO(base._png(fig))).convert("RGB"))
    assert image.shape == (base.DPI, base.DPI, 3) and np.all(image == 255)
