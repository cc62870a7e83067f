"""A copy of a robot description with corrected ``<inertial>`` elements, everything else left as it was.

Only the inertial of each link with a geometry result is touched: its origin moves to the centre of mass, its
orientation is the link frame (**rpy 0**, MJCF: no ``quat``) and the **full tensor** is written (products of
inertia in the tensor convention, ``ixy = −∫xy dm``, which URDF, SDFormat and MuJoCo's ``fullinertia`` use).

How, in three steps:

1. **Edit the tree.**  The new elements are built on an lxml tree of the description (the *expected*
   document): the old ``<inertial>`` edited in place, or a new one inserted where there was none (last in a
   URDF/SDF link, first in an MJCF body), plus one comment after the root's start tag saying which links were
   recomputed and from what (replacing the comment of an earlier run, so correcting twice adds nothing).
2. **Splice the text.**  The input is decoded in its own encoding (BOM, declared encoding; XML 1.0
   Appendix F), :func:`~inertia_tool.robot.xmlspans.element_spans` finds the exact offsets of every element
   (comments, CDATA, PIs, the DOCTYPE's internal subset, ``>`` inside quoted attributes and ``</inertial >``
   are followed, not guessed), and only the bytes of each replaced element change: every other byte —
   BOM, declaration, DOCTYPE, comments, indentation, attribute order and quoting, entity references, line
   ends — is the input's, in the input's encoding.
3. **Check before writing.**  The result is parsed again and compared with the input node by node: every
   element, comment, PI and entity reference outside the corrected ``<inertial>`` elements has the same
   tag, attributes (in order), text and tail (whitespace-only text may change only inside a link that
   received a new ``<inertial>``, and where the provenance comment went); each corrected ``<inertial>``
   equals the one built in step 1; the declaration, encoding and DOCTYPE are unchanged.  Any difference is
   :class:`~inertia_tool.errors.OutputCheckError` and nothing is written.

The file goes through :mod:`inertia_tool.output` (unpredictable temporary file beside the target,
fsync, atomic rename; never over an existing file, the input included, unless ``force``; never through a
symbolic link).  For xacro input the *expanded* URDF is written, indented two spaces per level.
"""

from __future__ import annotations

import os
import re

import numpy as np

from ..errors import OutputCheckError, UsageError
from ..output import check_targets, write_bytes
from .description import RobotDescription, parse_xml
from .xmlspans import DocumentText, ElementSpan, XMLSpanError, decode_document, element_spans

__all__ = ["write_corrected", "corrected_document", "rewrite_paths", "included_files"]

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


def _set_text(element, text: str) -> None:
    """``element`` holds ``text`` only: an entity reference, comment or CDATA inside the old value would
    otherwise stay after (and change) the new number."""
    for child in list(element):
        element.remove(child)
    element.text = text


def _sdf_inertial(link, props) -> None:
    com, t = _clean(props)
    inertial = _child(link, "inertial")
    pose = _child(inertial, "pose")
    _set_text(pose, " ".join(_num(c) for c in com) + " 0 0 0")
    pose.attrib.pop("degrees", None)
    pose.attrib.pop("rotation_format", None)
    _set_text(_child(inertial, "mass"), _num(props.mass))
    inertia = _child(inertial, "inertia")
    for key, (i, j) in (("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyy", (1, 1)), ("iyz", (1, 2)),
                        ("izz", (2, 2))):
        _set_text(_child(inertia, key), _num(t[i, j]))


def _mjcf_inertial(body, props) -> None:
    from lxml import etree
    com, t = _clean(props)
    inertial = body.find("inertial")
    if inertial is None:
        own, step = _layout(body)
        inertial = etree.Element("inertial")
        inertial.tail = body.text if body.text is not None and (len(body) or body.text.strip()) else own
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
    if fmt == "sdf":                # links of inline nested models are scoped "model::link", as read
        found: dict = {}
        tops = root.findall("model")
        stack = [(m, "") for m in tops] if len(tops) == 1 else [(w, "") for w in root.findall("world")]
        for _ in range(100_000):        # bounded: each element is visited once
            if not stack:
                break
            parent, prefix = stack.pop()
            for child in parent:
                if child.tag == "link":
                    found.setdefault(prefix + (child.get("name") or ""), child)
                elif child.tag == "model":
                    stack.append((child, f"{prefix}{child.get('name', '')}::"))
        return found
    bodies = {}
    for k, body in enumerate(root.iter("body")):
        bodies[body.get("name") or f"body {k + 1}"] = body
    return bodies


