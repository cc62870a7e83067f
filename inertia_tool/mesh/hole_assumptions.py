"""The assumptions a hole's bound rests on, each named once (issue 21, "certified answers").

No bound on a hole follows from the file alone: the missing surface can be anything with the rim as its
boundary.  Every bound :func:`~.holes.patched_estimate` states is therefore *conditional* on assumptions about
the missing surface, and an estimate names the ones its bound used (:func:`stated`, in its ``detail``, which
``repair=True`` prints as a note in text and JSON).  Where the file cannot tell a case the assumption covers from
one it does not (a missing triangle of a flat face and a boss taken whole with the faces round its footprint
leave the same rim on the same plane), the answer is an estimate whose bound holds *if* the named assumption
does, never ``exact``: a filled hole is always an estimate (``mesh/policy.py``).

Each :class:`HoleAssumption` has a short ``name`` (what tests and benchmarks match on), the ``statement`` (what
is assumed of the missing surface ``M`` of a hole) and ``fails_for`` (the damage it cannot see, so a reader knows
when to distrust the bound).  The evidence that withdraws a narrower assumption when the file contradicts it is in
:mod:`~.hole_bounds` and :mod:`~.hole_fills`.

One rule holds for all of them: **a slab of (near) zero width is no evidence**.  A hole that is an island in a
flat face (its rim and every face left at it in one plane) keeps no face that leaves the plane, so the file cannot
tell a flat lid from a dome or dimple taken whole with a flat ring round it, and every narrower assumption
(``flat``, ``planar``, ``bend``, ``graph``, ``capsule``, ``convex``) would bound it by round-off: such a hole keeps
the uncut ball over its rim (:data:`BALL`), or the estimate is refused where that is not useful
(:func:`~.hole_bounds.flat_islands` states the rule and its reason).  **Nor is a slope of (near) zero**: a hole
whose every face at the rim lies within 1.1° of the rim's plane (a *level* ring,
:func:`~.hole_bounds.level_rings`) is an island by the same rule, since ``bend`` and the ``flat`` slab would bound
a feature taken whole there by the ring's slope.

**The user's assumptions** (:data:`USER_ASSUMPTIONS`, issue 23) are the one exception, never taken by default:
``LoadOptions.assume`` / ``--assume flat-islands`` states that each such island lost a flat piece of its face
(:data:`FLAT_ISLANDS`); the island is then filled in its rim's plane and bounded by the rim's own slab
(:func:`~.hole_bounds.flat_island_doubt`), and the estimate names the assumption as the user's
(:func:`user_stated`).  ``smooth-holes`` (:data:`SMOOTH_HOLES`) states that each hole lost a piece of a smooth
surface continuing the one round it: a hole whose surroundings allow the reading is filled as a graph over the
plane most face-on to them and bounded by how far that assumption lets the surface stray from the surroundings'
quadratic (:func:`~.hole_bounds.smooth_doubt`), where that is narrower than its other bound.  ``faceted-holes``
(:data:`FACETED_HOLES`) states that each hole (not an island in a flat face) lost a piece of a faceted surface
staying inside the planes of the faces round it: the hole is bounded by the region between its cone and those
planes continued (:func:`~.hole_facets.faceted_doubt`) and filled on them where they close it, where that is
narrower than its other bound.  The user's
assumptions travel as a parameter, a frozen :class:`UserAssumptions`, from the
API (``LoadOptions.assume``) through :func:`~.prepare.prepare_mesh`, :func:`~.surface.close_surface` and
:func:`~.resolve.resolve_surface` to the one place that reads them, :func:`~.holes.patched_estimate`; no state
outside the call holds them (issues 21/23: a pure engine), so two calls, in one thread or two, each get the answer
of their own ``assume``.  The certificate of a result names those it rests on
(:attr:`~.policy.Certificate.assumptions`).
"""

from __future__ import annotations

import dataclasses
from typing import Iterable

__all__ = ["HoleAssumption", "BALL", "CAPSULE", "FLAT", "CREASE", "CONVEX", "INNER", "BEND", "GRAPH", "PLANAR",
           "QUADRIC", "ALL", "stated", "named", "FLAT_ISLANDS", "USER_ASSUMPTIONS", "user_named", "UserAssumptions",
           "NOTHING_ASSUMED", "user_stated", "ISLAND_HINT", "SMOOTH_HINT", "FACETED_HINT", "holes_hint", "SMOOTH_HOLES",
           "FACETED_HOLES"]


