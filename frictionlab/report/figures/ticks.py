"""Each axis' ticks and each legend's layout worked out once while a figure does not change. matplotlib works out
an axis' ticks (``Axis._update_ticks``: locations, label texts, which are in view) and their labels' boxes
(``Axis._get_ticklabel_bboxes``) anew each time it draws or measures the axis, the axis label, the spine or an
axes title: three to six times for one axis in one draw. A legend's boxes (``OffsetBox._get_bbox_and_child_offsets``
of its packers) are laid out anew by every box above them that measures, places or draws them: once per level of
nesting above. Inside ``same(fig)`` (nothing changes the figure's limits, sizes, ticks, texts or legends
meanwhile: one draw, one measurement) each axis and each legend box of ``fig`` computes them once."""
from __future__ import annotations

import contextlib
import threading
import types

import matplotlib
from matplotlib.offsetbox import OffsetBox

_KEPT = threading.local()
#: the matplotlib versions whose Axis._update_ticks and _get_ticklabel_bboxes this follows
SUPPORTED = (3, 7) <= tuple(matplotlib.__version_info__[:2]) <= (3, 11)


@contextlib.contextmanager
def same(fig):
    """Within: each axis of ``fig``'s axes works out its ticks and tick-label boxes once (for each renderer); with a
    matplotlib other than the ones whose Axis methods this follows (3.7 to 3.11), as matplotlib does. A window
    opened inside another keeps the outer one's results: nothing changes meanwhile there either."""
    if not SUPPORTED:
        yield
        return
    for ax in fig.axes:
        for axis in ax._axis_map.values():
            if "_update_ticks" not in vars(axis):
                axis._update_ticks = types.MethodType(_update_ticks, axis)
                axis._get_ticklabel_bboxes = types.MethodType(_get_ticklabel_bboxes, axis)
    for legend in [*fig.legends, *(ax.get_legend() for ax in fig.axes)]:
        if legend is not None:
            _laid_out_once(legend._legend_box)
    outer = getattr(_KEPT, "memo", None)
    if outer is None:
        _KEPT.memo = {}
    try:
        yield
    finally:
        _KEPT.memo = outer


def _update_ticks(axis):
    memo = getattr(_KEPT, "memo", None)
    if memo is None:
        return type(axis)._update_ticks(axis)
    key = ("ticks", axis)
    if key not in memo:
        memo[key] = type(axis)._update_ticks(axis)
    return list(memo[key])


def _get_ticklabel_bboxes(axis, ticks, renderer):
    memo = getattr(_KEPT, "memo", None)
    if memo is None or renderer is None:
        return type(axis)._get_ticklabel_bboxes(axis, ticks, renderer)
    key = ("boxes", axis, renderer, *ticks)
    if key not in memo:
        memo[key] = type(axis)._get_ticklabel_bboxes(axis, ticks, renderer)
    one, two = memo[key]
    return list(one), list(two)


def _laid_out_once(box) -> None:
    """Give ``box`` and the boxes inside it that lay out children (the packers) the kept layout."""
    if "_get_bbox_and_child_offsets" not in vars(box) and "_get_bbox_and_child_offsets" in vars(type(box)):
        box._get_bbox_and_child_offsets = types.MethodType(_get_bbox_and_child_offsets, box)
    for child in box.get_children():
        if isinstance(child, OffsetBox):
            _laid_out_once(child)


def _get_bbox_and_child_offsets(box, renderer):
    memo = getattr(_KEPT, "memo", None)
    if memo is None:
        return type(box)._get_bbox_and_child_offsets(box, renderer)
    key = ("layout", box, renderer, getattr(box, "width", None), getattr(box, "height", None))
    if key not in memo:
        memo[key] = type(box)._get_bbox_and_child_offsets(box, renderer)
    bbox, offsets = memo[key]
    return bbox.frozen(), list(offsets)