#: How the provenance comment starts; one already there (a corrected file corrected again) is replaced.
_PROVENANCE = " inertia-tool robot:"
_OLD_PROVENANCE = re.compile(r"[ \t\r\n]*(<!--" + re.escape(_PROVENANCE) + r".*?-->)", re.DOTALL)


def _old_provenance(root):
    """The root's first child node if it is a provenance comment of an earlier run, else None."""
    from lxml import etree
    first = root[0] if len(root) else None
    if (isinstance(first, etree._Comment) and (first.text or "").startswith(_PROVENANCE)
            and not (root.text or "").strip()):
        return first
    return None


def _provenance(robot: RobotDescription, changed: list, note: str) -> str:
    """The text of the comment naming what was recomputed: ASCII only (it must fit any encoding) and without
    ``--`` (not allowed in a comment)."""
    text = (f"{_PROVENANCE} <inertial> of {len(changed)} link{'s' if len(changed) != 1 else ''} "
            f"recomputed from the {robot.geometry} geometry{' (' + note + ')' if note else ''}: origin at the "
            "centre of mass, axes of the link frame (rpy 0), full tensor about the centre of mass, SI, "
            "ixy = -(integral of x*y dm) ")
    text = text.replace("\u00b3", "^3").replace("\u00b2", "^2").replace("\u00b7", "*")
    text = "".join(c if " " <= c < "\x7f" else "?" for c in text)
    while "--" in text:
        text = text.replace("--", "- -")
    return text


def _pretty(data: bytes, source: str) -> bytes:
    """The expanded xacro document indented two spaces per level (xacro's own output is one line)."""
    from lxml import etree
    tree = parse_xml(data, source)
    etree.indent(tree, space="  ")
    return etree.tostring(tree, xml_declaration=True, encoding="utf-8") + b"\n"


# -- paths that must stay right when the file is written to another folder ----------------------------------

#: MJCF asset elements whose ``file`` is relative to a compiler folder, and which folder attributes govern it.
_MJCF_ASSET_FOLDERS = {"mesh": ("meshdir", "assetdir"), "texture": ("texturedir", "assetdir"),
                       "hfield": ("assetdir",), "skin": ("assetdir",),
                       "model": ()}         # <asset><model file> (for <attach>): relative to the model's folder


def _moved(value: str, source_dir: str, out_dir: str) -> str | None:
    """``value`` (a relative path, or ``file://`` + one) re-expressed relative to ``out_dir``; None when it
    needs no change (absolute, another scheme, empty)."""
    text = value.strip()
    prefix = ""
    if text.startswith("file://"):
        prefix, text = "file://", text[len("file://"):]
    elif "://" in text:
        return None
    if not text or os.path.isabs(text):
        return None
    target = os.path.normpath(os.path.join(source_dir, text))
    moved = os.path.relpath(target, out_dir).replace(os.sep, "/")
    if text.endswith(("/", os.sep)) and not moved.endswith("/"):
        moved += "/"
    return prefix + moved if moved != text else None


def _mjcf_included_folders(robot: RobotDescription) -> set:
    """Compiler folder attributes that an included file sets (a moved main file cannot fix those)."""
    from .mjcf_model import _expand_includes
    root = parse_xml(robot.document, robot.source).getroot()
    own = set(id(c) for c in root.iter("compiler"))
    try:
        _expand_includes(root, robot.source)
    except Exception:  # noqa: BLE001 - read_robot already expanded it; this is only a second look
        return set()
    return {key for c in root.iter("compiler") if id(c) not in own for key in c.attrib}


def included_files(robot: RobotDescription) -> tuple[str, ...]:
    """The files an MJCF main file ``<include>``s, as written, when the main file itself holds no ``<body>`` and
    no ``<replicate>`` (a Menagerie ``scene.xml``): every body of the model is then in one of them, and only the
    main file is written.  Empty for other formats and for a main file with bodies of its own (which bodies
    come from where is then not said)."""
    if robot.format != "mjcf":
        return ()
    root = parse_xml(robot.document, robot.source).getroot()
    if next(root.iter("body", "replicate"), None) is not None:
        return ()
    return tuple(dict.fromkeys(i.get("file") or "" for i in root.iter("include")))


