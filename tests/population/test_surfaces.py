"""Textured surfaces (`ddmm.population.stimuli.surfaces`, issue 43 part 1): heightmaps, their sampling, refusals."""

import numpy as np
import pytest
from scipy import ndimage

from ddmm.population.stimuli.surfaces import FONT_5X7, Surface, dot_pattern, from_bitmap, grating, letters


def test_a_grating_has_its_period_duty_cycle_and_ridges_along_y():
    g = grating(1.0, ridge_mm=0.3, height_mm=0.4, width_mm=5.3, length_mm=2.0, pixel_mm=0.05)
    assert g.periodic and g.width_mm == pytest.approx(5.0) and g.shape == (40, 100)  # whole periods
    assert np.all(g.height_mm == g.height_mm[:1])  # every row alike: ridges run along y
    row = g.height_mm[0]
    assert np.array_equal(row, np.roll(row, 20)) and not np.array_equal(row, np.roll(row, 10))  # 1 mm = 20 pixels
    assert (row > 0).mean() == pytest.approx(0.3) and set(row.tolist()) == {0.0, 0.4}
    assert (grating(2.0, pixel_mm=0.1).height_mm[0] > 0).mean() == pytest.approx(0.5)  # half the period by default
    # sampled halfway up its edges, the ridge is ridge_mm wide at half height
    x = np.linspace(-2.5, 2.5, 5001)
    assert (g.height_at(x, 0.0) >= 0.2).mean() == pytest.approx(0.3, abs=2e-3)


def test_a_dot_pattern_is_a_square_lattice_of_round_dots():
    d = dot_pattern(2.0, 0.5, 0.3, width_mm=6.0, length_mm=4.0, pixel_mm=0.05)
    labels, n = ndimage.label(d.height_mm > 0)
    assert n == 6 and d.max_height_mm == 0.3  # 3 x 2 cells
    centres = np.array(ndimage.center_of_mass(d.height_mm > 0, labels, range(1, n + 1))) * d.pixel_mm
    assert np.allclose(np.unique(np.round(centres[:, 1], 6)), [1.0, 3.0, 5.0], atol=0.03)  # x, mm from the corner
    assert np.allclose(np.unique(np.round(centres[:, 0], 6)), [1.0, 3.0], atol=0.03)
    area = (labels == 1).sum() * d.pixel_mm ** 2
    assert area == pytest.approx(np.pi * 0.25, rel=0.03)


def test_letters_emboss_the_font_upright_and_left_to_right():
    s = letters("L7", height_mm=7.0, relief_mm=0.2, pixel_mm=1.0)  # one pixel a cell
    image = s.height_mm[::-1] / 0.2  # back to reading order, top row first
    assert image.shape == (9, 13) and not s.periodic
    glyph = lambda c: np.array([[ch == "#" for ch in row] for row in FONT_5X7[c]], dtype=float)
    np.testing.assert_array_equal(image[1:8, 1:6], glyph("L"))
    np.testing.assert_array_equal(image[1:8, 7:12], glyph("7"))
    assert image[0].sum() == image[-1].sum() == image[:, 6].sum() == 0  # margins and the gap are blank
    assert s.height_at(-5.0, -3.0) == pytest.approx(0.2)  # L's foot: low left (-x, -y)
    fine = letters("l", height_mm=3.5, pixel_mm=0.1)
    assert fine.shape == (45, 35) and fine.length_mm == pytest.approx(4.5)
    assert all(len(rows) == 7 and all(len(r) == 5 for r in rows) for rows in FONT_5X7.values())


def test_a_bitmap_reads_as_printed():
    s = from_bitmap(np.array([[True, False, False], [False, False, True]]), pixel_mm=0.5, relief_mm=0.3)
    assert s.height_mm.tolist() == [[0.0, 0.0, 0.3], [0.3, 0.0, 0.0]]  # row 0: the image's bottom row
    assert s.height_at(-0.5, 0.25) == pytest.approx(0.3) and s.height_at(0.5, -0.25) == pytest.approx(0.3)
    assert s.height_at(0.5, 0.25) == 0.0 and s.height_at(-0.5, -0.25) == 0.0


