"""MJCF constructs MuJoCo models ship with that the reader once refused (issue 23): height fields in a body
(MuJoCo's inertia box), inline meshes (``<mesh vertex face>``, and ``vertex`` alone: the convex hull),
``<attach>`` of a model asset.  The independent reference is MuJoCo's own compiler (``mujoco`` 4.0): body
masses, centres and inertias."""

import numpy as np
import pytest

from inertia_tool.errors import RobotDescriptionError
from inertia_tool.robot import link_inertials, read_robot
from inertia_tool.robot.mjspec import compare_with_mujoco

from mujoco_reference import assert_like_mujoco, mujoco_bodies

mujoco = pytest.importorskip("mujoco")


# -- height fields ------------------------------------------------------------------------------------------

HFIELD = """<mujoco><compiler inertiafromgeom="true"/>
<asset><hfield name="terrain" nrow="3" ncol="4" size="1 2 0.5 0.1" elevation="0 1 0 1 1 1 0 0 0 1 1 1"/>
<hfield name="bump" nrow="2" ncol="2" size="0.3 0.2 0.04 0.02"/></asset>
<worldbody><geom type="hfield" hfield="terrain"/>
<body name="a" pos="0 0 1"><freejoint/>
<geom type="hfield" hfield="bump" pos="0.3 0.2 0.1" euler="10 20 30" density="7"/>
<geom type="sphere" size="0.1" pos="0 0 -0.2"/></body>
</worldbody></mujoco>"""


def test_terrain_in_the_world_is_skipped_and_a_body_height_field_is_mujocos_box(tmp_path):
    path = tmp_path / "hfield.xml"
    path.write_text(HFIELD)
    robot = read_robot(path)
    results = link_inertials(robot, density="model")
    assert_like_mujoco(path, results, rtol=1e-12)
    (a,) = results
    assert any("height field 'bump'" in w and "0.6 x 0.4 x 0.04 m" in w for w in a.warnings), a.warnings
    assert compare_with_mujoco(robot) == ()


def test_the_height_field_box_is_the_closed_form(tmp_path):
    # independent of MuJoCo: half-sizes (rx, ry, elevation/4 + base/2) at the geom's frame, one density
    path = tmp_path / "hfield.xml"
    path.write_text(HFIELD)
    props = link_inertials(read_robot(path), density=1000)[0].properties
    a, b, c = 0.6, 0.4, 2 * (0.04 / 4 + 0.02 / 2)
    box_mass = 1000 * a * b * c
    sphere_mass = 1000 * 4 / 3 * np.pi * 0.1 ** 3
    assert props.mass == pytest.approx(box_mass + sphere_mass, rel=1e-13)


