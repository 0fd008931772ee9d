# SPDX-License-Identifier: GPL-2.0-or-later
"""addon/hbao/guard_geometry.py without Blender: the guard band's pixels
around a frame (the renders that use them: tests/test_addon.py)."""
from conftest import REPO  # noqa: F401  (puts the add-on on sys.path)
from hbao import guard_geometry, parameters


def test_the_band_keeps_the_frame_within_the_librarys_largest_image():
    """A frame 43692 pixels wide with a 25 % band (65536 at 6.25 %) passed
    the library's 65536 with its bands, and the whole frame's AO was off
    with the library's crop message (an exploratory run of very large
    renders): the band is narrowed to fit, to nothing where the frame fills
    the limit; other frames keep the band they ask for."""
    largest = parameters.MAX_IMAGE_SIZE
    assert guard_geometry.band_pixels(1920, 1080, 0.0625) == (120, 67)
    assert guard_geometry.band_pixels(43691, 64, 0.25) == (10922, 16)
    assert guard_geometry.band_pixels(43692, 64, 0.25) == ((largest - 43692) // 2, 16)
    assert guard_geometry.band_pixels(largest, 64, 0.0625) == (0, 4)
    assert guard_geometry.band_pixels(64, largest - 1, 0.25) == (16, 0)
    for width in (43692, 50000, largest - 1, largest):
        columns, _rows = guard_geometry.band_pixels(width, 64, 0.25)
        assert 0 <= columns and width + 2 * columns <= largest
