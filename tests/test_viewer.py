"""armdyn.viewer: the 3-D page (three.js) of an arm, still or moving.

Checked: the page is self-contained (no URL it could fetch; in Chromium it renders with
every host lookup failing); a browser draws the arm (pixels in the middle of the view)
and the page's script reports what it loaded; the link poses sent equal Pinocchio's
forward kinematics of the same URDF; mesh files (STL, OBJ, COLLADA) read as written by
hand here; hostile names stay text; paths out of the model's folder are refused.
"""

from __future__ import annotations

import html
import json
import re
import struct
import warnings
from pathlib import Path

import numpy as np
import pytest
from browser import _run, require_chromium
from optional import example_robot_data_dir, needs_pinocchio, pin

from armdyn.cli import main
from armdyn.errors import ModelError
from armdyn.io import load
from armdyn.viewer import MeshWarning, View, animate, script_json, view
from armdyn.viewer import meshes as meshes_mod
from armdyn.viewer.geometry import quaternions
from armdyn.viewer.meshes import read_mesh

WEBGL = ("--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--virtual-time-budget=6000")


def rp_arm():
    return load("rp-arm").bind({"m1": 2.0, "m2": 1.0, "l1": 0.5, "g": 9.81})


def ur5_urdf() -> Path:
    return example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"


def scene_of(page: str) -> dict:
    m = re.search(r'<script type="application/json" id="armdyn-scene">(.*?)</script>', page, re.S)
    assert m is not None
    return json.loads(m.group(1))


def browse(page_html: str, tmp_path: Path, name: str, shot: bool = True, size=(900, 700)):
    """(body attributes after the script ran, screenshot array or None) of the page in headless Chromium."""
    chromium = require_chromium()
    page = tmp_path / f"{name}.html"
    page.write_text(page_html, encoding="utf-8")
    dom = _run(chromium, [*WEBGL, "--dump-dom", page.as_uri()], 120).stdout
    body = re.search(r"<body([^>]*)>", dom)
    assert body is not None, dom[-2000:]
    attrs = dict(re.findall(r'data-([a-z]+)="([^"]*)"', body.group(1)))
    attrs["title"] = html.unescape(re.search(r"<title>(.*?)</title>", dom, re.S).group(1))
    if not shot:
        return attrs, None
    from PIL import Image

    png = tmp_path / f"{name}.png"
    _run(chromium, [*WEBGL, f"--window-size={size[0]},{size[1]}", f"--screenshot={png}", page.as_uri()], 120)
    assert png.exists(), "no screenshot"
    return attrs, np.asarray(Image.open(png).convert("RGB")).astype(int)


def drawn_fraction(img: np.ndarray) -> float:
    """Share of the view's middle (the arm is centred there) drawn darker than the white
    background and the light floor grid (channels above 190): the arm's shaded surfaces."""
    h, w, _ = img.shape
    middle = img[int(0.2 * h) : int(0.85 * h), int(0.15 * w) : int(0.85 * w)]
    return float(np.mean(middle.max(axis=2) < 180))


# ------------------------------------------------------------------ the page


def test_page_is_self_contained():
    page = view(rp_arm()).html()
    urls = set(re.findall(r"https?://[^\s\"'<>)]*", page))
    assert urls <= {"http://www.w3.org/1999/xhtml"}, urls  # an XML namespace name, never fetched
    assert not re.search(r"<(link|img|iframe|object|embed)\b", page, re.I)
    assert not re.search(r"<script[^>]*\bsrc=", page, re.I)
    assert "import(" not in page and "importScripts" not in page
    csp = re.search(r'http-equiv="Content-Security-Policy" content="([^"]*)"', page).group(1)
    assert "default-src 'none'" in csp and "connect-src" not in csp  # nothing may be fetched
    assert page.count("<script") == 2 and page.count("</script>") == 2


def test_jupyter_frame_holds_the_page():
    v = view(rp_arm())
    frame = v._repr_html_()
    assert frame.startswith("<iframe srcdoc=") and 'sandbox="allow-scripts"' in frame
    srcdoc = re.search(r'srcdoc="([^"]*)"', frame).group(1)
    assert "<" not in srcdoc and html.unescape(srcdoc) == v.html()


def test_save_writes_the_page(tmp_path):
    out = tmp_path / "arm.html"
    v = view(rp_arm(), [0.2, 0.1])
    v.save(out)
    assert out.read_text(encoding="utf-8") == v.html()


