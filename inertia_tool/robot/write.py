"""A copy of a robot description with corrected ``<inertial>`` elements, everything else left as it was.

The description is edited as an XML tree (lxml, comments and whitespace kept) and only the inertial of each
link with a geometry result is touched: its origin moves to the centre of mass, its orientation is the link
frame (**rpy 0**, MJCF: no ``quat``) and the **full tensor** is written (products of inertia in the tensor
convention, ``ixy = −∫xy dm``, which URDF, SDFormat and MuJoCo's ``fullinertia`` use).  Attribute order,
comments, indentation and every other element are kept; the XML declaration line is copied from the
input.  lxml may still normalise a few bytes (quotes around attribute values, ``<a />`` to ``<a/>``,
character references); the tests measure it on the bundled robots.  One comment inside the root element
says which links were recomputed and from what.

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


def _indent_of(element) -> str:
    """The whitespace before ``element`` (its indentation) or two spaces deeper than its parent."""
    prev = element.getprevious()
    text = prev.tail if prev is not None else element.getparent().text if element.getparent() is not None else None
    if text and text.strip() == "":
        return text
    return "\n  "


def _child(parent, tag: str, indent: str):
    """The first ``<tag>`` child of ``parent``, created (indented like its siblings) if missing."""
    from lxml import etree
    found = parent.find(tag)
    if found is not None:
        return found
    child = etree.SubElement(parent, tag)
    if len(parent) == 1:
        parent.text = indent + "  "
        child.tail = indent
    else:
        before = parent[-2]
        child.tail = before.tail
        before.tail = indent + "  "
    return child


def _new_inertial(link, indent: str):
    from lxml import etree
    inertial = etree.Element("inertial")
    children = [c for c in link]
    if children:
        last = children[-1]
        inertial.tail = last.tail
        last.tail = indent + "  "
        link.append(inertial)
    else:
        link.text = indent + "  "
        inertial.tail = indent
        link.append(inertial)
    return inertial


def _urdf_inertial(link, props) -> None:
    com, t = _clean(props)
    inertial = link.find("inertial")
    indent = _indent_of(link)
    if inertial is None:
        inertial = _new_inertial(link, indent)
    inner = indent + "  "
    origin = _child(inertial, "origin", inner)
    origin.set("xyz", " ".join(_num(c) for c in com))
    origin.set("rpy", "0 0 0")
    _child(inertial, "mass", inner).set("value", _num(props.mass))
    inertia = _child(inertial, "inertia", inner)
    for key, (i, j) in (("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyy", (1, 1)), ("iyz", (1, 2)),
                        ("izz", (2, 2))):
        inertia.set(key, _num(t[i, j]))


def _sdf_inertial(link, props) -> None:
    com, t = _clean(props)
    inertial = link.find("inertial")
    indent = _indent_of(link)
    if inertial is None:
        inertial = _new_inertial(link, indent)
    inner = indent + "  "
    pose = _child(inertial, "pose", inner)
    pose.text = " ".join(_num(c) for c in com) + " 0 0 0"
    pose.attrib.pop("degrees", None)
    pose.attrib.pop("rotation_format", None)
    _child(inertial, "mass", inner).text = _num(props.mass)
    inertia = _child(inertial, "inertia", inner)
    for key, (i, j) in (("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyy", (1, 1)), ("iyz", (1, 2)),
                        ("izz", (2, 2))):
        _child(inertia, key, inner + "  ").text = _num(t[i, j])


def _mjcf_inertial(body, props) -> None:
    from lxml import etree
    com, t = _clean(props)
    inertial = body.find("inertial")
    if inertial is None:
        inertial = etree.Element("inertial")
        indent = _indent_of(body) + "  "
        inertial.tail = body.text if body.text and not body.text.strip() else indent
        body.text = body.text if body.text and not body.text.strip() else indent
        body.insert(0, inertial)
    for key in _ORIENTATION_KEYS:
        inertial.attrib.pop(key, None)
    inertial.set("pos", " ".join(_num(c) for c in com))
    inertial.set("mass", _num(props.mass))
    inertial.set("fullinertia", " ".join(_num(v) for v in (t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2])))


def _links(root, fmt: str):
    """Link (URDF/SDF) or body (MJCF) elements by name, in document order."""
    if fmt in ("urdf", "xacro"):
        return {l.get("name"): l for l in root.findall("link")}
    if fmt == "sdf":
        models = root.findall("model") + root.findall("world/model")
        return {l.get("name"): l for l in models[0].findall("link")}
    bodies = {}
    for k, body in enumerate(root.iter("body")):
        bodies[body.get("name") or f"body {k + 1}"] = body
    return bodies


def corrected_document(robot: RobotDescription, inertials, *, note: str = "") -> bytes:
    """The description's bytes with the inertials of the links in ``inertials`` replaced.

    Parameters
    ----------
    robot : RobotDescription
    inertials : sequence of LinkInertial
        Links with ``properties`` None are left untouched.
    note : str
        Appended to the provenance comment (e.g. the density basis).
    """
    from lxml import etree
    tree = parse_xml(robot.document, robot.source)
    root = tree.getroot()
    elements = _links(root, robot.format)
    writer = {"urdf": _urdf_inertial, "xacro": _urdf_inertial, "sdf": _sdf_inertial, "mjcf": _mjcf_inertial}[robot.format]
    changed = []
    for result in inertials:
        if result.properties is None or result.name not in elements:
            continue
        writer(elements[result.name], result.properties)
        changed.append(result.name)
    if changed:
        comment = etree.Comment(
            f" inertia-tool robot: <inertial> of {len(changed)} links recomputed from the {robot.geometry} geometry"
            f"{' (' + note + ')' if note else ''}: origin at the centre of mass, axes of the link frame (rpy 0), "
            "full tensor about the centre of mass, SI, ixy = -(integral of x*y dm) ".replace("--", "- -"))
        comment.tail = root.text if root.text and not root.text.strip() else "\n"
        root.insert(0, comment)
        if root.text is None or root.text.strip():
            root.text = "\n"
    return _splice(robot.document, etree.tostring(root, encoding="utf-8"), root.tag)


_PROLOG = re.compile(rb"(?:\s+|<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>\[]*(?:\[.*?\])?\s*>)*", re.DOTALL)


def _splice(original: bytes, element: bytes, tag: str) -> bytes:
    """``element`` (the serialised root) between the input's own prolog and epilog, byte for byte: the XML
    declaration, comments before the root, and whatever follows its end tag."""
    start = _PROLOG.match(original).end()
    end_tag = f"</{tag}>".encode()
    close = original.rfind(end_tag)
    end = close + len(end_tag) if close >= 0 else len(original.rstrip())
    old_tag, new_tag = _START_TAG.match(original, start), _START_TAG.match(element)
    if old_tag and new_tag and not old_tag.group(0).endswith(b"/>"):   # the root's attributes are never edited
        element = old_tag.group(0) + element[new_tag.end():]
    return original[:start] + element + original[end:]


_START_TAG = re.compile(rb"<[^\s/>]+(?:\s+[^\s=/>]+\s*=\s*(?:\"[^\"]*\"|'[^']*'))*\s*/?>")


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
