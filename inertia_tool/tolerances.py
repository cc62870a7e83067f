"""Every numerical tolerance of the package, named and documented in one place.

Each is the *default* of a keyword argument of the function that uses it (STYLE §9: no global tolerance
object; a caller who needs another value passes it).  All are relative, dimensionless, and state what they are
relative to.
"""

#: Two principal moments count as equal when ``|I_a − I_b| ≤ EQUAL_MOMENTS_RTOL · max(I)``.  Decides labels
#: ("symmetric", "marginal"), the deterministic basis of an equal-moment plane and the
#: :class:`~inertia_tool.errors.NearlyEqualMomentsWarning`.  A faceted solid of revolution with a few hundred
#: segments has moments equal to about 1e-7, so 1e-6 calls it symmetric.
EQUAL_MOMENTS_RTOL = 1e-6

#: Slack of the physical-validity checks ``I_k > 0`` and ``I_1 + I_2 ≥ I_3`` (the perpendicular-axis theorem
#: of Chapter 4, "Rigid Body Motion", §4.3, turned into an inequality), relative to the largest moment.  A flat
#: plate meets the triangle inequality with equality, so round-off must not count against it.
TRIANGLE_INEQUALITY_RTOL = 1e-9

#: Spacing of the tolerance weld that joins nearly coincident vertices when the bit-exact weld leaves the
#: surface open, relative to the bounding-box diagonal.
MERGE_TOLERANCE = 1e-6

#: A shell whose |volume| is at most ``FLAT_RTOL · diagonal³`` encloses nothing (a sheet or a collapsed
#: surface).
FLAT_RTOL = 1e-12

#: A flat piece (|volume| ≤ FLAT_RTOL · diagonal³) is left out only when leaving it out changes the answer by no
#: more than round-off: its volume at most this fraction of the rest's, and its second moment about the rest's
#: centroid at most this fraction of the rest's.  A thin but real solid far from the rest (a 27 m long sliver
#: 27 m away moves the inertia by 5e-5) stays and is integrated as it stands.
FLAT_MOMENT_RTOL = 1e-12

#: Touching shells share no volume when the boolean union's volume equals their summed volume within this
#: (relative; rule R6 of ``mesh/policy.py``).  For touching shells of well-shaped triangles manifold3d keeps
#: the input vertices and adds only intersection vertices, so the two integrals differ by float64 rounding
#: (about faces · 2⁻⁵³, below 1e-10 up to millions of faces); a genuine overlap smaller than this changes the
#: mass by less than 1e-9 of itself, below any stated precision of the inputs.  manifold3d also collapses
#: degenerate slivers, which can move the volume by more (3e-8 on a patched 1.6k-face part): such a result
#: is certified ``unverified``, never silently exact.
TOUCH_VOLUME_RTOL = 1e-9

#: A body whose smallest principal moment is at most ``NEEDLE_RTOL`` of the largest is a needle to round-off:
#: its smallest moment carries no correct digit.
NEEDLE_RTOL = 1e-10

#: A matrix passed as a rotation must satisfy ``‖R Rᵀ − 1‖∞ ≤ ROTATION_ATOL`` and ``det R > 0``.
ROTATION_ATOL = 1e-9

#: Display only: tensor products and coordinates below ``DISPLAY_ZERO_RTOL`` of the body's scale print as 0
#: (round-off, not data).  Never applied to a computed value that is returned.
DISPLAY_ZERO_RTOL = 1e-12

#: A float32 file (binary STL, PLY ``float``, glTF/GLB, COLLADA) whose storage rounding bounds the volume only to
#: worse than ``STORAGE_PRECISION_RTOL`` relative gets a :class:`~inertia_tool.errors.StoragePrecisionWarning`
#: (the bound: :mod:`inertia_tool.mesh.precision`).  float32 rounds each coordinate by up to 2⁻²⁴ of its
#: magnitude, and the bound is about 60x that over the part's size, so a compact part near its origin is bounded
#: to ~4e-6 whatever it is: the warning is for a part far from the origin (or a film far thinner than its
#: coordinates), where the file itself has lost digits the reports would print.
STORAGE_PRECISION_RTOL = 1e-4

