"""One escaping helper per output format, for text that comes from outside (file names, part names, notes).

Every writer puts foreign text into its document through these, never raw: a file named
``<script>alert(1)</script>|x.stl`` must show as those characters, not run or break a table.
"""

from __future__ import annotations

import re

__all__ = ["escape_html", "escape_markdown", "escape_terminal"]

# C0 controls but tab and newline, DEL, C1 controls (U+009B is a one-character CSI on some terminals), the
# Unicode line and paragraph separators and the bidirectional embeddings, overrides and isolates (which reorder
# what a reader sees)
_TERMINAL_UNSAFE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")

# CommonMark lets any ASCII punctuation be backslash-escaped; these are the ones that mean something in the
# middle of a line (the writers never put foreign text at the start of one): emphasis, code spans, links and
# images (a ``(`` only after a ``]``), GFM tables and strike-through, a heading's closing ``#`` sequence
_MARKDOWN_SPECIAL = frozenset("\\`*_[]|~#")


def escape_html(text: object) -> str:
    """``text`` as HTML/XML character data or a quoted attribute value (``& < > " '`` escaped)."""
    import html         # imported on use: the command line escapes for the terminal only, unless it writes HTML
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


def escape_terminal(text: object, *, lines: bool = False) -> str:
    """``text`` safe to print on a terminal: every control character becomes its visible ``\\uXXXX`` escape.

    Escaped: C0 controls (ESC starts the sequences that move the cursor, recolour, retitle the window or
    rewrite what was printed), DEL, C1 controls, U+2028/U+2029 and the bidirectional controls.  With ``lines``
    newlines and tabs are kept (a whole report); without, they are escaped too (a file name on one line).
    The escape is also a valid JSON string escape of the same character, so JSON output stays valid and
    decodes to the original name.
    """
    out = _TERMINAL_UNSAFE.sub(lambda m: f"\\u{ord(m.group(0)):04x}", str(text))
    if not lines:
        out = out.replace("\n", "\\u000a").replace("\t", "\\u0009")
    return out