def test_hostile_names_stay_text(tmp_path):
    evil = "</script><script>document.title='owned'</script><!--\"'&"
    urdf = tmp_path / "evil.urdf"
    urdf.write_text(
        f"""<robot name="{html.escape(evil, quote=True)}">
  <link name="base"/>
  <link name="{html.escape(evil, quote=True)}x"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j&lt;/script&gt;" type="revolute"><parent link="base"/><child link="{html.escape(evil, quote=True)}x"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>""",
        encoding="utf-8",
    )
    robot = load(urdf)
    page = view(robot).html()
    assert page.count("</script>") == 2 and "<!--" not in page
    assert scene_of(page)["links"] == ["base", evil + "x"]
    assert scene_of(page)["name"] == evil
    attrs, _ = browse(page, tmp_path, "evil", shot=False)
    assert attrs["status"] == "ready"
    assert attrs["title"].startswith(evil) and "owned" != attrs["title"]


def test_script_json_is_inert():
    text = script_json({"a": "</script><!--\u2028\u2029&"})
    assert not set(text) & set("<>&\u2028\u2029")
    assert json.loads(text) == {"a": "</script><!--\u2028\u2029&"}


# ------------------------------------------------------------ in the browser


def test_ur5_meshes_render(tmp_path):
    robot = load(ur5_urdf())
    v = view(robot, [0.3, -1.0, 1.2, -0.5, 0.8, 0.2])
    scene = v.scene
    assert len(scene["meshes"]) == 7 and all(item["shape"] == "mesh" for item in scene["visuals"])
    attrs, img = browse(v.html(), tmp_path, "ur5")
    assert attrs["status"] == "ready", attrs
    assert int(attrs["links"]) == len(robot.links) and int(attrs["meshes"]) == 7 and attrs["frames"] == "1"
    assert drawn_fraction(img) > 0.03
    assert img[-5:, :].max(axis=2).min() >= 180  # the bottom edge is background or grid: the arm is in view


def test_the_floor_is_under_a_legged_robots_feet(tmp_path):
    """Solo-12 with its base fixed hangs its legs below the base: the floor grid goes under
    its feet, not through its legs. At q = 0 no joint turns anything, so each foot frame
    sits at the sum of its chain's joint origins in the URDF, z = -0.16 - 0.16 m; the
    foot's ball reaches a little below that. An arm's floor stays at its base plane (the
    UR5's base mesh reaches 1.6 cm below it)."""
    solo = load(example_robot_data_dir() / "solo_description" / "robots" / "solo12.urdf")
    attrs, img = browse(view(solo).html(), tmp_path, "solo12")
    assert attrs["status"] == "ready" and drawn_fraction(img) > 0.03
    assert -0.32 - 0.03 < float(attrs["floor"]) < -0.32
    attrs, _ = browse(view(load(ur5_urdf()), [0.3, -1.0, 1.2, -0.5, 0.8, 0.2]).html(), tmp_path, "ur5", shot=False)
    assert -0.03 < float(attrs["floor"]) <= 0


def test_rp_arm_simple_shapes_render(tmp_path):
    v = view(rp_arm(), [0.4, 0.3], frames=True)
    assert v.scene["meshes"] == [] and len(v.scene["segments"]) == 2 and len(v.scene["coms"]) == 2
    attrs, img = browse(v.html(), tmp_path, "rp")
    assert attrs["status"] == "ready" and attrs["links"] == "3"
    assert drawn_fraction(img) > 0.005
    # the joint cylinders' colours are there: orange (revolute) and purple (prismatic)
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    assert np.any((r > 180) & (g > 90) & (g < 170) & (b < 80)), "no orange joint"
    assert np.any((b > 150) & (r > 90) & (g < 110)), "no purple joint"
    # the control: the same page with nothing of the arm drawn has no such pixels
    empty = View({**v.scene, "segments": [], "joints": [], "coms": [], "axes": False})
    attrs, img = browse(empty.html(), tmp_path, "empty")
    assert attrs["status"] == "ready" and drawn_fraction(img) == 0


def test_animation_reports_its_frames(tmp_path):
    t = np.linspace(0, 3, 1201)
    Q = np.c_[np.sin(t), 0.2 + 0.1 * np.cos(t)]
    v = animate(rp_arm(), t, Q, max_frames=200)
    scene = v.scene
    assert len(scene["times"]) == 200 and scene["times"][0] == 0 and scene["times"][-1] == 3
    assert len(scene["poses"]) == 200 * 3 * 7
    attrs, _ = browse(v.html(), tmp_path, "anim", shot=False)
    assert attrs == {**attrs, "status": "ready", "frames": "200", "links": "3"}
    page = v.html()
    assert 'id="armdyn-play"' in page and 'max="199"' in page and 'id="armdyn-loop"' in page