#: A reference point farther than ``FAR_POINT_RATIO`` part sizes (bounding-box diagonal, or twice the radius
#: of gyration without a mesh) from the centre of mass is warned about (``ImplausiblePointWarning``): a
#: millimetre point read as metres lands 1000 sizes away from a 1-m part, and a point 100 sizes away changes
#: the tensor by 10⁴ times the central one — rarely what anyone meant.
FAR_POINT_RATIO = 100.0

#: spin-it (top): a pivot outside the part and farther than this fraction of the part's largest extent from its
#: surface is warned about (``PivotOffPartWarning``).  A top's pivot is a point of its surface (its tip); 2 % of
#: the extent leaves room for a tip rounded by the mesh's facets or a pivot given to a rounded coordinate.
PIVOT_GAP_RTOL = 0.02

#: Default manufacturing tolerance on the principal moments of a printed part (``--shell``/``--infill``),
#: relative to the largest: an FDM print holds its dimensions to about ±0.1–0.2 mm on a few centimetres
#: (≈ 0.5 % of a length, so ≈ 1 % of a moment ∝ m L²), and its infill pattern is neither uniform nor isotropic.
#: Two moments closer than this are "indifferent within tolerance" (``stability(moment_tolerance=...)``).
PRINTED_MOMENT_TOLERANCE = 0.01
#: Repair (``repair=True``): boundary vertices closer than ``SEAM_GAP_RTOL · diagonal`` to another boundary
#: vertex, or to a boundary edge (a T-junction), are taken to be one seam that the export split, and are
#: sealed.  Openings narrower than this are read as artefacts, not slots; the bound of the sealed estimate
#: covers the move (see :mod:`inertia_tool.mesh.uncertainty`).
SEAM_GAP_RTOL = 1e-4

#: Repair: an estimate whose relative mass bound exceeds this (or whose centre-of-mass or inertia bound is not
#: finite) is refused instead of printed — a mass "within ±60 %" says nothing the user can build on.
ESTIMATE_MAX_MASS_RTOL = 0.5

#: Repair: a surface more than this share of whose faces share no edge with another face is a soup (loose
#: triangles, not a surface with holes); its solid is read from the winding number, not by patching loops.
SOUP_BOUNDARY_SHARE = 0.5

#: Two parts of an assembly (a multi-material file, FILE:material files) overlap when the volume they share is
#: more than this fraction of the smaller one's: then the shared volume is counted once per part, and an
#: :class:`~inertia_tool.errors.OverlapWarning` names the parts, their materials and the shared volume.  Parts
#: that only touch (an insert in its pocket) share a sliver from the rounding of their written coordinates: a
#: text file with 6 to 9 significant digits moves a face by 1e-9 to 1e-6 of the part's size, and spin-it's own
#: insert shares 1.6e-10 of its volume with the part as written before coordinates were written in full.
PART_OVERLAP_RTOL = 1e-7

#: Intersection points of a self-crossing shell's arrangement (mesh/arrange.py) closer than this times the
#: bounding-box diagonal are merged when, rounded to float64, they leave faces crossing: a crossing in special
#: position (an edge exactly through an edge, common in symmetric meshes) splits one true point into several
#: within rounding of each other; merging them moves the surface by at most this relative distance.
ARRANGE_MERGE_RTOL = 1e-12

#: "Exact" for a float64 integral means: the volume within ``ROUNDOFF_RTOL`` of the polyhedron's (relative to the
#: total volume) and the inertia within ``ROUNDOFF_RTOL`` of the total's (Frobenius), by the derived floating-point
#: bound of :func:`inertia_tool.integrals.roundoff_bounds`.  A shell whose bound is larger (a sliver thinner than
#: its coordinates' rounding can carry, a part far from the rest) is integrated again in exact integer arithmetic
#: (:func:`inertia_tool.integrals.exact_volume_moments`); one too large for that is certified ``unverified``.
ROUNDOFF_RTOL = 1e-10

