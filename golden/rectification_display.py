"""Golden model of the rectification text on screen (docs/display.md, "Rectification text"), from the spec.

:func:`rectification_text`: "rect", the signed offset in use as ``f"{r:+3d}"``, the mode word
(``spec.display.RECTIFICATION_MODES``: hand, auto, held). Only constants come from ``spec``.
"""

from spec.display import RECTIFICATION_MODES, RECTIFICATION_TEXT

__all__ = ["rectification_text"]


def rectification_text(offset, auto, held):
    """The text of the rectification ``offset`` in use (buffer rows, -99..99) in automatic mode or not, with the
    estimator's ``held`` verdict (shown only in automatic mode). ``ValueError`` for an offset out of range."""
    if not -99 <= offset <= 99:
        raise ValueError(f"a rectification of {offset} rows has no text (-99..99)")
    hand, automatic, kept = RECTIFICATION_MODES
    text = f"rect {offset:+3d} {(kept if held else automatic) if auto else hand}"
    assert len(text) == len(RECTIFICATION_TEXT)
    return text
