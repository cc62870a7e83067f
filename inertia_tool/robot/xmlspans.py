"""Exact character offsets of the elements of an XML document, for edits that keep every other byte.

lxml tells where an element starts only as a line number, so an edit of the original text needs a tokenizer
of its own.  This one follows the XML 1.0 grammar closely enough to find every start tag, end tag and
empty-element tag of a well-formed document, skipping what can hide a ``<`` or a ``>``:

* comments ``<!-- … -->``, CDATA sections ``<![CDATA[ … ]]>``, processing instructions (and the XML
  declaration) ``<? … ?>``;
* the document type declaration with its internal subset: markup declarations (``<!ENTITY``, ``<!ELEMENT``,
  ``<!ATTLIST``, ``<!NOTATION``) whose quoted literals may hold ``>`` and ``]``, comments and PIs in the subset,
  parameter-entity references;
* attribute values in either quote holding ``>`` or the other quote; whitespace before ``>``, ``/>`` and in
  end tags (``</inertial >``).

Entity references stay references (as in lxml without entity expansion): elements declared inside an
entity's replacement text are not elements of the document's own text.  The tokenizer expects a document
lxml has already accepted; whatever it does not understand is :class:`XMLSpanError`, never a guess, and the
caller checks its element list against lxml's tree before using it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import InertiaToolError

__all__ = ["ElementSpan", "XMLSpanError", "element_spans", "DocumentText", "decode_document"]


class XMLSpanError(InertiaToolError, ValueError):
    """The text is not XML this tokenizer can follow (expected: a document lxml parsed)."""


@dataclass(frozen=True, slots=True)
class ElementSpan:
    """Where one element is written in the text (offsets into the ``str``, end offsets exclusive).

    Attributes
    ----------
    tag : str
        The name as written (with its prefix, if any).
    start : int
        Offset of the ``<`` of its start tag.
    start_end : int
        Offset just after the ``>`` of its start tag (of the whole element for ``<a/>``).
    close : int
        Offset of the ``<`` of its end tag (``start_end`` for ``<a/>``).
    end : int
        Offset just after the ``>`` of its end tag (``start_end`` for ``<a/>``).
    depth : int
        0 for the root element.
    """

    tag: str
    start: int
    start_end: int
    close: int
    end: int
    depth: int

    @property
    def empty(self) -> bool:
        """Written as one empty-element tag ``<a …/>`` (not ``<a></a>``)."""
        return self.end == self.start_end


#: XML's whitespace (production S): only these four, not Python's Unicode ``\s`` (U+1680 may be in a name).
_S = "[ \t\r\n]"
_NAME = re.compile(r"[^ \t\r\n<>/=\"'!?&;]+")
_SUBSET_END = re.compile(rf"\]{_S}*>")
_ATTRIBUTE = re.compile(rf"{_S}+([^ \t\r\n<>/=\"']+){_S}*={_S}*(?:\"[^\"<]*\"|'[^'<]*')")
_CLOSE_START = re.compile(rf"{_S}*(/?)>")
_END_TAG = re.compile(rf"</([^ \t\r\n<>/=\"']+){_S}*>")


def _skip_past(text: str, pos: int, marker: str, what: str) -> int:
    """Offset just after the next ``marker`` from ``pos``."""
    found = text.find(marker, pos)
    if found < 0:
        raise XMLSpanError(f"{what} opened at offset {pos} is not closed by {marker!r}")
    return found + len(marker)


def _skip_declaration(text: str, pos: int) -> int:
    """``pos`` at ``<!`` of a markup declaration in the internal subset; returns the offset after its ``>``
    (quoted literals may hold ``>``)."""
    i = pos + 2
    n = len(text)
    while i < n:
        c = text[i]
        if c in "\"'":
            i = _skip_past(text, i + 1, c, "a quoted literal")
            continue
        if c == ">":
            return i + 1
        i += 1
    raise XMLSpanError(f"the markup declaration at offset {pos} is not closed by '>'")


def _skip_doctype(text: str, pos: int) -> int:
    """``pos`` at ``<!DOCTYPE``; returns the offset after the declaration's final ``>``."""
    i = pos + len("<!DOCTYPE")
    n = len(text)
    while i < n:                        # name and external id, up to '[' or '>'
        c = text[i]
        if c in "\"'":
            i = _skip_past(text, i + 1, c, "a quoted literal")
        elif c == ">":
            return i + 1
        elif c == "[":
            i += 1
            break
        else:
            i += 1
    else:
        raise XMLSpanError(f"the DOCTYPE at offset {pos} is not closed")
    while i < n:                        # the internal subset, up to ']'
        while i < n and text[i] in " \t\r\n":
            i += 1
        if text.startswith("]", i):
            m = _SUBSET_END.match(text, i)
            if m is None:
                raise XMLSpanError(f"the DOCTYPE's internal subset at offset {i} is not closed by ']>'")
            return m.end()
        if text.startswith("<!--", i):
            i = _skip_past(text, i + 4, "-->", "a comment")
        elif text.startswith("<?", i):
            i = _skip_past(text, i + 2, "?>", "a processing instruction")
        elif text.startswith("<!", i):
            i = _skip_declaration(text, i)
        elif text.startswith("%", i):
            i = _skip_past(text, i + 1, ";", "a parameter-entity reference")
        else:
            raise XMLSpanError(f"unexpected {text[i:i + 10]!r} at offset {i} in the DOCTYPE's internal subset")
    raise XMLSpanError(f"the DOCTYPE at offset {pos} is not closed")


