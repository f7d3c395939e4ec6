"""hmatddm.render.offscreen: PNG output and the refusal of an empty render (the plotter
itself is exercised by every picture of tests/render/test_render.py)."""
import matplotlib.image
import numpy as np
import pytest

from hmatddm.errors import HmatddmError
from hmatddm.render.offscreen import save_png, screenshot


def test_save_png_writes_the_image_atomically(tmp_path):
    image = np.zeros((20, 30, 3), dtype=np.uint8)
    image[5:10, 10:20] = (255, 0, 0)
    path = save_png(image, tmp_path / "sub" / "red.png")
    read = matplotlib.image.imread(path)
    assert read.shape[:2] == (20, 30)
    assert np.allclose(read[7, 15, :3], (1.0, 0.0, 0.0)) and np.allclose(read[0, 0, :3], 0.0)
    assert [p.name for p in path.parent.iterdir()] == ["red.png"]  # no temporary left behind


class _Plotter:
    def __init__(self, image=None, error=None):
        self.image, self.error = image, error

    def screenshot(self, return_img, window_size):
        if self.error is not None:
            raise self.error
        return self.image


def test_an_all_black_or_failed_render_is_reported_as_no_render_context():
    white = np.full((4, 4, 3), 255, dtype=np.uint8)
    assert screenshot(_Plotter(white), (4, 4)) is white
    for plotter in (_Plotter(np.zeros((4, 4, 3), np.uint8)), _Plotter(np.zeros((0, 0, 3), np.uint8)),
                    _Plotter(error=RuntimeError("no GL"))):
        with pytest.raises(HmatddmError, match="offscreen render context"):
            screenshot(plotter, (4, 4))
