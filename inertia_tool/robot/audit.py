"""Declared ``<inertial>`` against what the geometry implies, link by link.

For each link with both a declared inertial and a geometry result (:class:`LinkInertial`):

* ``mass_ratio`` = declared mass / geometry mass (1 with ``keep_mass``);
* ``com_distance``: |declared − geometry centre of mass| in m, and relative to the link's size (the diagonal of
  its geometry's bounding box);
* ``inertia_difference``: ``‖I_decl − (m_decl/m_geom) I_geom‖_F / ‖(m_decl/m_geom) I_geom‖_F`` — the shapes
  compared at equal mass, both about their own centre of mass in link axes (Frobenius norm, so a tensor
  that is right but expressed in swapped or rotated axes shows up);
* the declared tensor's validity: positive principal moments and the triangle inequality ``I1 + I2 ≥ I3``
  (:func:`inertia_tool.robot.inertial.check_moments`, the checks Gazebo and MuJoCo apply);
* the implied density ``declared mass / geometry volume`` against the range of the material table
  (:data:`inertia_tool.units.MATERIALS`, 500–19300 kg/m³): outside it, mass and geometry disagree (a
  collision hull much larger than the part, a mass in grams, a mesh in millimetres);
* whether the declared centre of mass lies inside the link's geometry (bounding box, then winding number /
  closed-form inside tests).  A hollow or C-shaped part legitimately has its centre outside its material, so
  this is reported, not judged.

Where the tensors disagree, :func:`inertia_tool.robot.diagnose.diagnose_inertial` names the likely cause
(a unit or decimal slip, a tensor about the link origin, swapped axes, a placeholder) with its evidence and
the declared tensor with the cause undone; a declared tensor that the simulators refuse gets the nearest
valid one (:func:`~inertia_tool.robot.diagnose.nearest_valid_tensor`).

Every threshold is a keyword argument; an issue is a sentence in ``LinkAudit.issues``.
"""

from __future__ import annotations


from dataclasses import replace

import numpy as np

from ..errors import InertiaToolError
from ..mass.properties import MassProperties
from ..units import MATERIALS
from ..values import frozen_value
from .description import DeclaredInertial, RobotDescription
from .geometry import LinkInertial, element_bounds, points_inside_element
from .diagnose import copied_masses, diagnose_inertial, nearest_valid_tensor
from .inertial import MomentCheck, check_moments

__all__ = ["LinkAudit", "audit_links", "DENSITY_RANGE", "DEFAULT_COM_TOLERANCE", "DEFAULT_INERTIA_TOLERANCE",
           "DEFAULT_MASS_TOLERANCE"]

#: (lowest, highest) density of the material table, kg/m³.
DENSITY_RANGE = (min(MATERIALS.values()), max(MATERIALS.values()))

#: Declared and geometric centres of mass further apart than this fraction of the link size are an issue.
DEFAULT_COM_TOLERANCE = 0.05

#: A relative Frobenius difference of the tensors at equal mass above this is an issue.
DEFAULT_INERTIA_TOLERANCE = 0.25

#: A declared/geometry mass ratio further than this (relative) from 1 is an issue (not with ``keep_mass``).
DEFAULT_MASS_TOLERANCE = 0.25