def test_an_undefined_height_field_is_named(tmp_path):
    path = tmp_path / "h.xml"
    path.write_text('<mujoco><worldbody><body name="b"><geom type="hfield" hfield="nowhere"/></body>'
                    '</worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="height field 'nowhere' is not defined"):
        read_robot(path)
    path.write_text('<mujoco><worldbody><body name="b"><geom type="hfield"/></body></worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="a height field geom without hfield"):
        read_robot(path)


# -- inline meshes ------------------------------------------------------------------------------------------

def _octahedron(a=0.1, b=0.2, c=0.3):
    vertices = [(a, 0, 0), (-a, 0, 0), (0, b, 0), (0, -b, 0), (0, 0, c), (0, 0, -c)]
    faces = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    return (" ".join(f"{x:g} {y:g} {z:g}" for x, y, z in vertices), " ".join(f"{i} {j} {k}" for i, j, k in faces))


def test_inline_vertex_and_face_match_mujoco_with_scale_and_reference_frame(tmp_path):
    vertex, face = _octahedron()
    path = tmp_path / "inline.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true" angle="radian"/><asset>'
                    f'<mesh name="octa" vertex="{vertex}" face="{face}" scale="1 2 0.5" refpos="0.01 0.02 0.03" '
                    'refquat="0.9 0.1 0.2 0.3"/></asset><worldbody>'
                    '<body name="a"><freejoint/><geom type="mesh" mesh="octa" pos="0.1 0.2 0.3" euler="0.1 0.2 0.3" '
                    'density="500"/><geom type="box" size="0.01 0.02 0.03" pos="0.3 0 0"/></body>'
                    '<body name="b"><freejoint/><geom type="mesh" mesh="octa"/></body></worldbody></mujoco>')
    robot = read_robot(path)
    assert robot.links[0].elements[0].mesh is None and robot.links[0].elements[0].vertices.shape == (6, 3)
    # MuJoCo keeps mesh vertices in float32 (0.1 is not one): agreement to its rounding, not to 1e-9
    assert_like_mujoco(path, link_inertials(robot, density="model"), rtol=1e-6)
    assert compare_with_mujoco(robot) == ()


def test_inline_octahedron_is_the_closed_form(tmp_path):
    # independent of MuJoCo: the octahedron of semi-axes a, b, c has V = 4abc/3 and I_xx = V (b² + c²)/10
    vertex, face = _octahedron(0.1, 0.2, 0.3)
    path = tmp_path / "octa.xml"
    path.write_text(f'<mujoco><asset><mesh name="o" vertex="{vertex}" face="{face}"/></asset><worldbody>'
                    '<body name="b"><geom type="mesh" mesh="o"/></body></worldbody></mujoco>')
    props = link_inertials(read_robot(path), density=1.0)[0].properties
    volume = 4 * 0.1 * 0.2 * 0.3 / 3
    assert props.volume == pytest.approx(volume, rel=1e-13)
    expected = volume / 10 * np.array([0.2 ** 2 + 0.3 ** 2, 0.1 ** 2 + 0.3 ** 2, 0.1 ** 2 + 0.2 ** 2])
    np.testing.assert_allclose(np.diag(props.inertia), expected, rtol=1e-12)


def test_vertex_without_face_is_mujocos_convex_hull(tmp_path):
    # the corners of a 1 x 2 x 3 box, points inside it and on its faces: the hull is the box
    rng = np.random.default_rng(23)
    corners = [(x, y, z) for x in (0, 1) for y in (0, 2) for z in (0, 3)]
    inside = rng.uniform(0.1, 0.9, (20, 3)) * (1, 2, 3)
    on_faces = np.column_stack([np.zeros(5), rng.uniform(0, 2, 5), rng.uniform(0, 3, 5)])
    points = np.vstack([inside[:10], corners, on_faces, inside[10:]])
    vertex = " ".join(f"{v!r}" for v in points.ravel().tolist())
    path = tmp_path / "hull.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true"/><asset>'
                    f'<mesh name="h" vertex="{vertex}" scale="1 1 2" refpos="0.5 0 0"/></asset><worldbody>'
                    '<body name="b"><freejoint/><geom type="mesh" mesh="h" pos="0 0 1"/></body></worldbody></mujoco>')
    robot = read_robot(path)
    results = link_inertials(robot, density=1000)
    assert_like_mujoco(path, results, rtol=1e-9)
    props = results[0].properties
    assert props.mass == pytest.approx(1000 * 1 * 2 * 6, rel=1e-12)
    np.testing.assert_allclose(props.center_of_mass, [0, 1, 4], atol=1e-12)
    assert results[0].method == "exact"


