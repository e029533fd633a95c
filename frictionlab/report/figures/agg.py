"""The Agg canvas of the report's figures (``base.figure``): its renderer keeps, for this thread until ``release``,
what matplotlib's Agg renderer works out anew for each renderer (a new one at each figure size) or each draw of a
text: a string's size and glyph layout, a font's line metrics, and each glyph's bitmap at each phase of its origin.
They depend only on the string, the font properties, the DPI, the angle and the hinting.

Plain text is drawn glyph by glyph as matplotlib 3.11 draws it, except that each glyph's origin (matplotlib's, in
1/64 pixel) is rounded to a multiple of ``STEP`` = 16, a quarter pixel (halves up): each glyph sits at most 1/8 pixel
from matplotlib's place in x and in y, drawn as FreeType renders it there. All else (mathtext, TeX, text with another
matplotlib, everything but text) has matplotlib's own pixels."""
from __future__ import annotations

import math
import os
import threading

import matplotlib
import numpy as np
from matplotlib import rcParams
from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg, get_hinting_flag
from matplotlib.ft2font import FT2Font

_KEPT = threading.local()
#: glyphs drawn here as matplotlib 3.11 draws them (it lays out a string with FT2Font._layout); with another
#: matplotlib, RendererAgg draws them as it does
_LAYOUT = hasattr(FT2Font, "_layout") and tuple(matplotlib.__version_info__[:2]) == (3, 11)
if _LAYOUT:
    from matplotlib.ft2font import RenderMode

    _MODES = {True: RenderMode.NORMAL, False: RenderMode.MONO}


def release() -> None:
    """Let go of this thread's kept text measures."""
    _KEPT.__dict__.clear()


# A forked worker lets go of them too: the kept layouts and glyphs hold the parent's fonts, which read their files
# through descriptors the processes share (matplotlib's own font cache is cleared at a fork for the same reason).
if hasattr(os, "register_at_fork"):  # (not on Windows, which does not fork)
    os.register_at_fork(after_in_child=release)


#: Grid of glyph origins in 1/64 pixel (a quarter pixel): 4 x 4 phases of a glyph's bitmap, not 64 x 64
STEP = 16

#: Entries of each kind kept at most (a report keeps a few thousand glyphs); beyond, all are let go.
MEMO = 1 << 16


def _kept() -> tuple[dict, dict, dict, dict]:
    """(text sizes, glyph layouts, line metrics, glyph bitmaps) of this thread."""
    k = _KEPT.__dict__
    if "sizes" not in k or any(len(d) > MEMO for d in k.values()):
        k["sizes"], k["layouts"], k["lines"], k["glyphs"] = {}, {}, {}, {}
    return k["sizes"], k["layouts"], k["lines"], k["glyphs"]


def _font(prop) -> tuple:
    """What FontProperties compares (its ``__eq__`` is its hash's tuple): a key that does not change with it."""
    return (tuple(prop.get_family()), prop.get_slant(), prop.get_variant(), prop.get_weight(), prop.get_stretch(),
            prop.get_size(), prop.get_file(), prop.get_math_fontfamily())


def _hinting() -> tuple:
    return rcParams["text.hinting"], rcParams["text.hinting_factor"], rcParams["text.kerning_factor"]


