"""A copy of a robot description with corrected ``<inertial>`` elements, everything else left as it was.

Only the inertial of each link with a geometry result is touched: its origin moves to the centre of mass, its
orientation is the link frame (**rpy 0**, MJCF: no ``quat``) and the **full tensor** is written (products of
inertia in the tensor convention, ``ixy = −∫xy dm``, which URDF, SDFormat and MuJoCo's ``fullinertia`` use).
The new element is built on the lxml tree of the description and its text is spliced into the input's bytes
in place of the old element (or inserted where there was none: last in a URDF/SDF link, first in an MJCF
body), so every other byte — declaration, comments, indentation, attribute order and quoting — is the
input's.  One comment after the root's start tag says which links were recomputed and from what.  (If the
elements cannot be matched to the text — a non-UTF-8 encoding, entities — the whole tree is serialised by
lxml instead, which keeps all of that except the spelling of a few tags and quotes.)

The file is written atomically (a temporary file beside it, then ``os.replace``) and never over an
existing file (including the input) unless ``force``.  For xacro input the *expanded* URDF is written.
"""

from __future__ import annotations

import os
import re

import numpy as np

from ..errors import UsageError
from .description import RobotDescription, parse_xml

__all__ = ["write_corrected", "corrected_document"]

_ORIENTATION_KEYS = ("quat", "axisangle", "euler", "xyaxes", "zaxis", "diaginertia", "fullinertia")


def _num(x: float) -> str:
    """Shortest text that reads back to the same float (``repr``); ``-0`` prints as ``0``."""
    return repr(float(x) + 0.0)


def _clean(props):
    """Round-off, not data: products below 1e-12 of the largest moment and COM coordinates below 1e-12 of the
    body size become 0."""
    tensor = np.array(props.inertia, dtype=float)
    scale = float(np.max(np.abs(np.diag(tensor))))
    off = ~np.eye(3, dtype=bool)
    tensor[off & (np.abs(tensor) <= 1e-12 * scale)] = 0.0
    com = np.array(props.center_of_mass, dtype=float)
    size = float(np.max(np.abs(com))) + float(np.sqrt(max(scale, 0.0) / props.mass))
    com[np.abs(com) <= 1e-12 * size] = 0.0
    return com, tensor


def _whitespace_before(element) -> str | None:
    """The whitespace text right before ``element`` (its parent's text or its previous sibling's tail)."""
    prev = element.getprevious()
    text = prev.tail if prev is not None else element.getparent().text if element.getparent() is not None else None
    return text if text is not None and not text.strip() else None


def _layout(element) -> tuple[str, str]:
    """``(own, step)``: the newline-and-indentation before ``element`` and one indentation step of the file."""
    own = (_whitespace_before(element) if element.getparent() is not None else None) or "\n"
    first = element[0] if len(element) else None
    inner = _whitespace_before(first) if first is not None else None
    if inner and inner.startswith(own) and len(inner) > len(own):
        return own, inner[len(own):]
    parent = element.getparent()
    return own, (_layout(parent)[1] if parent is not None else "  ")   # no children yet: the parent's step


def _child(parent, tag: str):
    """The first ``<tag>`` child of ``parent``, created last (indented like the file) if missing."""
    from lxml import etree
    found = parent.find(tag)
    if found is not None:
        return found
    own, step = _layout(parent)
    child = etree.SubElement(parent, tag)
    if len(parent) == 1:
        parent.text = own + step
    else:
        parent[-2].tail = own + step
    child.tail = own
    return child


def _urdf_inertial(link, props) -> None:
    com, t = _clean(props)
    inertial = _child(link, "inertial")
    origin = _child(inertial, "origin")
    origin.set("xyz", " ".join(_num(c) for c in com))
    origin.set("rpy", "0 0 0")
    _child(inertial, "mass").set("value", _num(props.mass))
    inertia = _child(inertial, "inertia")
    for key, (i, j) in (("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyy", (1, 1)), ("iyz", (1, 2)),
                        ("izz", (2, 2))):
        inertia.set(key, _num(t[i, j]))


def _sdf_inertial(link, props) -> None:
    com, t = _clean(props)
    inertial = _child(link, "inertial")
    pose = _child(inertial, "pose")
    pose.text = " ".join(_num(c) for c in com) + " 0 0 0"
    pose.attrib.pop("degrees", None)
    pose.attrib.pop("rotation_format", None)
    _child(inertial, "mass").text = _num(props.mass)
    inertia = _child(inertial, "inertia")
    for key, (i, j) in (("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyy", (1, 1)), ("iyz", (1, 2)),
                        ("izz", (2, 2))):
        _child(inertia, key).text = _num(t[i, j])


def _mjcf_inertial(body, props) -> None:
    from lxml import etree
    com, t = _clean(props)
    inertial = body.find("inertial")
    if inertial is None:
        own, step = _layout(body)
        inertial = etree.Element("inertial")
        inertial.tail = body.text if body.text is not None and not body.text.strip() and len(body) else own
        body.text = own + step
        body.insert(0, inertial)
    for key in _ORIENTATION_KEYS:
        inertial.attrib.pop(key, None)
    inertial.set("pos", " ".join(_num(c) for c in com))
    inertial.set("mass", _num(props.mass))
    inertial.set("fullinertia", " ".join(_num(v) for v in (t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2])))