def element_spans(text: str, *, max_depth: int = 10_000) -> list[ElementSpan]:
    """Every element of the document ``text``, in document order (the order of ``root.iter()``).

    Parameters
    ----------
    text : str
        The decoded document (a BOM, if any, removed).
    max_depth : int
        Nesting beyond this is refused (lxml refuses beyond 256 without ``huge_tree``).

    Returns
    -------
    list of ElementSpan

    Raises
    ------
    XMLSpanError
        Markup this tokenizer cannot follow, or an end tag that does not match its start tag.
    """
    spans: list[ElementSpan | None] = []
    open_elements: list[tuple[str, int, int, int]] = []       # (tag, start, start_end, index in spans)
    i = 0
    while True:
        lt = text.find("<", i)
        if lt < 0:
            break
        if text.startswith("<!--", lt):
            i = _skip_past(text, lt + 4, "-->", "a comment")
        elif text.startswith("<![CDATA[", lt):
            i = _skip_past(text, lt + 9, "]]>", "a CDATA section")
        elif text.startswith("<?", lt):
            i = _skip_past(text, lt + 2, "?>", "a processing instruction")
        elif text.startswith("<!DOCTYPE", lt):
            if spans:
                raise XMLSpanError(f"a DOCTYPE at offset {lt} after the root element")
            i = _skip_doctype(text, lt)
        elif text.startswith("</", lt):
            m = _END_TAG.match(text, lt)
            if m is None or not open_elements or open_elements[-1][0] != m.group(1):
                expected = f"</{open_elements[-1][0]}>" if open_elements else "no end tag"
                raise XMLSpanError(f"end tag at offset {lt} does not match: expected {expected}, found "
                                   f"{text[lt:lt + 40]!r}")
            tag, start, start_end, index = open_elements.pop()
            spans[index] = ElementSpan(tag, start, start_end, lt, m.end(), len(open_elements))
            i = m.end()
        else:
            name = _NAME.match(text, lt + 1)
            if name is None:
                raise XMLSpanError(f"unexpected {text[lt:lt + 10]!r} at offset {lt}")
            j = name.end()
            while True:
                attribute = _ATTRIBUTE.match(text, j)
                if attribute is None:
                    break
                j = attribute.end()
            close = _CLOSE_START.match(text, j)
            if close is None:
                raise XMLSpanError(f"the start tag at offset {lt} is not closed where expected: "
                                   f"{text[j:j + 20]!r}")
            if close.group(1):
                spans.append(ElementSpan(name.group(0), lt, close.end(), close.end(), close.end(),
                                         len(open_elements)))
            else:
                if len(open_elements) >= max_depth:
                    raise XMLSpanError(f"elements nested more than {max_depth} deep")
                open_elements.append((name.group(0), lt, close.end(), len(spans)))
                spans.append(None)
            i = close.end()
    if open_elements:
        raise XMLSpanError(f"<{open_elements[-1][0]}> at offset {open_elements[-1][1]} is not closed")
    result = [s for s in spans if s is not None]
    if len(result) != len(spans):           # cannot happen: every open element was closed above
        raise XMLSpanError("an element was left without an end")
    return result


# -- the document's encoding ---------------------------------------------------------------------------------

_BOMS = ((b"\xef\xbb\xbf", "utf-8"), (b"\xff\xfe\x00\x00", "utf-32-le"), (b"\x00\x00\xfe\xff", "utf-32-be"),
         (b"\xff\xfe", "utf-16-le"), (b"\xfe\xff", "utf-16-be"))
_UNMARKED = ((b"<\x00\x00\x00", "utf-32-le"), (b"\x00\x00\x00<", "utf-32-be"), (b"<\x00?\x00", "utf-16-le"),
             (b"\x00<\x00?", "utf-16-be"))
_DECLARED = re.compile(r"<\?xml\s[^>]*?\bencoding\s*=\s*([\"'])([A-Za-z][A-Za-z0-9._\-]*)\1")


@dataclass(frozen=True)
class DocumentText:
    """A document's bytes as text, and how to turn text back into the same bytes.

    Attributes
    ----------
    bom : bytes
        The byte order mark the file starts with (``b""`` for none).
    codec : str
        The Python codec of the bytes after the BOM (the BOM's, else the declared one, else UTF-8).
    text : str
        The decoded document without its BOM.
    """

    bom: bytes
    codec: str
    text: str

    def encode(self, text: str) -> bytes:
        """``text`` (a piece of the document) in the document's encoding, without BOM.

        Raises
        ------
        UnicodeEncodeError
            A character the encoding cannot represent.
        """
        return text.encode(self.codec)


def decode_document(data: bytes) -> DocumentText:
    """Decode an XML document the way XML 1.0 Appendix F says a parser detects its encoding.

    The BOM decides (UTF-8, UTF-16, UTF-32); without one, the first bytes ``<?`` in a 2- or 4-byte encoding
    decide the UTF-16/32 byte order; otherwise the declaration's ``encoding`` names it (default UTF-8).

    Raises
    ------
    XMLSpanError
        An encoding Python does not know, or bytes that are not valid in it.
    """
    import codecs
    bom, codec = b"", ""
    for mark, name in _BOMS:
        if data.startswith(mark):
            bom, codec = mark, name
            break
    else:
        for mark, name in _UNMARKED:
            if data.startswith(mark):
                codec = name
                break
    if not codec:
        declared = _DECLARED.match(data[:200].decode("latin-1"))
        codec = declared.group(2) if declared else "utf-8"
    try:
        codec = codecs.lookup(codec).name
        text = data[len(bom):].decode(codec)
    except LookupError:
        raise XMLSpanError(f"the declared encoding {codec!r} is not one Python can decode") from None
    except UnicodeDecodeError as exc:
        raise XMLSpanError(f"the bytes are not valid {codec} (offset {exc.start})") from None
    return DocumentText(bom, codec, text)