#: Compiler attributes naming folders, which MuJoCo takes relative to the main model file's folder.
_MJCF_FOLDER_KEYS = ("meshdir", "assetdir", "texturedir")


def _folders_set_by(include, robot: RobotDescription) -> dict:
    """The compiler folder attributes that the file of ``include`` (an ``<include>`` of the main file) sets,
    with the files it includes in turn, as MuJoCo merges them (later ones win); {} when it sets none."""
    from .mjcf_model import _expand_includes
    from lxml import etree
    probe = etree.Element("mujoco")
    probe.append(etree.Element("include", file=include.get("file") or ""))
    try:
        _expand_includes(probe, robot.source)
    except Exception:  # noqa: BLE001 - read_robot already expanded it; this is only a second look
        return {}
    merged: dict = {}
    for compiler in probe.iter("compiler"):
        merged.update({k: v for k, v in compiler.attrib.items() if k in _MJCF_FOLDER_KEYS})
    return merged


def _restate_included_folders(robot: RobotDescription, root, source_dir: str, out_dir: str) -> list:
    """After each ``<include>`` of the main file whose file sets ``meshdir``/``assetdir``/``texturedir``, a new
    ``<compiler>`` giving the same folders relative to ``out_dir``.  MuJoCo takes those folders relative to the
    *main* file's folder, wherever the included file sits, so a main file written elsewhere needs them restated
    (the included file is not written).  The new element comes right after the include, so that it holds
    where the included one held (a later ``<compiler>`` of the main file still overrides it).  Returns the new
    elements (in ``root``)."""
    from lxml import etree
    added = []
    for include in root.findall("include"):        # a <compiler> may only stand at the top level
        folders = _folders_set_by(include, robot)
        moved = {k: _moved(v, source_dir, out_dir) for k, v in folders.items()}
        moved = {k: v for k, v in moved.items() if v is not None}
        if not moved:
            continue
        compiler = etree.Element("compiler", moved)
        compiler.tail = include.tail
        include.tail = _whitespace_before(include) or " "
        include.addnext(compiler)
        added.append(compiler)
    return added


def rewrite_paths(robot: RobotDescription, root, out_dir: str | None) -> list:
    """Make the relative file references of the tree ``root`` (the description's document) right for a
    copy written in ``out_dir``; returns the elements changed (in place).

    URDF: ``<mesh filename>`` (plain relative paths and ``file://`` + a relative path); SDFormat: the text
    of ``<mesh><uri>``; MJCF: ``<compiler meshdir/assetdir/texturedir>``, ``<include file>`` and the ``file``
    of ``<mesh>``/``<texture>``/``<hfield>``/``<skin>`` assets that no folder attribute governs; the folders an
    included file sets are restated after its ``<include>`` (:func:`_restate_included_folders`).
    ``package://`` and ``model://`` URIs and absolute paths are left alone.  Nothing changes when
    ``out_dir`` is the description's own folder (or None).
    """
    source_dir = os.path.dirname(os.path.abspath(robot.source))
    if out_dir is None or os.path.realpath(out_dir) == os.path.realpath(source_dir):
        return []
    changed = []

    def move(element, attribute: str | None) -> None:
        if attribute is None:
            new = _moved(element.text or "", source_dir, out_dir)
            if new is not None:
                element.text = new
                changed.append(element)
            return
        value = element.get(attribute)
        new = _moved(value, source_dir, out_dir) if value is not None else None
        if new is not None:
            element.set(attribute, new)
            if element not in changed:
                changed.append(element)

    if robot.format in ("urdf", "xacro"):
        for mesh in root.iter("mesh"):
            move(mesh, "filename")
    elif robot.format == "sdf":
        for uri in root.iter("uri"):
            if uri.getparent() is not None and uri.getparent().tag == "mesh":
                move(uri, None)
    else:
        folders: set = set()
        for compiler in root.iter("compiler"):
            for key in ("meshdir", "assetdir", "texturedir"):
                if compiler.get(key) is not None:
                    folders.add(key)
                    move(compiler, key)
        folders |= _mjcf_included_folders(robot)
        changed.extend(_restate_included_folders(robot, root, source_dir, out_dir))
        for include in root.iter("include"):
            move(include, "file")
        for tag, governing in _MJCF_ASSET_FOLDERS.items():
            if any(key in folders for key in governing):
                continue
            for asset in root.iter(tag):
                move(asset, "file")
    return changed