class Renderer(RendererAgg):
    """RendererAgg with this thread's kept text measures (plain text; mathtext and TeX as RendererAgg has them)."""

    def get_text_width_height_descent(self, s, prop, ismath):
        if ismath:
            return super().get_text_width_height_descent(s, prop, ismath)
        sizes = _kept()[0]
        key = (s, _font(prop), self.dpi, _hinting())
        got = sizes.get(key)
        if got is None:
            got = sizes[key] = super().get_text_width_height_descent(s, prop, ismath)
        return got

    def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
        if ismath or not _LAYOUT:
            return super().draw_text(gc, x, y, s, prop, angle, ismath, mtext)
        features = mtext.get_fontfeatures() if mtext is not None else None
        language = mtext.get_language() if mtext is not None else None
        if not isinstance(features, (tuple, type(None))) or not isinstance(language, (str, type(None))):
            return super().draw_text(gc, x, y, s, prop, angle, ismath, mtext)
        layouts = _kept()[1]
        key = (s, _font(prop), self.dpi, _hinting(), features, language)
        items = layouts.get(key)
        if items is None:  # RendererAgg.draw_text's layout of the string's glyphs
            font = self._prepare_font(prop)
            items = layouts[key] = [(i.ft_object, i.glyph_index, i.x, i.y) for i in font._layout(
                s, flags=get_hinting_flag(), features=features, language=language)]
        self._glyphs(gc, x, y, angle, prop.get_size_in_points(), items)

    def _glyphs(self, gc, x, y, angle, size, items) -> None:
        """RendererAgg._draw_text_glyphs_and_boxes for the glyphs ``items`` of plain text (no slant, no stretch),
        each glyph's origin rounded to a multiple of ``STEP`` and its bitmap rendered once for each phase: moved by
        whole pixels, FreeType renders the same bitmap moved by as many pixels."""
        glyphs = _kept()[3]
        cos, sin = math.cos(math.radians(angle)), math.sin(math.radians(angle))
        matrix = (0x10000 * np.array([[cos, -sin], [sin, cos]])).round().astype(int)
        flags, aa = get_hinting_flag(), gc.get_antialiased()
        turn = (*matrix.ravel().tolist(), self.dpi, flags, aa, size)
        height = self.height
        half = STEP // 2
        for font, index, dx, dy in items:  # dy is upwards; FreeType's y is upwards, the renderer's downwards
            ox = (round(0x40 * (x + dx * cos - dy * sin)) + half) // STEP * STEP
            oy = (round(0x40 * (height - y + dx * sin + dy * cos)) + half) // STEP * STEP
            key = (font, index, turn, ox & 0x3f, oy & 0x3f)
            got = glyphs.get(key)
            if got is None:
                font.set_size(size, self.dpi)
                font._set_transform(matrix, [ox, oy])
                bitmap = font._render_glyph(index, flags, _MODES[aa])
                buffer = bitmap.buffer
                if not aa:
                    buffer *= 0xff
                got = glyphs[key] = (buffer, bitmap.left - (ox >> 6), bitmap.top - (oy >> 6))
            buffer, left, top = got
            self._renderer.draw_text_image(buffer, left + (ox >> 6), int(height) - top - (oy >> 6) + buffer.shape[0],
                                           0, gc)

    def _get_font_height_metrics(self, prop):
        """(ascent, descent, line gap) in pixels of the font of ``prop`` from its tables, as ``Text`` works them
        out without this method (at its figure's DPI: the renderer's); (None, None, None) without the tables."""
        lines = _kept()[2]
        key = (_font(prop), self.dpi, _hinting())
        got = lines.get(key)
        if got is None:
            got = lines[key] = _line_metrics(prop, self.dpi)
        return got


def _line_metrics(prop, dpi: float) -> tuple:
    from matplotlib.font_manager import fontManager, get_font

    font = get_font(fontManager._find_fonts_by_props(prop))
    for table_name, gap, ascent, descent in (("OS/2", "sTypoLineGap", "sTypoAscender", "sTypoDescender"),
                                             ("hhea", "lineGap", "ascent", "descent")):
        table = font.get_sfnt_table(table_name)
        if table is not None:
            scale = 1 / font.get_sfnt_table("head")["unitsPerEm"] * prop.get_size_in_points() * dpi / 72
            return table[ascent] * scale, -table[descent] * scale, table[gap] * scale
    return None, None, None


class Canvas(FigureCanvasAgg):
    """FigureCanvasAgg drawing with ``Renderer``."""

    def get_renderer(self):
        w, h = self.get_width_height(physical=True)
        key = w, h, self.figure.dpi
        if self._lastKey != key:
            self.renderer = Renderer(w, h, self.figure.dpi)
            self._lastKey = key
        return self.renderer