@pytest.mark.parametrize("mesh, message", [
    ('vertex="0 0 0 1 0 0 0 1 0"', "4 to"),
    ('vertex="0 0 0 1 0 0 0 1 0 0 0"', "x y z"),
    ('vertex="0 0 0 1 0 0 0 1 0 2 2 0"', "span no volume"),
    ('vertex="0 0 0 1 0 0 0 1 0 0 0 1" face="0 1 4"', "whole vertex indices from 0 to 3"),
    ('vertex="0 0 0 1 0 0 0 1 0 0 0 1" face="0 1 2.5"', "whole vertex indices"),
    ('vertex="0 0 0 1 0 0 0 1 0 0 0 1" face="0 1"', "triples"),
    ('face="0 1 2"', "face without vertex"),
    ('vertex="0 0 0 1 0 0 0 1 0 0 0 1" file="x.stl"', "both a file and inline vertices"),
    ('builtin="sphere"  params="1 2 3 4 5 6 7 8 9"', "MuJoCo refuses builtin='sphere'"),
    ('builtin="sphere" params="1" file="x.stl"', "also a file or vertices"),
])
def test_bad_inline_meshes_are_one_sentence(tmp_path, mesh, message):
    path = tmp_path / "bad.xml"
    path.write_text(f'<mujoco><asset><mesh name="m" {mesh}/></asset><worldbody><body name="b">'
                    '<geom type="mesh" mesh="m"/></body></worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match=message) as caught:
        read_robot(path)
    assert "\n" not in str(caught.value)


# -- <attach> -----------------------------------------------------------------------------------------------

CHILD = """<mujoco model="child"><compiler angle="radian" meshdir="meshes"/>
<default><geom density="2000"/><default class="k"><geom type="box" size="0.1 0.1 0.1"/></default></default>
<asset><mesh name="part" file="part.stl" refpos="0.01 0 0"/><model name="gm" file="grand.xml"/></asset>
<worldbody><body name="root" pos="1 0 0"><geom type="mesh" mesh="part"/>
<body name="hand" pos="0 0 1" euler="0.5 0 0" childclass="k"><geom euler="0.3 0 0" pos="0.1 0 0" size="0.1 0.2 0.3"/>
<geom type="mesh" mesh="part" pos="0 0 0.5"/>
<body><geom type="sphere" size="0.05"/></body>
<body name="finger"><geom size="0.02"/><attach model="gm" body="tip" prefix="g_"/></body></body></body>
</worldbody></mujoco>"""

GRAND = """<mujoco model="grand"><compiler meshdir="g"/>
<asset><mesh name="part" file="part.stl" scale="2 1 1"/></asset>
<worldbody><geom type="box" size="0.1 0.2 0.3" pos="1 0 0" euler="0 30 0"/>
<body name="tip"><geom type="mesh" mesh="part"/></body><body name="other"><geom size="0.3"/></body></worldbody>
</mujoco>"""

MAIN = """<mujoco model="main"><compiler meshdir="meshes"/>
<asset><model name="c" file="sub/child.xml"/><model name="w" file="sub/grand.xml"/>
<mesh name="part" file="part.stl"/></asset>
<worldbody><body name="base"><geom type="mesh" mesh="part"/>
<body name="first"><geom size="0.1"/></body>
<attach model="c" body="hand" prefix="c_"/>
<body name="last"><geom size="0.1 0.2 0.3" euler="30 0 0" type="box"/>
<frame pos="0 1 0" euler="0 0 45"><attach model="w" prefix="w_"/></frame></body>
</body></worldbody></mujoco>"""


@pytest.fixture
def attached(tmp_path):
    """A model attaching a body of a child model (own angle unit, meshdir, defaults, childclass), which attaches
    a body of a grandchild (own meshdir and mesh scale); and the grandchild's whole worldbody in a frame (its
    world geom joins the enclosing body)."""
    from inertia_tool.mass import shapes
    for folder, size in (("meshes", (0.3, 0.2, 0.1)), ("sub/meshes", (0.1, 0.2, 0.3)), ("sub/g", (0.1, 0.1, 0.2))):
        (tmp_path / folder).mkdir(parents=True)
        shapes.write_stl(shapes.box(*size), tmp_path / folder / "part.stl")
    (tmp_path / "sub" / "child.xml").write_text(CHILD)
    (tmp_path / "sub" / "grand.xml").write_text(GRAND)
    (tmp_path / "main.xml").write_text(MAIN)
    return tmp_path / "main.xml"


def test_attached_bodies_are_read_as_mujoco_reads_them(attached):
    robot = read_robot(attached)
    assert [link.name for link in robot.links] == ["base", "first", "c_hand", "body 4", "c_finger", "c_g_tip",
                                                   "last", "w_tip", "w_other"]
    assert_like_mujoco(attached, link_inertials(robot, density="model"), rtol=1e-9)
    assert compare_with_mujoco(robot) == ()


def test_attached_with_one_density_matches_mujoco_at_that_density(attached, tmp_path):
    # the child's default density is 2000: with MuJoCo told 2000 in the other two models, density=2000 agrees
    default = '<default><geom density="2000"/></default>'
    attached.write_text(MAIN.replace('<mujoco model="main">', f'<mujoco model="main">{default}'))
    (tmp_path / "sub" / "grand.xml").write_text(GRAND.replace("<compiler", f"{default}<compiler"))
    assert_like_mujoco(attached, link_inertials(read_robot(attached), density=2000), rtol=1e-9)


@pytest.mark.parametrize("attach, message", [
    ('<attach model="c" body="hand"/>', "expected a prefix"),
    ('<attach model="nowhere" body="hand" prefix="x_"/>', "no <asset><model name='nowhere'>"),
    ('<attach model="c" body="nobody" prefix="x_"/>', "has no body 'nobody'"),
    ('<attach model="self" body="base" prefix="x_"/>', "attaches itself"),
    ('<attach model="missing" body="b" prefix="x_"/>', "does not exist"),
])
def test_attach_problems_are_one_sentence(attached, attach, message):
    text = MAIN.replace('<attach model="c" body="hand" prefix="c_"/>', attach).replace(
        "<asset>", '<asset><model name="self" file="main.xml"/><model name="missing" file="no.xml"/>')
    attached.write_text(text)
    with pytest.raises(RobotDescriptionError, match=message) as caught:
        read_robot(attached)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("builtin, params", [
    ("sphere", "1"), ("hemisphere", "2"), ("supersphere", "10 0.5 0.5"),
    ("cone", "8 0.5"), ("wedge", "8 8 60 30 1"),                 # MuJoCo gives points only: their convex hull
    ("supertorus", "16 0.3 0.5 0.5"),                            # not convex: MuJoCo's exact inertia
])
def test_builtin_meshes_are_mujocos_triangles(tmp_path, builtin, params):
    path = tmp_path / "builtin.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true"/><asset>'
                    f'<mesh name="m" builtin="{builtin}" params="{params}" scale="0.1 0.2 0.15" refpos="0.01 0 0.02" '
                    'refquat="1 0.2 0 0.1" inertia="exact"/></asset><worldbody><body name="b"><freejoint/>'
                    '<geom type="mesh" mesh="m" pos="0.1 0 0" euler="10 20 30"/></body></worldbody></mujoco>')
    robot = read_robot(path)
    results = link_inertials(robot, density=1000)
    assert results[0].method == "exact", results[0].problem
    assert_like_mujoco(path, results, rtol=1e-6)      # MuJoCo keeps mesh vertices in float32