def _elements_in_order(root) -> list:
    """The elements under and including ``root`` in document order (no comments, PIs or entity references)."""
    from lxml import etree
    return list(root.iter(tag=etree.Element))


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1].rsplit(":", 1)[-1]


def corrected_document(robot: RobotDescription, inertials, *, note: str = "",
                       out_dir: str | None = None) -> bytes:
    """The description's bytes with the inertials of the links in ``inertials`` replaced, checked (see
    :func:`_corrected`, which also says which links were written)."""
    return _corrected(robot, inertials, note=note, out_dir=out_dir)[0]


def _corrected(robot: RobotDescription, inertials, *, note: str = "",
               out_dir: str | None = None) -> tuple[bytes, list]:
    """The description's bytes with the inertials of the links in ``inertials`` replaced, checked.

    Only the bytes of each replaced ``<inertial>`` element change (a missing one is inserted), plus one
    provenance comment after the root's start tag; every other byte is the input's, in its encoding.  The
    result is parsed again and compared with the input before it is returned (see the module docstring).

    Parameters
    ----------
    robot : RobotDescription
        The description (its ``document``; for xacro the expansion, which is indented first).
    inertials : sequence of LinkInertial
        Links with ``properties`` None are left untouched.
    note : str
        Appended to the provenance comment (e.g. the density basis).
    out_dir : str, optional
        The folder the copy will be written to: relative file references are re-expressed from there
        (:func:`rewrite_paths`), so the copy loads where it is written.

    Returns
    -------
    bytes
        The corrected document.

    Raises
    ------
    OutputCheckError
        The edit could not be made exactly, or its result differs from the input outside the corrected
        elements (a bug; nothing should be written).
    """
    base = _pretty(robot.document, robot.source) if robot.format == "xacro" else robot.document
    original = parse_xml(base, robot.source)
    expected = parse_xml(base, robot.source)
    root = expected.getroot()
    order = {element: k for k, element in enumerate(_elements_in_order(root))}    # before any edit
    elements = _links(root, robot.format)
    moved = rewrite_paths(robot, root, out_dir)
    writer = {"urdf": _urdf_inertial, "xacro": _urdf_inertial, "sdf": _sdf_inertial,
              "mjcf": _mjcf_inertial}[robot.format]
    changed = []
    for result in inertials:
        if result.properties is None or result.name not in elements or result.name in changed:
            continue
        writer(elements[result.name], result.properties)
        changed.append(result.name)
    if not changed and not moved:
        return base, changed
    comment = _provenance(robot, changed, note)
    try:
        document = decode_document(base)
        spans = element_spans(document.text)
        _check_alignment(spans, order, robot.source)
        edits = _edits(document.text, spans, order, [elements[name] for name in changed], comment,
                       _old_provenance(original.getroot()) is not None)
        edits = sorted(edits + _path_edits(spans, order, moved), key=lambda e: (e[0], e[1]))
        for (_, end, _r), (start, _e, _s) in zip(edits, edits[1:]):
            if start < end:
                raise XMLSpanError(f"two edits overlap at offset {start}")
        out = _apply(document, base, edits)
    except (XMLSpanError, UnicodeError) as exc:
        raise OutputCheckError(f"{robot.source}: cannot edit its <inertial> elements in place ({exc}); "
                               "nothing was written") from None
    if moved:             # the input as it should read after the same path rewrites: the reference of the check
        original = parse_xml(base, robot.source)
        rewrite_paths(robot, original.getroot(), out_dir)
    _verify(original, expected, out, robot, changed, comment)
    return out, changed