def test_animation_plays(tmp_path):
    """Opened as ``page.html#play`` the page starts playing: after some (virtual) time it
    shows a later frame; opened plainly it stays at the first."""
    chromium = require_chromium()
    t = np.linspace(0, 2, 201)
    page = tmp_path / "play.html"
    animate(rp_arm(), t, np.c_[t, 0.1 * t]).save(page)
    shown = []
    for suffix in ("#play", ""):
        dom = _run(
            chromium, [*WEBGL[:2], "--virtual-time-budget=3000", "--dump-dom", page.as_uri() + suffix], 120
        ).stdout
        shown.append(int(re.search(r'<body[^>]*data-frame="(\d+)"', dom).group(1)))
    assert shown[0] > 0 and shown[1] == 0, shown


# --------------------------------------------------------------- kinematics


def quat_matrix(x, y, z, w):
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


@needs_pinocchio
def test_poses_equal_pinocchio():
    path = ur5_urdf()
    robot = load(path)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    rng = np.random.default_rng(7)
    Q = rng.uniform(-np.pi, np.pi, size=(5, robot.dof))
    scene = animate(robot, np.arange(5.0), Q).scene
    L = len(scene["links"])
    poses = np.array(scene["poses"]).reshape(5, L, 7)
    for k, q in enumerate(Q):
        q_pin = np.zeros(model.nq)
        for name, value in zip(robot.coordinate_names, q):
            q_pin[model.joints[model.getJointId(name)].idx_q] = value
        pin.framesForwardKinematics(model, data, q_pin)
        for i, name in enumerate(scene["links"]):
            if not model.existFrame(name, pin.FrameType.BODY):
                continue
            oMf = data.oMf[model.getFrameId(name, pin.FrameType.BODY)]
            assert np.allclose(poses[k, i, :3], oMf.translation, atol=1e-6), (name, k)
            assert np.allclose(quat_matrix(*poses[k, i, 3:]), oMf.rotation, atol=1e-6), (name, k)
    assert sum(model.existFrame(n, pin.FrameType.BODY) for n in scene["links"]) >= 7


@needs_pinocchio
def test_floating_poses_equal_pinocchio():
    """A floating robot's configurations (base position, quaternion, joints) place its
    links where Pinocchio's free flyer does; Solo-12's arrays are Pinocchio's as they are."""
    path = example_robot_data_dir() / "solo_description" / "robots" / "solo12.urdf"
    robot = load(path, root_joint="free-flyer")
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    np.random.seed(11)  # pin.randomConfiguration draws from NumPy's global generator
    Q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)) for _ in range(4)])
    scene = animate(robot, np.arange(4.0), Q).scene
    L = len(scene["links"])
    poses = np.array(scene["poses"]).reshape(4, L, 7)
    for k, q in enumerate(Q):
        pin.framesForwardKinematics(model, data, q)
        for i, name in enumerate(scene["links"]):
            oMf = data.oMf[model.getFrameId(name, pin.FrameType.BODY)]
            assert np.allclose(poses[k, i, :3], oMf.translation, atol=1e-6), (name, k)
            assert np.allclose(quat_matrix(*poses[k, i, 3:]), oMf.rotation, atol=1e-6), (name, k)
    bad = Q[:1].copy()
    bad[0, 3:7] *= 1.1
    with pytest.raises(ValueError, match="unit length"):
        view(robot, bad[0])


def test_quaternions_match_scipy():
    """Random rotations and the half turns about each axis (where the trace is -1: the
    other branches of Shepperd's method) against SciPy's conversion."""
    Rotation = pytest.importorskip("scipy.spatial.transform").Rotation
    M = np.concatenate([Rotation.random(500, random_state=3).as_matrix(), [np.diag(d) for d in np.eye(3) * 2 - 1]])
    q = quaternions(M)
    ref = Rotation.from_matrix(M).as_quat()  # [x, y, z, w], either sign
    assert np.all(q[:, 3] >= 0) and np.allclose(np.abs(np.einsum("ij,ij->i", q, ref)), 1, atol=1e-12)


def test_too_many_frames_are_sampled():
    t = np.linspace(0, 1, 50)
    Q = np.c_[t, t]
    scene = animate(rp_arm(), t, Q, max_frames=7).scene
    assert scene["times"] == [round(float(x), 9) for x in t[[0, 8, 16, 24, 33, 41, 49]]]
    with pytest.raises(ValueError, match="NaN"):
        animate(rp_arm(), t, np.c_[t, t * np.nan])
    with pytest.raises(ValueError, match="decrease"):
        animate(rp_arm(), t[::-1], Q)


# --------------------------------------------------------------------- meshes