# -- <replicate> of geoms in a body ------------------------------------------------------------------------

@pytest.mark.parametrize("angle, turn", [("degree", "0 10 30"), ("radian", "0.1 0.2 0.5")])
def test_geoms_replicated_in_a_body_are_all_counted_where_mujoco_puts_them(tmp_path, angle, turn):
    # the reader once skipped geoms inside a <replicate> in a body: the body's mass lacked every copy
    path = tmp_path / "rep.xml"
    path.write_text(f'<mujoco><compiler inertiafromgeom="true" angle="{angle}" eulerseq="zyx"/><worldbody>'
                    '<body name="wheel"><freejoint/><geom type="cylinder" size="0.05 0.02"/>'
                    f'<replicate count="5" offset="0.2 0 0.01" euler="{turn}">'
                    '<geom type="box" size="0.05 0.01 0.02" pos="0.2 0.1 0" euler="0.3 0 0"/>'
                    '<frame pos="0 0 0.05"><replicate count="2" offset="0 0.1 0">'
                    '<geom type="capsule" size="0.01 0.03" pos="0 0 0.1"/></replicate></frame>'
                    '</replicate></body></worldbody></mujoco>')
    robot = read_robot(path)
    assert len(robot.links[0].elements) == 1 + 5 * (1 + 2)
    assert_like_mujoco(path, link_inertials(robot, density=1000), rtol=1e-9)
    assert compare_with_mujoco(robot) == ()


