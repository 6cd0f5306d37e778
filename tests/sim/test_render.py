"""Drawing helpers: frame labels placed so that none covers another."""

from __future__ import annotations

import itertools

import pytest

from rosl.sim.render import LABEL_GAP, LABEL_OFFSET, Scene, place_labels, svg


def overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def assert_apart(boxes, sizes) -> None:
    for box, (width, height) in zip(boxes, sizes, strict=True):
        assert box[2] - box[0] == pytest.approx(width)
        assert box[3] - box[1] == pytest.approx(height)
    for a, b in itertools.combinations(boxes, 2):
        assert not overlap(a, b), (a, b)


def test_a_lone_label_sits_below_right_of_its_anchor() -> None:
    (box,) = place_labels([(100.0, 50.0)], [(40.0, 13.0)])

    assert box == (100 + LABEL_OFFSET, 50 + LABEL_OFFSET, 140 + LABEL_OFFSET, 63 + LABEL_OFFSET)


def test_labels_of_frames_at_one_spot_do_not_overlap() -> None:
    anchors = [(200.0, 200.0)] * 3  # Dolly standing still: its pose, chassis and odom_demo
    sizes = [(110.0, 13.0), (50.0, 13.0), (70.0, 13.0)]

    boxes = place_labels(anchors, sizes)

    assert_apart(boxes, sizes)
    for left, top, right, bottom in boxes:  # the four places around the anchor come first
        assert min(abs(left - 200), abs(right - 200)) == pytest.approx(LABEL_OFFSET)
        assert min(abs(top - 200), abs(bottom - 200)) == pytest.approx(LABEL_OFFSET)


def test_many_close_labels_are_stacked_apart() -> None:
    anchors = [(300.0 + k, 300.0 + 0.5 * k) for k in range(12)]
    sizes = [(60.0 + 5 * k, 13.0) for k in range(12)]

    boxes = place_labels(anchors, sizes)

    assert_apart(boxes, sizes)
    for a, b in itertools.combinations(boxes, 2):  # the gap between labels is kept too
        apart_x = max(a[0] - b[2], b[0] - a[2])
        apart_y = max(a[1] - b[3], b[1] - a[3])
        assert max(apart_x, apart_y) >= LABEL_GAP - 1e-9


def test_an_svg_with_frames_at_one_spot_writes_their_labels_at_different_places() -> None:
    scene = Scene(title="t", frame="odom_demo")
    scene.frames = [("/dolly/odom pose", (0.0, 0.0), 0.0), ("chassis", (0.0, 0.0), 0.0),
                    ("odom_demo", (0.0, 0.0), 0.0)]  # fmt: skip

    text = svg(scene)

    places = [line.split(' font-family')[0] for line in text.splitlines()
              if line.startswith("<text x=") and 'font-size="11"' in line]  # fmt: skip
    assert len(places) == 3
    assert len(set(places)) == 3