TETRA = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
FACES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
# surface of the unit corner tetrahedron: three right triangles of area 1/2 and one equilateral of side sqrt(2)
TETRA_AREA = 1.5 + np.sqrt(3) / 4 * 2


def area(v, t):
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()


def test_stl_binary_and_ascii(tmp_path):
    binary = tmp_path / "t.stl"
    records = b"".join(struct.pack("<12fH", *([0.0] * 3), *TETRA[list(f)].reshape(-1), 0) for f in FACES)
    binary.write_bytes(b"solid but binary".ljust(80, b" ") + struct.pack("<I", 4) + records)
    ascii_ = tmp_path / "a.stl"
    facets = "".join(
        "facet normal 0 0 0\n outer loop\n"
        + "".join(f"  vertex {x} {y} {z}\n" for x, y, z in TETRA[list(f)])
        + " endloop\nendfacet\n"
        for f in FACES
    )
    ascii_.write_text(f"solid t\n{facets}endsolid t\n")
    for path in (binary, ascii_):
        v, t = read_mesh(path)
        assert len(v) == 4 and len(t) == 4
        assert area(v.astype(float), t) == pytest.approx(TETRA_AREA)


def test_obj_polygons_and_negative_indices(tmp_path):
    obj = tmp_path / "sq.obj"
    obj.write_text("# unit square and a triangle\nv 0 0 0\nv 2 0 0\nv 2 3 0\nv 0 3 0\nf 1/1/1 2/2/1 3 4\nf -4 -3 -1\n")
    v, t = read_mesh(obj)
    assert len(t) == 3 and area(v.astype(float), t) == pytest.approx(6 + 3)


def test_dae_units_up_axis_and_nodes(tmp_path):
    dae = tmp_path / "m.dae"
    dae.write_text(
        """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><unit name="centimetre" meter="0.01"/><up_axis>Y_UP</up_axis></asset>
 <library_geometries><geometry id="g"><mesh>
  <source id="p"><float_array id="pa" count="9">0 0 0 10 0 0 0 10 0</float_array>
   <technique_common><accessor source="#pa" count="3" stride="3"/></technique_common></source>
  <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
  <polylist count="1"><input semantic="VERTEX" source="#v" offset="0"/><vcount>3</vcount><p>0 1 2</p></polylist>
 </mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node><translate>0 0 5</translate>
  <instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
</COLLADA>""",
        encoding="utf-8",
    )
    v, t = read_mesh(dae)
    # translate z by 5 cm, then Y up -> Z up: (x, y, z) -> (x, -z, y); centimetres -> metres
    expected = np.array([[0, -5, 0], [10, -5, 0], [0, -5, 10]]) * 0.01
    assert np.allclose(v[t[0]], expected, atol=1e-7)


def test_ur5_collada_matches_its_collision_stl():
    """The UR5's visual COLLADA meshes (with their node transforms) and its collision
    STLs are independent files of the same parts: their bounding boxes agree to 3 mm."""
    folder = example_robot_data_dir() / "ur_description" / "meshes" / "ur5"
    for part in ("base", "shoulder", "upperarm", "forearm", "wrist1", "wrist2", "wrist3"):
        v, _ = read_mesh(folder / "visual" / f"{part}.dae")
        c, _ = read_mesh(folder / "collision" / f"{part}.stl")
        assert np.allclose(v.min(axis=0), c.min(axis=0), atol=3e-3), part
        assert np.allclose(v.max(axis=0), c.max(axis=0), atol=3e-3), part


def test_mesh_size_cap(tmp_path, monkeypatch):
    big = tmp_path / "big.stl"
    big.write_bytes(b"\0" * 80 + struct.pack("<I", 100) + b"\0" * 5000)
    monkeypatch.setattr(meshes_mod, "MESH_MAX_BYTES", 1000)
    with pytest.raises(ModelError, match="larger than 1000 bytes"):
        read_mesh(big)


def arm_with_mesh(tmp_path: Path, filename: str) -> Path:
    folder = tmp_path / "model"
    folder.mkdir(exist_ok=True)
    urdf = folder / "arm.urdf"
    urdf.write_text(
        f"""<robot name="m">
  <link name="base"/>
  <link name="arm"><visual><geometry><mesh filename="{filename}"/></geometry></visual>
    <inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.2"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>""",
        encoding="utf-8",
    )
    return urdf