def test_a_copy_written_elsewhere_still_attaches_its_model(attached, tmp_path):
    # the attached bodies live in the model files, which are not written: they are named as left as they were,
    # and the copy's <model file> is re-expressed from its own folder, so MuJoCo still finds the child
    from inertia_tool.robot.write import write_corrected
    robot = read_robot(attached)
    out = tmp_path / "elsewhere" / "deeper" / "main.xml"
    out.parent.mkdir(parents=True)
    changed = write_corrected(robot, link_inertials(robot, density="model"), out)
    assert set(changed) == {"base", "first", "last"}
    theirs = mujoco_bodies(out)
    assert set(theirs) == set(mujoco_bodies(attached))
    assert theirs["c_g_tip"][0] == pytest.approx(mujoco_bodies(attached)["c_g_tip"][0], rel=1e-12)


# -- adversarial: generated replicates and point clouds against MuJoCo ---------------------------------------

from hypothesis import example, given, settings, strategies as st  # noqa: E402

_angles = st.lists(st.floats(-180, 180, allow_nan=False).map(lambda a: round(a, 3)), min_size=3, max_size=3)
_offset = st.lists(st.floats(-0.5, 0.5, allow_nan=False).map(lambda a: round(a, 4)), min_size=3, max_size=3)


@settings(max_examples=25, deadline=None)
@given(count=st.integers(1, 6), angles=_angles, offset=_offset, sequence=st.sampled_from(["xyz", "zyx", "XYZ", "xYz"]),
       inner=st.integers(1, 3))