def _links(root, fmt: str):
    """Link (URDF/SDF) or body (MJCF) elements by name, in document order."""
    if fmt in ("urdf", "xacro"):
        return {link.get("name"): link for link in root.findall("link")}
    if fmt == "sdf":
        models = root.findall("model") + root.findall("world/model")
        return {link.get("name"): link for link in models[0].findall("link")}
    bodies = {}
    for k, body in enumerate(root.iter("body")):
        bodies[body.get("name") or f"body {k + 1}"] = body
    return bodies


def corrected_document(robot: RobotDescription, inertials, *, note: str = "") -> bytes:
    """The description's bytes with the inertials of the links in ``inertials`` replaced.

    Only the bytes of each replaced ``<inertial>`` element change (a missing one is inserted), plus one
    provenance comment after the root's start tag; every other byte is the input's.  Where the elements cannot
    be matched to the text (an encoding other than UTF-8/ASCII, an entity that hides markup), the whole tree is
    serialised by lxml instead, which keeps comments, whitespace and attribute order but may normalise
    ``<a />`` to ``<a/>`` and the quotes.

    Parameters
    ----------
    robot : RobotDescription
        The description (its ``document`` is edited).
    inertials : sequence of LinkInertial
        Links with ``properties`` None are left untouched.
    note : str
        Appended to the provenance comment (e.g. the density basis).

    Returns
    -------
    bytes
        The corrected document.
    """
    from lxml import etree
    tree = parse_xml(robot.document, robot.source)
    root = tree.getroot()
    elements = _links(root, robot.format)
    writer = {"urdf": _urdf_inertial, "xacro": _urdf_inertial, "sdf": _sdf_inertial,
              "mjcf": _mjcf_inertial}[robot.format]
    before = list(root.iter("inertial"))
    changed = []
    for result in inertials:
        if result.properties is None or result.name not in elements:
            continue
        writer(elements[result.name], result.properties)
        changed.append(result.name)
    comment_text = (f" inertia-tool robot: <inertial> of {len(changed)} link{'s' if len(changed) != 1 else ''} "
                    f"recomputed from the {robot.geometry} "
                    f"geometry{' (' + note + ')' if note else ''}: origin at the centre of mass, axes of the link "
                    "frame (rpy 0), full tensor about the centre of mass, SI, ixy = -(integral of x*y dm) "
                    ).replace("--", "- -")
    spliced = _splice_text(robot, root, before, [elements[n] for n in changed], comment_text) if changed else None
    if spliced is not None:
        return spliced
    if changed:
        comment = etree.Comment(comment_text)
        comment.tail = root.text if root.text and not root.text.strip() else "\n"
        root.insert(0, comment)
        if root.text is None or root.text.strip():
            root.text = "\n"
    return _splice(robot.document, etree.tostring(root, encoding="utf-8"), root.tag)


