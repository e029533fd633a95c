"""The report's PNG writer (report.figures.png): what Pillow decodes is the image given, at the resolution given."""
import io

import numpy as np
import pytest
from PIL import Image

from frictionlab.report.figures.png import png


@pytest.mark.parametrize("shape", [(1, 1), (3, 7), (480, 640), (101, 33)])
def test_what_pillow_reads_back_is_the_image_and_its_resolution(shape):
    rng = np.random.default_rng(sum(shape))
    rgb = rng.integers(0, 256, (*shape, 3), dtype=np.uint8)
    rgb[: shape[0] // 2] = 255  # flat white, as most of a figure is
    image = Image.open(io.BytesIO(png(rgb, 110)))
    assert image.format == "PNG" and image.mode == "RGB" and image.size == (shape[1], shape[0])
    assert np.array_equal(np.asarray(image), rgb)
    assert [round(v) for v in image.info["dpi"]] == [110, 110]


def test_a_strided_view_is_written_as_its_pixels():
    rgba = np.random.default_rng(1).integers(0, 256, (20, 30, 4), dtype=np.uint8)
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(png(rgba[:, :, :3], 72)))), rgba[:, :, :3])