def _path_edits(spans: list, order: dict, moved: list) -> list:
    """Edits replacing the start tag (attributes) or, for a text-only element, the whole element of each
    element whose path was rewritten."""
    from lxml import etree
    edits = []
    for element in moved:
        if element not in order:      # a <compiler> restating an included file's folders: after that <include>
            before = spans[order[element.getprevious()]]
            edits.append((before.end, before.end, (element.getprevious().tail or "")
                          + etree.tostring(element, encoding="unicode", with_tail=False)))
            continue
        span = spans[order[element]]
        if len(element) == 0 and element.text is not None and not span.empty:      # SDFormat <uri>text</uri>
            edits.append((span.start, span.end, _serialized(element, "\n")))
            continue
        shallow = etree.Element(element.tag, dict(element.attrib), nsmap=element.nsmap)
        tag = etree.tostring(shallow, encoding="unicode")
        if span.empty:
            edits.append((span.start, span.end, tag))
        else:
            edits.append((span.start, span.start_end, tag[:-2] + ">"))
    return edits


def _check_alignment(spans: list, order: dict, source: str) -> None:
    """The tokenizer's elements are lxml's, one for one, in the same order with the same names."""
    elements = sorted(order, key=lambda element: order[element])
    if len(spans) != len(elements):
        raise XMLSpanError(f"found {len(spans)} elements in the text where the parser found {len(elements)}")
    for span, element in zip(spans, elements):
        if _local(span.tag) != _local(element.tag):
            raise XMLSpanError(f"found <{span.tag}> at offset {span.start} where the parser found "
                               f"<{element.tag}> (line {element.sourceline})")


def _newline(text: str) -> str:
    return "\r\n" if "\r\n" in text and text.count("\r\n") == text.count("\n") else "\n"


def _serialized(element, newline: str) -> str:
    from lxml import etree
    return etree.tostring(element, encoding="unicode", with_tail=False).replace("\n", newline)


def _edits(text: str, spans: list[ElementSpan], order: dict, containers: list, comment: str,
           replace_comment: bool) -> list:
    """``(start, end, replacement)`` character ranges of ``text``: each corrected inertial, and the comment
    (in place of the one of an earlier run when ``replace_comment``)."""
    newline = _newline(text)
    edits = []
    for container in containers:
        inertial = container.find("inertial")
        serialized = _serialized(inertial, newline)
        if inertial in order:                               # an edited element of the input: replace its text
            span = spans[order[inertial]]
            edits.append((span.start, span.end, serialized))
            continue
        span = spans[order[container]]
        if span.empty:
            raise XMLSpanError(f"<{span.tag}> at offset {span.start} is written as an empty-element tag")
        before = (_whitespace_before(inertial) or "").replace("\n", newline)
        if container.tag == "body":                         # MJCF: first, right after the body's start tag
            edits.append((span.start_end, span.start_end, before + serialized))
            continue
        line_start = text.rfind("\n", 0, span.close) + 1
        if not text[line_start:span.close].strip() and before.startswith(newline):   # "</link>" on its own line
            edits.append((line_start, line_start, before[len(newline):] + serialized + newline))
        else:
            edits.append((span.close, span.close, serialized))
    root = spans[0]
    if root.empty:
        raise XMLSpanError("the root element is written as an empty-element tag")
    following = text[root.start_end:root.start_end + 200]
    indent = following.lstrip("\r\n")
    indent = indent[:len(indent) - len(indent.lstrip(" \t"))] if following[:1] in "\r\n" and following else ""
    if replace_comment:
        old = _OLD_PROVENANCE.match(text, root.start_end)
        if old is None:
            raise XMLSpanError(f"the provenance comment after the root's start tag (offset {root.start_end}) "
                               "was not found in the text")
        edits.append((old.start(1), old.end(1), f"<!--{comment}-->"))
    else:
        edits.append((root.start_end, root.start_end, f"{newline}{indent or '  '}<!--{comment}-->"))
    edits.sort(key=lambda e: (e[0], e[1]))
    for (_, end, _r), (start, _e, _s) in zip(edits, edits[1:]):
        if start < end:
            raise XMLSpanError(f"two edits overlap at offset {start}")
    return edits