_MARKUP_TO_HIDE = re.compile(r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>", re.DOTALL)


def _tag_spans(masked: str, tag: str) -> list:
    """``(start, end_of_start_tag, end)`` of every ``<tag>`` element in ``masked`` text (comments blanked);
    ``end`` is after ``</tag>`` or the self-closing ``/>`` (tags of this kind must not nest)."""
    spans = []
    for m in re.finditer(rf"<{tag}(?:\s(?:\"[^\"]*\"|'[^']*'|[^'\">])*)?/?>", masked):
        if m.group(0).endswith("/>"):
            spans.append((m.start(), m.end(), m.end()))
            continue
        close = masked.find(f"</{tag}>", m.end())
        if close < 0:
            return []
        spans.append((m.start(), m.end(), close + len(tag) + 3))
    return spans


def _line_indent(text: str, position: int) -> str:
    line_start = text.rfind("\n", 0, position) + 1
    prefix = text[line_start:position]
    return prefix if not prefix.strip() else ""


def _splice_text(robot: RobotDescription, root, before: list, links: list, comment_text: str) -> bytes | None:
    """Byte-preserving edit: replace/insert only the changed inertials; None when the text cannot be matched."""
    from lxml import etree
    try:
        text = robot.document.decode("utf-8")
    except UnicodeDecodeError:
        return None
    if "<!ENTITY" in text:
        return None
    masked = _MARKUP_TO_HIDE.sub(lambda m: " " * len(m.group(0)), text)
    inertial_spans = _tag_spans(masked, "inertial")
    container = "body" if robot.format == "mjcf" else "link"
    containers = list(root.iter(container))
    container_spans = _tag_spans(masked, container) if container == "link" else [
        (m.start(), m.end(), m.end()) for m in re.finditer(r"<body(?:\s(?:\"[^\"]*\"|'[^']*'|[^'\">])*)?>", masked)]
    if len(inertial_spans) != len(before) or len(container_spans) != len(containers):
        return None
    edits = []
    for element in links:
        inertial = element.find("inertial")
        serialized = etree.tostring(inertial, encoding="unicode", with_tail=False)
        if any(inertial is b for b in before):
            k = next(i for i, b in enumerate(before) if b is inertial)
            start, _, end = inertial_spans[k]
            edits.append((start, end, serialized))
            continue
        start, start_end, end = container_spans[next(i for i, c in enumerate(containers) if c is element)]
        before_it = _whitespace_before(inertial) or ""
        if container == "body":                 # MJCF: the inertial goes first, after the body's start tag
            edits.append((start_end, start_end, before_it + serialized))
            continue
        if start_end == end:                    # a self-closing link holds no geometry: never changed
            return None
        close = end - len(container) - 3        # at "</link>"
        closing_indent = _line_indent(text, close)
        if closing_indent and before_it.startswith("\n"):   # a line of its own, above "</link>"
            line_start = close - len(closing_indent)
            edits.append((line_start, line_start, before_it[1:] + serialized + "\n"))
        else:
            edits.append((close, close, serialized))
    root_start = _START_TAG_TEXT.match(masked, _prolog_end(masked))
    if root_start is None or root_start.group(0).endswith("/>"):
        return None
    edits.append((root_start.end(), root_start.end(),
                  f"\n{_first_child_indent(text, root_start.end())}<!--{comment_text}-->"))
    out = text
    for start, end, replacement in sorted(edits, key=lambda e: e[0], reverse=True):
        out = out[:start] + replacement + out[end:]
    return out.encode("utf-8")


def _prolog_end(masked: str) -> int:
    m = re.match(r"\s*(?:<!DOCTYPE[^>\[]*(?:\[.*?\])?\s*>\s*)?", masked, re.DOTALL)
    return m.end() if m else 0          # the pattern matches the empty string: m is never None


def _first_child_indent(text: str, position: int) -> str:
    """The indentation of the line after ``position`` (the root's first child), or two spaces."""
    m = re.match(r"[ \t]*\r?\n([ \t]*)", text[position:])
    return m.group(1) if m and m.group(1) else "  "


_PROLOG = re.compile(rb"(?:\s+|<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>\[]*(?:\[.*?\])?\s*>)*", re.DOTALL)


def _splice(original: bytes, element: bytes, tag: str) -> bytes:
    """``element`` (the serialised root) between the input's own prolog and epilog, byte for byte: the XML
    declaration, comments before the root, and whatever follows its end tag."""
    prolog = _PROLOG.match(original)
    start = prolog.end() if prolog else 0      # the pattern matches the empty string: never None
    end_tag = f"</{tag}>".encode()
    close = original.rfind(end_tag)
    end = close + len(end_tag) if close >= 0 else len(original.rstrip())
    old_tag, new_tag = _START_TAG.match(original, start), _START_TAG.match(element)
    if old_tag and new_tag and not old_tag.group(0).endswith(b"/>"):   # the root's attributes are never edited
        element = old_tag.group(0) + element[new_tag.end():]
    return original[:start] + element + original[end:]


_START_TAG_PATTERN = r"<[^\s/>!?]+(?:\s+[^\s=/>]+\s*=\s*(?:\"[^\"]*\"|'[^']*'))*\s*/?>"
_START_TAG = re.compile(_START_TAG_PATTERN.encode())
_START_TAG_TEXT = re.compile(_START_TAG_PATTERN)


def write_corrected(robot: RobotDescription, inertials, path, *, force: bool = False, note: str = "") -> tuple:
    """Write :func:`corrected_document` to ``path`` atomically; returns the names of the corrected links.

    Parameters
    ----------
    robot : RobotDescription
        The description read by :func:`~inertia_tool.robot.read_robot` (its ``document`` is edited).
    inertials : sequence of LinkInertial
        From :func:`~inertia_tool.robot.link_inertials`; links without ``properties`` are left untouched.
    path : str or os.PathLike
        The file to write (a temporary file beside it is renamed onto it).
    force : bool
        Replace an existing file (also the input itself).
    note : str
        Appended to the provenance comment (e.g. the density basis).

    Returns
    -------
    tuple of str
        The links whose ``<inertial>`` was written.

    Raises
    ------
    UsageError
        ``path`` exists (or is the input) and ``force`` is false; ``path`` is a directory or cannot be written.
    """
    path = os.fspath(path)
    if os.path.isdir(path):
        raise UsageError(f"{path}: is a directory")
    if os.path.exists(path) and not force:
        same = os.path.exists(robot.source) and os.path.samefile(path, robot.source)
        raise UsageError(f"{path}: {'is the input description' if same else 'exists'}; refusing to overwrite it")
    data = corrected_document(robot, inertials, note=note)
    directory = os.path.dirname(os.path.abspath(path))
    tmp = os.path.join(directory, f".{os.path.basename(path)}.tmp-{os.getpid()}")
    try:
        with open(tmp, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except OSError as exc:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise UsageError(f"{path}: cannot write it ({exc.strerror or exc})") from None
    return tuple(r.name for r in inertials if r.properties is not None)