def test_generated_replicates_of_geoms_match_mujoco(tmp_path_factory, count, angles, offset, sequence, inner):
    path = tmp_path_factory.mktemp("rep") / "r.xml"
    turn, step = " ".join(map(str, angles)), " ".join(map(str, offset))
    path.write_text(f'<mujoco><compiler inertiafromgeom="true" eulerseq="{sequence}"/><worldbody><body name="b">'
                    f'<geom type="sphere" size="0.05"/><replicate count="{count}" offset="{step}" euler="{turn}">'
                    '<geom type="box" size="0.05 0.01 0.02" pos="0.2 0.1 0" euler="30 0 10"/>'
                    f'<replicate count="{inner}" offset="{step}" euler="{turn}"><geom type="capsule" size="0.01 0.03" '
                    'pos="0 0.05 0.1"/></replicate></replicate></body></worldbody></mujoco>')
    robot = read_robot(path)
    assert_like_mujoco(path, link_inertials(robot, density=1000), rtol=1e-9)
    assert compare_with_mujoco(robot) == ()


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), count=st.integers(4, 40), flat=st.booleans())
@example(seed=123299, count=4, flat=False)        # a thin tetrahedron: MuJoCo's float32 points move it by 1.5e-5
def test_generated_point_clouds_are_mujocos_hull(tmp_path_factory, seed, count, flat):
    # random points (some on a grid of one plane when `flat`, so that hull facets have coplanar points)
    rng = np.random.default_rng(seed)
    points = np.round(rng.uniform(-1, 1, (count, 3)), 2)
    if flat:
        points[: count // 2, 2] = -1.0
    path = tmp_path_factory.mktemp("hull") / "h.xml"
    vertex = " ".join(f"{v:g}" for v in points.ravel())
    path.write_text(f'<mujoco><compiler inertiafromgeom="true"/><asset><mesh name="m" vertex="{vertex}"/></asset>'
                    '<worldbody><body name="b"><geom type="mesh" mesh="m"/></body></worldbody></mujoco>')
    try:
        mujoco.MjModel.from_xml_path(str(path))
    except ValueError:              # MuJoCo refuses it (coplanar points): so must the reader
        with pytest.raises(RobotDescriptionError):
            link_inertials(read_robot(path), density=1000)
        return
    results = link_inertials(read_robot(path), density=1000)
    assert results[0].method == "exact"
    # independent truth for the volume: Qhull's own (scipy), on the float64 points
    from scipy.spatial import ConvexHull
    volume = ConvexHull(points).volume
    assert results[0].properties.volume == pytest.approx(volume, rel=1e-10)
    # MuJoCo rounds the points to float32 (a relative 6e-8): on a thin hull that moves the volume by up to
    # ~ extent³/volume times as much, so the comparison allows what that rounding can do, no more
    extent = float(np.max(np.abs(points)))
    assert_like_mujoco(path, results, rtol=1e-6 * max(1.0, extent ** 3 / volume))


def test_attaches_that_multiply_are_bounded(tmp_path):
    # each level attaches the next ten times: 10^5 bodies from five small files, refused at the body limit
    for level in range(5):
        attaches = "".join(f'<attach model="n" body="b" prefix="p{k}_"/>' for k in range(10))
        nxt = f'<asset><model name="n" file="l{level + 1}.xml"/></asset>' if level < 4 else ""
        (tmp_path / f"l{level}.xml").write_text(f'<mujoco>{nxt}<worldbody><body name="b"><geom size="0.1"/>'
                                                f'{attaches if level < 4 else ""}</body></worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="more than the 10,000 bodies allowed"):
        read_robot(tmp_path / "l0.xml")


def test_a_scene_of_world_geoms_only_says_so(tmp_path):
    path = tmp_path / "scene.xml"
    path.write_text('<mujoco><asset><hfield name="t" nrow="2" ncol="2" size="1 1 0.1 0.1"/></asset><worldbody>'
                    '<geom type="hfield" hfield="t"/><geom type="box" size="1 1 0.1"/></worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="no bodies: every geom is in <worldbody>"):
        read_robot(path)


def test_a_builtin_mesh_without_mujoco_is_one_sentence(tmp_path, monkeypatch):
    import inertia_tool.robot.mjspec as mjspec
    monkeypatch.setattr(mjspec, "mujoco_available", lambda: False)
    path = tmp_path / "b.xml"
    path.write_text('<mujoco><asset><mesh name="m" builtin="sphere" params="1"/></asset><worldbody><body name="b">'
                    '<geom type="mesh" mesh="m"/></body></worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="generated by MuJoCo; expected the mujoco package"):
        read_robot(path)


def test_an_attach_may_name_a_replicate_copy(tmp_path):
    # MuJoCo attaches copy 1 of a replicated leg by its replicated name, with its subtree named by the copy's
    # suffix ('c_leg-1', 'c_foot-1'); the reader refused it ("the model has no body 'leg-1'")
    (tmp_path / "child.xml").write_text("""<mujoco model="child"><worldbody>
  <replicate count="3" offset="0.5 0 0" sep="-">
    <body name="leg"><geom type="box" size="0.1 0.05 0.02" density="1000"/>
      <body name="foot" pos="0 0 -0.1"><geom type="capsule" size="0.03 0.02" density="800"/></body>
    </body>
  </replicate>
</worldbody></mujoco>""")
    path = tmp_path / "scene.xml"
    path.write_text("""<mujoco model="scene"><compiler inertiafromgeom="true"/>
  <asset><model name="child" file="child.xml"/></asset>
  <worldbody><body name="base"><geom type="box" size="0.2 0.2 0.05"/>
    <attach model="child" body="leg-1" prefix="c_"/>
  </body></worldbody>
</mujoco>""")
    robot = read_robot(path)
    assert [link.name for link in robot.links] == ["base", "c_leg-1", "c_foot-1"]
    assert_like_mujoco(path, link_inertials(robot, density="model"), rtol=1e-9)
    assert compare_with_mujoco(robot) == ()