def _apply(document: DocumentText, data: bytes, edits: list) -> bytes:
    """The input's bytes with ``edits`` made: the untouched stretches are the input's own bytes."""
    body = data[len(document.bom):]
    if document.encode(document.text) != body:
        raise XMLSpanError(f"the {document.codec} text does not encode back to the same bytes")
    pieces, position, offset = [document.bom], 0, 0
    for start, end, replacement in edits:
        unchanged = len(document.encode(document.text[position:start]))
        pieces.append(body[offset:offset + unchanged])
        offset += unchanged + len(document.encode(document.text[start:end]))
        pieces.append(document.encode(replacement))
        position = end
    pieces.append(body[offset:])
    return b"".join(pieces)


# -- the check before writing ----------------------------------------------------------------------------

def _describe(node) -> tuple:
    """What must be equal in two nodes, text and children apart."""
    from lxml import etree
    if isinstance(node, etree._Comment):
        return ("comment", node.text)
    if isinstance(node, etree._ProcessingInstruction):
        return ("processing instruction", node.target, node.text)
    if isinstance(node, etree._Entity):
        return ("entity reference", node.name)
    return ("element", node.tag, tuple(node.attrib.items()))


def _content(element, dropped) -> tuple[list, list]:
    """``(children, slots)`` of ``element`` with the node ``dropped`` left out: ``slots`` are the text runs
    between the kept children (``slots[0]`` the element's text); a dropped child's tail joins the run before."""
    if not isinstance(element.tag, str):
        return [], []
    children, slots = [], [element.text or ""]
    for child in element:
        if child is dropped:
            slots[-1] += child.tail or ""
        else:
            children.append(child)
            slots.append(child.tail or "")
    return children, slots


def _where(node) -> str:
    tag = node.tag if isinstance(node.tag, str) else _describe(node)[0]
    return f"line {node.sourceline}, <{tag}>"


def _differ(robot: RobotDescription, where: str, what: str, expected, found) -> OutputCheckError:
    return OutputCheckError(f"{robot.source}: the corrected copy differs from the input at {where} ({what}: "
                            f"expected {str(expected)[:80]!r}, found {str(found)[:80]!r}); nothing was written "
                            "(please report this)")


def _whitespace_inserted(old: str, new: str, *, max_tries: int = 10_000) -> bool:
    """``new`` is ``old`` with one run of whitespace inserted somewhere (or equal to it)."""
    extra = len(new) - len(old)
    if extra <= 0:
        return new == old
    prefix = 0
    while prefix < len(old) and old[prefix] == new[prefix]:
        prefix += 1
    for start in range(prefix, max(-1, prefix - max_tries), -1):
        if not new[start:start + extra].strip() and new[start + extra:] == old[start:]:
            return True
    return False


def _same_slots(a: list, b: list, loose: bool) -> int:
    """Index of the first text run that differs, or -1; when ``loose`` a run may have gained whitespace in
    one place (where an element was inserted next to it)."""
    for k, (x, y) in enumerate(zip(a, b)):
        if x != y and not (loose and _whitespace_inserted(x, y)):
            return k
    return -1


def _compare(robot, old_root, new_root, *, fixed: dict, skip_first_comment: str | None = None) -> None:
    """Node-by-node equality of two trees; in ``fixed`` (old element → new element) the children that are
    the corrected inertials (``old.find("inertial")`` and ``new.find("inertial")``) are left out and runs of
    whitespace may differ."""
    stack = [(old_root, new_root)]
    while stack:                     # bounded: each node of the old tree is visited once
        old, new = stack.pop()
        if _describe(old) != _describe(new):
            raise _differ(robot, _where(old), "the node", _describe(old), _describe(new))
        if old in fixed and fixed[old] is not new:
            raise _differ(robot, _where(old), "the corrected link", old.get("name"), new.get("name"))
        if not isinstance(old.tag, str):
            continue
        loose = old in fixed
        old_dropped = old.find("inertial") if loose else None
        if old is old_root and skip_first_comment is not None:
            old_dropped = _old_provenance(old)          # replaced by the new comment, if there was one
        old_children, old_slots = _content(old, old_dropped)
        dropped = new.find("inertial") if loose else None
        if new is new_root and skip_first_comment is not None:
            first = new[0] if len(new) else None
            if first is None or _describe(first) != ("comment", skip_first_comment):
                raise _differ(robot, _where(new), "the provenance comment", skip_first_comment,
                              _describe(first) if first is not None else None)
            dropped, loose = first, True
        new_children, new_slots = _content(new, dropped)
        if len(old_children) != len(new_children):
            raise _differ(robot, _where(old), "the number of children", len(old_children), len(new_children))
        k = _same_slots(old_slots, new_slots, loose)
        if k >= 0:
            raise _differ(robot, _where(old), "the text" if k == 0 else f"the text after child {k}",
                          old_slots[k], new_slots[k])
        stack.extend(zip(old_children, new_children))