#: Two closed surfaces that repeat each other corner for corner with every corner within ``COINCIDENT_RTOL`` times
#: the largest |coordinate| of the pair are one surface listed twice up to rounding (R0 of mesh/policy.py): a copy
#: whose coordinates were computed apart (the same rigid motion applied in another order) differs by a few units
#: in the last place, 2⁻⁵³ each; 64 of them leave room for a dozen roundings per coordinate.  Counted once only
#: when the bound on what the copy could add (its corners' δ-neighbourhood of the surface) is within
#: ``ROUNDOFF_RTOL`` of the result.
COINCIDENT_RTOL = 64 * 2.0 ** -53

#: The principal moments of a 3×3 tensor as float64 computes them (``numpy.linalg.eigvalsh``, a backward-stable
#: symmetric eigensolver: the exact moments of a tensor within a few ``u ‖Î‖`` of the given one, ``u = 2⁻⁵³``) and
#: the sums ``I_i + I_j − I_k`` of MuJoCo's inertia box (two roundings of terms at most ``‖Î‖``) are within
#: ``EIGEN_ROUNDOFF_RTOL · ‖Î‖_F`` of the exact values: measured at most 5 ``u`` on turned flat boxes (review 11);
#: 64 ``u`` leaves a factor of ten.  A bound on what is fitted to a tensor adds it to the tensor's own bound
#: (robot.geometry.fitted_mass_bound): a flat part's smallest sum is below the round-off of the others.
EIGEN_ROUNDOFF_RTOL = 64 * 2.0 ** -53

#: A printed bound is rounded up (``rounding.round_up``) from the stored value raised by this much: the float64
#: sums and products a bound comes from (``100 * mass``, a ratio of two volume sums) land a few units in the last
#: place, 2⁻⁵³ each, from the exact value, and the printed number must cover the exact one.  An exact decimal
#: such as 25 % is therefore printed one step up (26 % at two digits): the price of never printing too little.
PRINTED_BOUND_RTOL = 1e-12

#: The corners of an internal wall (R3a of mesh/policy.py: two coplanar sheets of opposite orientation, e.g. the
#: two halves of a part written face to face with their cut faces triangulated apart) lie within ``WALL_PLANE_RTOL``
#: times the largest |coordinate| of one plane: cut points computed on a plane are off it by a few units of
#: rounding (2⁻⁵³ each).  Only a filter: whether leaving a wall out keeps the answer exact is decided by the volume
#: in which its sheets can differ (2·distance·area, mesh/folds.py), which must be within ``ROUNDOFF_RTOL``.
WALL_PLANE_RTOL = 1e-12

# -- limits on the input (guards, not tolerances; here so that a command's parser states them without loading
#    the mesh layer) ---------------------------------------------------------------------------------------------

#: Default guard on the number of triangles a file may hold (``LoadOptions.max_faces``).  Peak memory at the
#: limit (``docs/bad-input.md``; ``benchmarks/bench_memory.py``): binary STL ~63 MiB + 37 B per face with the C
#: extension (1.8 GiB at 50M), 77 B per face on the numpy path; a 3MF (streaming reader, ``mesh.threemf``)
#: ~150 B per face for a whole ``analyze`` run; other formats per ``benchmarks/bench_memory.py --formats``.
DEFAULT_MAX_FACES = 50_000_000

#: Most triangles any reader accepts, whatever ``max_faces`` says: the welders number the 3 corners of every
#: triangle with 32-bit integers, so 3 x faces must stay below 2^31 (715,827,882 triangles, ~36 GB of
#: binary STL).  A file announcing more is refused from its header, before anything is allocated.
MAX_SUPPORTED_FACES = (2**31 - 1) // 3

#: Most output samples of a simulated trajectory (``spin``'s experiment, ``top``'s heavy top): bounds memory
#: (~100 B a sample) and the integrator's work.
MAX_TRAJECTORY_SAMPLES = 400_001