@dataclasses.dataclass(frozen=True)
class HoleAssumption:
    """One assumption about the surface a hole lost.

    Attributes
    ----------
    name : str
        Short identifier (``"flat"``, ``"ball"``, ...), printed before the statement.
    statement : str
        What is assumed of the missing surface ``M`` of a hole.
    fails_for : str
        Damage the assumption cannot see (the bound is then wrong, not merely loose).
    """

    name: str
    statement: str
    fails_for: str


BALL = HoleAssumption(
    "ball", "the missing surface of each hole lies within the ball enclosing its rim",
    "a feature taller than its rim is wide (a pin, a housing) taken whole, or a band joining two rims")
CAPSULE = HoleAssumption(
    "capsule", "the missing surface of a long thin hole lies within the capsule round its rim's principal axis "
    "that holds the rim", "a long slot or rib taken whole")
FLAT = HoleAssumption(
    "flat", "the flat face continues across the hole: the missing surface strays from the plane of a face beside "
    "the hole no farther than the rim does", "a boss, pocket, slot or dimple taken whole with the faces round it")
CREASE = HoleAssumption(
    "crease", "the two planes that hold the rim continue across the hole, meeting at one crease",
    "a feature standing on either face, or a chamfer or fillet along the crease, taken whole")
CONVEX = HoleAssumption(
    "convex", "the part is convex, as what remains of it is", "a dent, pocket or groove taken whole")
BEND = HoleAssumption(
    "bend", "the missing surface is a graph over the rim's mean plane and slopes against that plane no more "
    "steeply than the steepest face touching the rim", "a feature taken whole whose walls are "
    "steeper than the faces round its rim (a boss or pocket on a gently curved face; on a flat one with its "
    "surroundings flat, or with every face at the rim within 1.1° of its plane, the hole keeps its ball: "
    "hole_bounds.flat_islands)")
GRAPH = HoleAssumption(
    "graph", "the missing surface is a graph over the plane most face-on to the faces touching the rim and slopes "
    "against that plane no more steeply than the steepest of those faces", "a feature taken whole whose walls are "
    "steeper than the faces round its rim (a boss or pocket), or a surface that folds back over the hole")
INNER = HoleAssumption(
    "inner", "a rim vertex whose faces left all lie in one flat face and turn round it by more than 180° lies inside "
    "that face (as a fan-triangulated cap's centre does), not at a corner of a feature's footprint",
    "a pocket or boss taken whole whose footprint kept one corner on the rim with more than 180° of the face round "
    "it and neither rim neighbour of that corner another such (the file cannot tell it from a vertex inside a "
    "flat face)")
PLANAR = HoleAssumption(
    "planar", "a hole whose rim of four or more corners lies in one plane and meets every face beside it at a crease "
    "lost a flat face: the "
    "missing surface lies no farther from the rim's plane than the rim does",
    "a dome, boss or pocket bounded by a crease and taken whole (a domed lid on a prism reads as a flat lid); "
    "a surface that continues round over the hole on one quadric (a sphere cut "
    "by a plane) withdraws it")
QUADRIC = HoleAssumption(
    "quadric", "(the fill, not the bound) the missing surface continues the quadric its surroundings lie on",
    "nothing: the bound stays that of the other assumptions named")

#: Every assumption, in the order :func:`stated` prints them.
ALL = (CONVEX, INNER, BALL, CAPSULE, FLAT, PLANAR, CREASE, BEND, GRAPH, QUADRIC)


def named(names: Iterable[str]) -> tuple[HoleAssumption, ...]:
    """The assumptions called ``names``, in the order of :data:`ALL` (unknown names raise ``KeyError``)."""
    wanted = set(names)
    unknown = wanted - {a.name for a in ALL}
    if unknown:
        raise KeyError(f"expected names of hole assumptions ({', '.join(a.name for a in ALL)}), got "
                       f"{', '.join(sorted(unknown))}")
    return tuple(a for a in ALL if a.name in wanted)


def stated(names: Iterable[str]) -> str:
    """One line naming the assumptions ``names`` a bound rests on, for the estimate's ``detail``."""
    chosen = named(names)
    if not chosen:
        return ""
    return "the bound holds only if " + "; and ".join(f"{a.name}: {a.statement}" for a in chosen)


# -- assumptions only the user can make (issue 23: opt-in, never a default) ------------------------------------

FLAT_ISLANDS = HoleAssumption(
    "flat-islands", "each hole that is an island in a flat face lost a flat piece of that face",
    "a boss or pocket taken whole there")

