"""One named sub-mesh of a COLLADA file, as Gazebo selects it (SDFormat ``<mesh><submesh><name>``).

Gazebo's COLLADA loader (gz-common) makes one sub-mesh per primitive of every ``<instance_geometry>`` in the
visual scene, with the node transforms applied to its vertices, and names it after the ``<node>`` that holds
it: the node's ``name`` attribute, or, when it has none, the nearest enclosing node's.  ``<submesh><name>N``
keeps the sub-meshes called ``N``; ``<center>true`` then moves them so that the centre of their axis-aligned
bounding box, ``(min + max)/2``, is at the origin (gz-common ``SubMesh::Center``: the box centre, not the
centroid).

:func:`select_collada_node` writes a copy of the document from which every other ``<instance_geometry>`` is
removed, so the ordinary reader (node transforms, units, checks) reads only the named piece.
"""

from __future__ import annotations

from typing import Any

from ..errors import MeshReadError
from .regular import open_regular

__all__ = ["collada_node_names", "select_collada_node"]


def _local(tag: object) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _gazebo_name(element: Any) -> str | None:
    """The name Gazebo gives the sub-meshes of ``element`` (an ``<instance_geometry>``): the nearest
    enclosing ``<node>`` with a ``name``; None when no enclosing node has one."""
    parent = element.getparent()
    while parent is not None:
        if _local(parent.tag) == "node" and parent.get("name"):
            return str(parent.get("name"))
        parent = parent.getparent()
    return None


def _instances(tree: Any) -> list[Any]:
    """The ``<instance_geometry>`` elements of the document's visual scenes."""
    return [e for e in tree.iter() if _local(e.tag) == "instance_geometry"
            and any(_local(a.tag) == "library_visual_scenes" for a in e.iterancestors())]


def _parse(path: str) -> Any:
    from lxml import etree
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False)
    try:
        with open_regular(path) as fh:
            return etree.parse(fh, parser)
    except etree.XMLSyntaxError as error:
        raise MeshReadError(f"{path}: not well-formed COLLADA ({str(error)[:200]})") from None


def collada_node_names(path: str) -> list[str]:
    """The sub-mesh names Gazebo would see in the COLLADA file ``path``, each once, in document order."""
    return list(dict.fromkeys(n for n in map(_gazebo_name, _instances(_parse(path))) if n is not None))


def select_collada_node(path: str, name: str) -> bytes:
    """The COLLADA document ``path`` keeping only the geometry of the sub-mesh ``name`` (see the module notes).

    Raises
    ------
    MeshReadError
        The file is not well-formed, instances library nodes (``<instance_node>``, whose sub-mesh names this
        selection does not follow), or has no sub-mesh ``name``: the message lists the names it has.
    """
    from lxml import etree
    tree = _parse(path)
    if any(_local(e.tag) == "instance_node" for e in tree.iter()):
        raise MeshReadError(f"{path}: <submesh> selection in a COLLADA file with <instance_node> is not "
                            "supported (expected geometry instanced directly in the scene's nodes)")
    instances = _instances(tree)
    names = [_gazebo_name(e) for e in instances]
    if name not in names:
        found = list(dict.fromkeys(n for n in names if n is not None))
        shown = ", ".join(repr(n) for n in found[:20]) + (f" and {len(found) - 20} more" if len(found) > 20 else "")
        raise MeshReadError(f"{path}: expected a sub-mesh (COLLADA node) named {name!r}, found "
                            f"{shown or 'no named node'}")
    for element, own in zip(instances, names):
        if own != name:
            parent = element.getparent()
            if parent is not None:
                parent.remove(element)
    return bytes(etree.tostring(tree))
