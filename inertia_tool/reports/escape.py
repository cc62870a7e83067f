"""One escaping helper per output format, for text that comes from outside (file names, part names, notes).

Every writer puts foreign text into its document through these, never raw: a file named
``<script>alert(1)</script>|x.stl`` must show as those characters, not run or break a table.
"""

from __future__ import annotations

import html

__all__ = ["escape_html", "escape_markdown"]

# CommonMark lets any ASCII punctuation be backslash-escaped; these are the ones that mean something in the
# middle of a line (the writers never put foreign text at the start of one): emphasis, code spans, links and
# images (a ``(`` only after a ``]``), GFM tables and strike-through, a heading's closing ``#`` sequence
_MARKDOWN_SPECIAL = frozenset("\\`*_[]|~#")


def escape_html(text: object) -> str:
    """``text`` as HTML/XML character data or a quoted attribute value (``& < > " '`` escaped)."""
    return html.escape(str(text), quote=True)


def escape_markdown(text: object) -> str:
    """``text`` as literal inline Markdown (CommonMark with GFM tables), on one line.

    ``& < >`` become character references (no raw HTML can pass), Markdown punctuation is backslash-escaped
    (``|`` included, so a table cell stays one cell), and line breaks become spaces (a break would end a
    table row or a heading).
    """
    out = []
    for ch in " ".join(str(text).splitlines()):
        if ch in "&<>":
            out.append({"&": "&amp;", "<": "&lt;", ">": "&gt;"}[ch])
        elif ch in _MARKDOWN_SPECIAL:
            out.append("\\" + ch)
        else:
            out.append(ch)
    return "".join(out)