SMOOTH_HOLES = HoleAssumption(
    "smooth-holes", "each hole lost a piece of a smooth surface continuing the one round it: a graph over the plane "
    "its fill is a graph over, whose curvature departs from the least-squares quadratic of the faces within two "
    "rings of the rim by at most twice what their quartic fit shows, with facets no longer than the edges there",
    "a feature, sharp edge or corner taken whole with the hole (a boss, a pocket, a box's corner), or a surface "
    "folding back over it")

FACETED_HOLES = HoleAssumption(
    "faceted-holes", "each hole not an island in a flat face lost a piece of a faceted surface that stays inside the "
    "planes of the faces round its rim (outside them round a pocket): the missing surface lies between the cone over "
    "the rim and those planes continued across the hole until they meet, as a graph over the plane square to the "
    "rim's vector area where the rim is one (a hole reaching round an edge of the part need not be)",
    "a boss, rib or housing standing out of those planes (or a dent into a pocket's) taken whole with the hole, a "
    "surface folding back over the hole, or a curved surface bulging past the planes of its facets")

#: The assumptions a user may state (``LoadOptions.assume``, ``--assume``): each is what the file cannot show,
#: so the tool never makes it on its own; with one stated, the holes it covers get the narrower bound it implies
#: and the estimate names it as the user's (:func:`user_stated`).
USER_ASSUMPTIONS = (FLAT_ISLANDS, SMOOTH_HOLES, FACETED_HOLES)

#: The end of a refusal of a hole that is an island in a flat face: the option that would take it.
ISLAND_HINT = " or, if the lost surface was flat, `assume` flat-islands"

#: The same for holes that are not islands: the user may know the surface round them went on smoothly.
SMOOTH_HINT = " or, if the surface round each hole is smooth and went on smoothly across it, `assume` smooth-holes"
FACETED_HINT = (" or, if the part round each hole is flat faces meeting at edges and stays inside their planes, "
                "`assume` faceted-holes")


def holes_hint(assumed: Iterable[str]) -> str:
    """The "ball too large" refusal's way on: each hole assumption (:data:`SMOOTH_HOLES`, :data:`FACETED_HOLES`)
    the user has not stated yet, as a clause to append to the refusal's reason ("" when both are stated)."""
    stated = set(assumed)
    return "".join(hint for a, hint in ((SMOOTH_HOLES, SMOOTH_HINT), (FACETED_HOLES, FACETED_HINT))
                   if a.name not in stated)


def user_named(names: Iterable[str]) -> tuple[str, ...]:
    """``names`` checked against :data:`USER_ASSUMPTIONS`, in their order (``ValueError`` naming the known ones)."""
    wanted = list(names)
    known = [a.name for a in USER_ASSUMPTIONS]
    unknown = sorted({str(n) for n in wanted} - set(known))
    if unknown:
        raise ValueError(f"expected assumptions among {', '.join(known)}, got {', '.join(unknown)}")
    return tuple(n for n in known if n in wanted)


@dataclasses.dataclass(frozen=True)
class UserAssumptions:
    """The assumptions the user stated about the holes a repair fills, as the engine takes them (a parameter of
    every stage from :func:`~.prepare.prepare_mesh` to :func:`~.holes.patched_estimate`; hashable, so caches can
    be keyed by it).

    Attributes
    ----------
    names : tuple of str
        Names among :data:`USER_ASSUMPTIONS` (``("flat-islands",)``), each once, in that order: checked and
        ordered on construction (``ValueError`` for an unknown name, ``TypeError`` for a bare string).
    """

    names: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if isinstance(self.names, str) or not isinstance(self.names, (tuple, list, frozenset, set)):
            raise TypeError(f"Expected `names` to be a tuple of assumption names, got {self.names!r}")
        object.__setattr__(self, "names", user_named(self.names))

    def __contains__(self, name: object) -> bool:
        return name in self.names

    def __bool__(self) -> bool:
        return bool(self.names)


#: No assumption stated (the default of every stage).
NOTHING_ASSUMED = UserAssumptions()


def user_stated(names: Iterable[str]) -> str:
    """One line naming the user's assumptions an estimate took, with what breaks each (empty when none)."""
    chosen = [a for a in USER_ASSUMPTIONS if a.name in set(names)]
    return "; ".join(f"assumed by the user: {a.name}: {a.statement}; {a.fails_for} breaks it" for a in chosen)