@pytest.mark.parametrize(
    "filename, why",
    [
        ("meshes/missing.stl", "not found"),
        ("../secret.stl", "outside the model's folder"),
        ("/etc/passwd.stl", "absolute path"),
        ("package://nopkg/x.stl", "package 'nopkg' not found"),
        ("http://example.invalid/x.stl", "only package://"),
    ],
)
def test_unusable_mesh_becomes_a_capsule_with_one_warning(tmp_path, filename, why):
    (tmp_path / "secret.stl").write_text("solid s\nendsolid s\n")
    robot = load(arm_with_mesh(tmp_path, filename))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = view(robot).scene
    relevant = [w for w in caught if issubclass(w.category, MeshWarning)]
    assert len(relevant) == 1 and filename in str(relevant[0].message) and why in str(relevant[0].message)
    assert scene["visuals"] == [] and scene["segments"] == [[0, 1]]


def test_model_file_gone_draws_simple_shapes(tmp_path):
    urdf = arm_with_mesh(tmp_path, "m.stl")
    robot = load(urdf)
    urdf.unlink()
    with pytest.warns(MeshWarning, match="visual geometry not read: .*no such file"):
        scene = view(robot).scene
    assert scene["visuals"] == [] and scene["segments"] == [[0, 1]]


def test_package_mesh_resolves_inside_its_package(tmp_path):
    package = tmp_path / "mypkg"
    (package / "meshes").mkdir(parents=True)
    (package / "meshes" / "t.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    urdf = arm_with_mesh(tmp_path, "package://mypkg/meshes/t.obj")
    scene = view(load(urdf), package_dirs=[tmp_path]).scene
    assert len(scene["meshes"]) == 1 and scene["visuals"][0]["link"] == 1 and scene["segments"] == []
    with pytest.warns(MeshWarning, match="leaves its package"):
        view(load(arm_with_mesh(tmp_path, "package://mypkg/../model/arm.urdf.stl")), package_dirs=[tmp_path])


# ------------------------------------------------------------------------ CLI


def test_cli_show_and_simulate_3d(tmp_path, capsys):
    out = tmp_path / "arm.html"
    assert main(["show", "planar-3r", "--3d", "--q", "0.1,0.2,0.3", "-o", str(out)]) == 0
    scene = scene_of(out.read_text(encoding="utf-8"))
    assert scene["times"] == [0.0] and "wrote" in capsys.readouterr().out
    run = tmp_path / "run.html"
    code = main(["simulate", "planar-3r", "--duration", "1", "--dt", "0.001", "--q0", "0.5", "--3d", str(run)])
    assert code == 0
    scene = scene_of(run.read_text(encoding="utf-8"))
    assert 2 <= len(scene["times"]) <= 500 and scene["times"][-1] == pytest.approx(1.0)
    assert main(["show", "planar-3r", "--3d", "-o", str(tmp_path / "a.png")]) == 2
    assert "HTML page" in capsys.readouterr().err


def test_show_3d_of_a_floating_robot_takes_its_joints_or_its_whole_configuration(tmp_path, capsys):
    """``armdyn show --root-joint free-flyer``: the joints alone put the base at the origin,
    unturned; a whole configuration places it (its quaternion, typed to 7 digits, normalised
    and said); anything else is one clear error."""
    path = str(example_robot_data_dir() / "solo_description" / "robots" / "solo12.urdf")
    legs = [0.1, 0.8, -1.6, -0.1, 0.8, -1.6, 0.1, -0.8, 1.6, -0.1, -0.8, 1.6]
    s, c = np.sin(np.pi / 8), np.cos(np.pi / 8)  # a turn of 45 degrees about z
    whole = [0.0, 0.0, 0.3, 0.0, 0.0, round(s, 7), round(c, 7), *legs]
    robot = load(path, root_joint="free-flyer")
    for q, name in ((legs, "legs"), (whole, "whole")):
        out = tmp_path / f"{name}.html"
        args = ["show", path, "--root-joint", "free-flyer", "--3d", "--q", ",".join(map(str, q)), "-o", str(out)]
        assert main(args) == 0
        full = [0, 0, 0, 0, 0, 0, 1, *legs] if name == "legs" else [*whole[:3], 0, 0, s, c, *legs]
        written = re.search(r'"poses":(\[[^\]]*\])', out.read_text()).group(1)
        assert np.allclose(json.loads(written), view(robot, np.array(full)).scene["poses"], atol=1e-7)
    assert "quaternion normalised" in capsys.readouterr().err
    for q, said in (([1, 2, 3], "3 values for a floating robot with 12 joints"), ([*whole[:6], 1.01, *legs], "not 1")):
        args = [
            "show",
            path,
            "--root-joint",
            "free-flyer",
            "--3d",
            "--q",
            ",".join(map(str, q)),
            "-o",
            str(tmp_path / "x.html"),
        ]
        assert main(args) == 2
        assert said in capsys.readouterr().err