@frozen_value
class LinkAudit:
    """One link's declared inertial judged against its geometry.

    Attributes
    ----------
    name : str
    declared : DeclaredInertial or None
    computed : MassProperties or None
        From the geometry, link frame.
    mass_ratio : float
        Declared / geometry mass; nan when either is missing.
    com_distance : float
        m between the declared and the geometric centre of mass; nan when either is missing.
    com_distance_relative : float
        ``com_distance`` over the link size (bounding-box diagonal of its geometry).
    inertia_difference : float
        Relative Frobenius difference at equal mass (see the module docstring); nan when either is missing.
    declared_check : MomentCheck or None
        Positivity and triangle inequality of the declared principal moments.
    implied_density : float
        kg/m³, declared mass / geometry volume; nan when either is missing.
    density_plausible : bool or None
        ``implied_density`` within :data:`DENSITY_RANGE`; None when not computed.
    com_in_bounding_box : bool or None
        The declared centre of mass lies in the geometry's bounding box (link frame).
    com_inside_geometry : bool or None
        It lies inside at least one geometry element (winding number for meshes).
    size : float
        m, bounding-box diagonal of the link geometry; nan without geometry.
    issues : tuple of str
        One sentence per finding beyond the tolerances, or about an invalid declaration.
    causes : tuple of Diagnosis
        Likely causes of a tensor disagreement, best first (empty when none explains it).
    nearest_valid_inertia : (3, 3) float or None
        kg·m²: for a declared tensor the simulators refuse, the nearest one they accept (same axes).
    """

    name: str
    declared: DeclaredInertial | None
    computed: MassProperties | None
    mass_ratio: float
    com_distance: float
    com_distance_relative: float
    inertia_difference: float
    declared_check: MomentCheck | None
    implied_density: float
    density_plausible: bool | None
    com_in_bounding_box: bool | None
    com_inside_geometry: bool | None
    size: float
    issues: tuple
    causes: tuple = ()
    nearest_valid_inertia: np.ndarray | None = None

    @property
    def ok(self) -> bool:
        """No issue found."""
        return not self.issues


def _declared_check(declared: DeclaredInertial) -> MomentCheck | None:
    tensor = 0.5 * (declared.inertia + declared.inertia.T)
    if not np.all(np.isfinite(tensor)):
        return None
    return check_moments(np.linalg.eigvalsh(tensor), min_moment=0.0)