def test_bilinear_sampling_interpolates_and_wraps():
    rng = np.random.default_rng(0)
    h = rng.uniform(0.0, 1.0, (6, 8))
    finite, tile = Surface(h, 0.25), Surface(h, 0.25, periodic=True)
    cx, cy = (np.arange(8) - 3.5) * 0.25, (np.arange(6) - 2.5) * 0.25
    xx, yy = np.meshgrid(cx, cy)
    np.testing.assert_allclose(finite.height_at(xx, yy), h)  # exact at pixel centres
    mid = finite.height_at(cx[2] + 0.125, cy[3] + 0.125)
    assert mid == pytest.approx(h[3:5, 2:4].mean())  # the centre of four pixels is their mean
    plane = Surface(np.add.outer(0.1 * np.arange(6), 0.2 * np.arange(8)), 0.25)
    x, y = rng.uniform(-0.8, 0.8, 50), rng.uniform(-0.6, 0.6, 50)
    np.testing.assert_allclose(plane.height_at(x, y), 0.1 * (y / 0.25 + 2.5) + 0.2 * (x / 0.25 + 3.5))  # planes exact
    x, y = rng.uniform(-5, 5, 50), rng.uniform(-5, 5, 50)
    np.testing.assert_allclose(tile.height_at(x + 3 * tile.width_mm, y - 2 * tile.length_mm), tile.height_at(x, y))
    assert np.all(finite.height_at([10.0, -1.25], [0.0, 0.0]) == 0.0)  # flat beyond a finite surface's edge
    assert finite.height_at(cx[-1] + 0.125, cy[0]) == pytest.approx(h[0, -1] / 2)  # half-way off its edge


@pytest.mark.parametrize(("make", "message"), [
    (lambda: grating(0.33), r"period_mm=0.33 mm must be a whole number \(>= 2\) of pixels of pixel_mm=0.05"),
    (lambda: grating(1.0, ridge_mm=1.0), r"ridge_mm=1.0 mm must be less than period_mm=1.0"),
    (lambda: grating(1.0, height_mm=-0.5), r"height_mm must be a finite number > 0"),
    (lambda: dot_pattern(1.0, 0.5), r"dot_radius_mm=0.5 mm is too large for spacing_mm=1.0"),
    (lambda: dot_pattern(0.05), r"spacing_mm=0.05 mm must be a whole number \(>= 2\)"),
    (lambda: letters("A?"), r"text='A\?' must hold letters A-Z, digits 0-9 .* unknown: '\?'"),
    (lambda: letters("  "), r"text='  ' must hold .* got none"),
    (lambda: letters(5), r"text must be a str, got int"),
    (lambda: letters("A", height_mm=0.5, pixel_mm=0.1), r"pixel_mm=0.1 mm is coarser than a glyph cell"),
    (lambda: from_bitmap([[0, 2]], 0.1, 0.5), r"array must hold values in \[0, 1\]"),
    (lambda: from_bitmap([0, 1], 0.1, 0.5), r"array must be 2-D"),
    (lambda: Surface(np.array([[0.0, -0.1]]), 0.1), r"height_mm must be >= 0 mm .* -0.1 at row 0, column 1"),
    (lambda: Surface(np.ones((2, 2)), 0.1, periodic="no"), r"periodic must be True or False, got str"),
    (lambda: Surface(np.ones((2, 2)), 0.0), r"pixel_mm must be a finite number > 0"),
    (lambda: Surface(np.zeros((0, 3)), 0.1), r"height_mm must hold at least one pixel, got shape \(0, 3\)"),
    (lambda: grating(1.0, width_mm=0.0), r"width_mm must be a finite number > 0"),
    (lambda: grating(1.0, length_mm=-1.0), r"length_mm must be a finite number > 0"),
    (lambda: dot_pattern(1.0, 0.3, height_mm=0.0), r"height_mm must be a finite number > 0"),
    (lambda: dot_pattern(1.0, -0.3), r"dot_radius_mm must be a finite number > 0"),
    (lambda: from_bitmap([[0, 1]], 0.1, 0.0), r"relief_mm must be a finite number > 0"),
    (lambda: from_bitmap([[0, 1]], -0.1, 0.5), r"pixel_mm must be a finite number > 0"),
    (lambda: letters("A", height_mm=0.0), r"height_mm must be a finite number > 0"),
])
def test_bad_input_is_refused_by_name(make, message):
    with pytest.raises((ValueError, TypeError), match=message) as info:
        make()
    assert "\n" not in str(info.value)
