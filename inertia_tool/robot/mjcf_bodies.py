"""The bodies of an MJCF tree as MuJoCo names and copies them: through ``<frame>`` and ``<replicate>``
(:func:`_child_bodies`, copy names ``NAME + sep + index``), the poses of the geoms a ``<replicate>`` copies
inside a body (:func:`_replica_poses`), and the body an ``<attach body>`` names in another model
(:func:`_attached_body`)."""

from __future__ import annotations

import math

import numpy as np

from .description import _coordinates, _numbers
from .mjcf_model import _Model
from .mjcf_orientation import _euler_matrix, _fail

__all__ = ["MAX_REPLICAS"]

#: Most copies one ``<replicate>`` may make (and all of them together).
MAX_REPLICAS = 10_000


def _child_bodies(element, class_name: str, suffix: str = "", source: str = "", budget: list | None = None):
    """The ``<body>`` children of ``element``, looking through ``<frame>`` and ``<replicate>`` elements, with
    their default class and name suffix.

    ``<replicate count sep>`` repeats its bodies ``count`` times; MuJoCo names copy ``i`` of ``NAME``
    ``NAME + sep + i`` (``i`` zero-padded to the digits of ``count − 1``), inner replicates' suffixes first.
    The copies' placement (``offset``, orientation) does not change a body's own mass properties.
    An ``<attach>`` element is yielded as it is, with ``None`` for its class: its bodies are another model's.
    """
    budget = [MAX_REPLICAS] if budget is None else budget
    for child in element:
        if child.tag == "body":
            yield child, class_name, suffix
        elif child.tag == "frame":
            yield from _child_bodies(child, child.get("childclass", class_name), suffix, source, budget)
        elif child.tag == "replicate":
            count = _numbers(child.get("count"), 1, "<replicate count>", source)[0]
            if not (count == int(count) and 1 <= count <= budget[0]):
                raise _fail(source, f"<replicate count={child.get('count')!r}>: expected a whole number from 1 to "
                                    f"{budget[0]:,} (copies left of {MAX_REPLICAS:,})")
            budget[0] -= int(count)
            width = len(str(int(count) - 1))
            for k in range(int(count)):
                yield from _child_bodies(child, class_name, f"{child.get('sep', '')}{k:0{width}d}{suffix}", source,
                                         budget)
        elif child.tag == "attach":
            yield child, None, suffix          # the caller reads the attached model (:func:`read_mjcf`)


def _replica_poses(replicate, pose, model, budget: list) -> list:
    """The poses of the copies a ``<replicate count offset euler>`` makes of the geoms (and frames) it holds
    in a body, composed onto ``pose``: copy ``k`` is turned by the Euler angles ``k · euler`` (the model's angle
    unit and ``eulerseq``) and moved by ``Σ_{j<k} R(j · euler) offset`` — each step's offset taken in the
    previous copy's axes (checked against ``mujoco`` 4.0's ``geom_pos`` and ``geom_quat``; for angles about
    one axis this is the step ``x ↦ R x + offset`` applied ``k`` times).  ``budget`` is the copies left of
    :data:`MAX_REPLICAS`."""
    degrees, eulerseq, _ = model.compiler
    count = _numbers(replicate.get("count"), 1, "<replicate count>", model.source)[0]
    if not (count == int(count) and 1 <= count <= budget[0]):
        raise _fail(model.source, f"<replicate count={replicate.get('count')!r}>: expected a whole number from 1 to "
                                  f"{budget[0]:,} (copies left of {MAX_REPLICAS:,})")
    budget[0] -= int(count)
    angles = _numbers(replicate.get("euler"), 3, "<replicate euler>", model.source, default=(0, 0, 0))
    angles = angles * (math.pi / 180.0 if degrees else 1.0)
    step = _coordinates(_numbers(replicate.get("offset"), 3, "<replicate offset>", model.source, default=(0, 0, 0)),
                        "<replicate offset>", model.source)
    poses = []
    rotation, translation = pose
    moved = np.zeros(3)
    for k in range(int(count)):
        turn = _euler_matrix(eulerseq, k * angles)
        poses.append((rotation @ turn, rotation @ moved + translation))
        moved = moved + turn @ step
    return poses


def _named_bodies(element, class_name: str, suffix: str, source: str, budget: list):
    """Every body under ``element`` as MuJoCo names it: ``(body element, default class in force, name suffix of
    its ``<replicate>`` copies)``, depth first (the bodies of ``<attach>`` elements are another model's)."""
    for child, cls, more in _child_bodies(element, class_name, suffix, source, budget):
        if cls is None:
            continue
        yield child, cls, more
        yield from _named_bodies(child, child.get("childclass", cls), more, source, budget)


def _attached_body(attach, model: _Model):
    """``(body element, its default class, name suffix)`` of the body an ``<attach body>`` names in ``model``:
    a body of that name, or a ``<replicate>`` copy of one by MuJoCo's name for it (``leg-1``: checked against
    ``mujoco`` 4.0, which attaches that copy alone, its subtree named with the copy's suffix).  The class is
    the ``childclass`` in force where the body stands in its own model."""
    wanted = attach.get("body")
    for world in model.root.findall("worldbody"):
        for body, class_name, suffix in _named_bodies(world, "main", "", model.source, [MAX_REPLICAS]):
            if body.get("name") is not None and body.get("name") + suffix == wanted:
                return body, class_name, suffix
    raise _fail(model.source, f"<attach model=... body={wanted!r}>: the model has no body {wanted!r}")