def _document_facts(tree) -> tuple:
    """What must not change outside the root element: declaration, encoding, DOCTYPE, entity declarations,
    the comments and PIs around the root."""
    info = tree.docinfo
    dtd = info.internalDTD
    entities = tuple((e.name, e.content, e.system_url) for e in dtd.iterentities()) if dtd is not None else ()
    root = tree.getroot()
    around = tuple(_describe(n) for n in root.itersiblings(preceding=True)) + ("root",) + tuple(
        _describe(n) for n in root.itersiblings())
    return (info.xml_version, info.encoding, info.standalone, info.doctype, entities, around)


def _verify(original, expected, out: bytes, robot: RobotDescription, changed: list, comment: str) -> None:
    """Parse ``out`` and compare it with the input (``original``) and the edited tree (``expected``)."""
    from ..errors import RobotDescriptionError
    try:
        written = parse_xml(out, robot.source)
    except RobotDescriptionError as exc:
        raise OutputCheckError(f"{exc}: the corrected copy is not well-formed XML; nothing was written "
                               "(please report this)") from None
    old_facts, new_facts = _document_facts(original), _document_facts(written)
    if old_facts != new_facts:
        raise _differ(robot, "the document's declaration, DOCTYPE or top level", "the prolog", old_facts, new_facts)
    old_links = _links(original.getroot(), robot.format)
    new_links = _links(written.getroot(), robot.format)
    want_links = _links(expected.getroot(), robot.format)
    fixed = {old_links[name]: new_links.get(name) for name in changed}
    _compare(robot, original.getroot(), written.getroot(), fixed=fixed, skip_first_comment=comment)
    for name in changed:
        got, want = new_links[name].find("inertial"), want_links[name].find("inertial")
        if got is None:
            raise _differ(robot, _where(new_links[name]), "the corrected <inertial>", "an <inertial>", None)
        _compare(robot, want, got, fixed={})
        if (got.getparent().index(got) == 0) != (want.getparent().index(want) == 0):
            raise _differ(robot, _where(got), "the place of the <inertial>", want.getparent().index(want),
                          got.getparent().index(got))


def write_corrected(robot: RobotDescription, inertials, path, *, force: bool = False, note: str = "") -> tuple:
    """Write :func:`corrected_document` to ``path`` through :mod:`inertia_tool.output`; returns the
    names of the corrected links.

    Parameters
    ----------
    robot : RobotDescription
        The description read by :func:`~inertia_tool.robot.read_robot`.
    inertials : sequence of LinkInertial
        From :func:`~inertia_tool.robot.link_inertials`; links without ``properties`` are left untouched.
    path : str or os.PathLike
        The file to write (a temporary file beside it is renamed onto it).
    force : bool
        Replace an existing file (also the input itself).  A symbolic link is never written through.
    note : str
        Appended to the provenance comment (e.g. the density basis).

    Returns
    -------
    tuple of str
        The links whose ``<inertial>`` was written (a link of an MJCF or SDFormat included file is not: it
        is not in this document).

    Raises
    ------
    UsageError
        ``path`` is empty, exists (or is the input) and ``force`` is false, is a directory or a symbolic link,
        or cannot be written (:class:`~inertia_tool.output.OutputFileError`).
    OutputCheckError
        The corrected document failed its check; nothing was written.
    """
    path = os.fspath(path)
    if not path:
        raise UsageError("Expected a file name to write the corrected description to, got ''")
    if (not force and os.path.exists(path) and os.path.exists(robot.source)
            and os.path.samefile(path, robot.source)):
        raise UsageError(f"{path}: is the input description; refusing to overwrite it (`force=True` does)")
    check_targets([path], force=force)
    data, changed = _corrected(robot, inertials, note=note, out_dir=os.path.dirname(os.path.abspath(path)))
    write_bytes(path, data, replace=force)
    return tuple(changed)