def audit_links(robot: RobotDescription, inertials, *, com_tolerance: float = DEFAULT_COM_TOLERANCE,
          inertia_tolerance: float = DEFAULT_INERTIA_TOLERANCE, mass_tolerance: float = DEFAULT_MASS_TOLERANCE,
          keep_mass: bool = False) -> tuple:
    """Audit every link of ``robot`` against the geometry results ``inertials`` (:func:`link_inertials`).

    Parameters
    ----------
    robot : RobotDescription
    inertials : sequence of LinkInertial
        In the order of ``robot.links``.
    com_tolerance : float
        Relative (to the link size) centre-of-mass distance above which an issue is raised (default 0.05).
    inertia_tolerance : float
        Relative Frobenius tensor difference at equal mass above which an issue is raised (default 0.25).
    mass_tolerance : float
        Relative mass difference above which an issue is raised (default 0.25); not applied with
        ``keep_mass`` (the masses are equal by construction).
    keep_mass : bool
        The geometry results were scaled to the declared masses.

    Returns
    -------
    tuple of LinkAudit
    """
    by_name = {i.name: i for i in inertials}
    out = []
    for link in robot.links:
        result: LinkInertial | None = by_name.get(link.name)
        computed = result.properties if result is not None else None
        declared = link.declared
        issues = []
        check = _declared_check(declared) if declared is not None else None
        massless_frame = (declared is not None and declared.mass == 0 and not np.any(declared.inertia)
                          and not link.elements)          # a virtual frame (tool0, world): legitimate
        if declared is not None and not massless_frame:
            if not declared.mass > 0:
                issues.append(f"declared mass {declared.mass:g} kg is not positive")
            elif check is not None and not check.ok:
                issues.append(f"declared inertia is not physical: {check.problem()}")
        if result is not None and result.problem and link.elements and result.problem not in issues:
            issues.append(result.problem)
        causes: tuple = ()
        nearest = None
        if check is not None and not check.ok and declared is not None and not massless_frame:
            nearest = nearest_valid_tensor(declared.inertia)
        nan = float("nan")
        mass_ratio = com_distance = com_rel = inertia_diff = implied = size = nan
        plausible = in_box = inside = None
        lo = hi = None
        if link.elements and computed is not None:
            try:
                bounds = [element_bounds(e) for e in link.elements]
            except (InertiaToolError, ValueError):      # a mesh the engine only read with repair: no box
                bounds = []
            if bounds:
                lo = np.min([b[0] for b in bounds], axis=0)
                hi = np.max([b[1] for b in bounds], axis=0)
                size = float(np.linalg.norm(hi - lo))
        if computed is not None and declared is not None and declared.mass > 0:
            mass_ratio = declared.mass / computed.mass
            com_distance = float(np.linalg.norm(declared.center_of_mass - computed.center_of_mass))
            com_rel = com_distance / size if size > 0 else nan
            reference = computed.inertia * mass_ratio
            inertia_diff = float(np.linalg.norm(declared.inertia - reference) / np.linalg.norm(reference))
            implied = declared.mass / computed.volume
            plausible = bool(DENSITY_RANGE[0] <= implied <= DENSITY_RANGE[1])
            c = declared.center_of_mass
            if lo is not None and hi is not None:
                in_box = bool(np.all(c >= lo - 1e-12 * size) and np.all(c <= hi + 1e-12 * size))
                try:
                    inside = bool(in_box and any(points_inside_element(e, c) for e in link.elements))
                except (InertiaToolError, ValueError):
                    inside = None
            if not keep_mass and abs(mass_ratio - 1.0) > mass_tolerance:
                issues.append(f"declared mass {declared.mass:.4g} kg is {mass_ratio:.3g}× the geometry's "
                              f"{computed.mass:.4g} kg")
            if com_rel > com_tolerance:
                issues.append(f"declared centre of mass is {com_distance * 1e3:.1f} mm ({com_rel:.0%} of the link "
                              "size) from the geometry's")
            if inertia_diff > inertia_tolerance:
                issues.append(f"declared inertia differs from the geometry's by {inertia_diff:.0%} at equal mass")
            if not plausible:
                issues.append(f"implied density {implied:.4g} kg/m³ is outside every material's "
                              f"({DENSITY_RANGE[0]:g}–{DENSITY_RANGE[1]:g} kg/m³)")
            if inertia_diff > inertia_tolerance or not plausible:
                causes = diagnose_inertial(declared.mass, declared.center_of_mass, declared.inertia, computed.mass,
                                           computed.inertia, tolerance=inertia_tolerance,
                                           geometry_volume=computed.volume, density_range=DENSITY_RANGE,
                                           geometry_extents=None if lo is None or hi is None else hi - lo)
                issues += [f"likely cause: {c.explanation}" for c in causes]
            if in_box is False:
                issues.append("declared centre of mass lies outside the link geometry's bounding box")
            elif inside is False and _own_centre_inside(link, computed.center_of_mass):
                # a hollow or bent link's own centre of mass lies outside its material too: there a declared
                # centre outside is no evidence of a slip (its distance from the geometry's is judged above)
                issues.append("declared centre of mass lies outside the link geometry (in its bounding box), "
                              "where the geometry's own centre of mass lies inside it")
        out.append(LinkAudit(name=link.name, declared=declared, computed=computed, mass_ratio=mass_ratio,
                             com_distance=com_distance, com_distance_relative=com_rel, inertia_difference=inertia_diff,
                             declared_check=check, implied_density=implied, density_plausible=plausible,
                             com_in_bounding_box=in_box, com_inside_geometry=inside, size=size, issues=tuple(issues),
                             causes=causes, nearest_valid_inertia=nearest))
    if keep_mass:                    # the geometry was scaled to the declared masses: no mass disagrees
        return tuple(out)
    missing = float("nan")
    copied = copied_masses([a.name for a in out],
                           [a.declared.mass if a.declared is not None else missing for a in out],
                           [a.computed.mass if a.computed is not None else missing for a in out],
                           mass_tolerance=mass_tolerance)
    return tuple(replace(a, causes=a.causes + (copied[a.name],),
                         issues=a.issues + (f"likely cause: {copied[a.name].explanation}",))
                 if a.name in copied else a for a in out)


def _own_centre_inside(link, centre: np.ndarray) -> bool:
    """True unless the geometry's own centre of mass is known to lie outside every element of ``link``."""
    try:
        return any(points_inside_element(e, centre) for e in link.elements)
    except (InertiaToolError, ValueError):
        return True
