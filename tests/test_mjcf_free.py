"""MJCF with a free root body: armdyn reads it as a floating base (Pinocchio's layout);
:mod:`armdyn.io.mjcf_state` passes arrays to and from MuJoCo's. Second opinions:

* MuJoCo on the same file (contacts and other constraints off): its mass matrix
  (``mj_fullM`` after ``mj_forward``) is ``T^T M T`` with ``T = diag(R^T, 1, P)`` built
  here (``R`` the base rotation written out, ``P`` the joints by name), and its inverse
  dynamics (``mj_inverse``) is armdyn's ``rnea`` through the state and force
  conversions, to 1e-10 relative: hand-written models (free bodies, hinge and slide
  children, several joints in one body, frames, siblings out of name order) and the
  MJCF MuJoCo's own compiler writes from example-robot-data's floating URDFs;
* Pinocchio (``buildModelFromUrdf(path, JointModelFreeFlyer())``) on the URDF: MuJoCo's
  model compiled from the same URDF in memory (full precision) agrees with it through
  the conversions; armdyn's model read from the written MJCF equals armdyn's (and
  Pinocchio's) from the URDF to the 6 significant digits MuJoCo writes numbers with;
* MuJoCo's RK4 rollout of a floating robot (no contacts): armdyn's RK4 run ends at the
  same state, to a difference below 1e-9 that shrinks 16-fold when the step halves;
* refusals: a free joint below the root, a free joint's damping, ... each one
  ModelError naming the file, line and element.
"""

from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from optional import example_robot_data_dir, needs_pinocchio, pin

import armdyn
import armdyn.numeric as numeric
from armdyn.errors import ModelError
from armdyn.io.mjcf import MjcfIgnoredWarning, load_mjcf
from armdyn.io.mjcf_state import (
    from_mujoco_force,
    from_mujoco_state,
    to_mujoco_force,
    to_mujoco_state,
    urdf_for_mujoco,
)
from armdyn.simulate import simulate

mujoco = pytest.importorskip("mujoco")

TOL = 1e-10

#: a free body turned and placed (MuJoCo's qpos0), legs out of name order, a body with
#: a hinge and a slide, a frame, a static world body beside it
QUADRUPED = """<mujoco model="bug">
  <compiler angle="radian"/>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <body name="post" pos="2 0 0"><geom type="box" size="0.1 0.1 0.5"/></body>
    <body name="torso" pos="0.1 -0.2 0.8" quat="0.9 0.1 -0.3 0.2">
      FREE
      <inertial pos="0.02 -0.01 0.03" quat="0.8 0.2 0.1 0.3" mass="4" diaginertia="0.1 0.2 0.25"/>
      <body name="zeta" pos="0.3 0.1 0" euler="0.1 0.2 0.3">
        <joint name="zeta_hip" axis="0.3 1 0.2" pos="0 0 0.02"/>
        <geom type="capsule" fromto="0 0 0 0.2 0 -0.2" size="0.04"/>
        <body name="zeta_shin" pos="0.2 0 -0.2">
          <joint name="zeta_knee" axis="0 1 0"/>
          <joint name="zeta_slide" type="slide" axis="0 0 1"/>
          <inertial pos="0 0 -0.1" mass="0.3" diaginertia="0.002 0.002 0.0005"/>
        </body>
      </body>
      <frame pos="-0.3 0 0" euler="0 0 0.5">
        <body name="alpha">
          <joint name="alpha_hip" axis="1 0 0" ref="0.2"/>
          <inertial pos="0.05 0.01 -0.1" mass="0.7" fullinertia="0.01 0.012 0.004 0.001 -0.0005 0.0002"/>
          <body name="alpha_shin" pos="0 0 -0.25">
            <joint name="alpha_knee" axis="0 1 0"/>
            <geom type="sphere" size="0.05" pos="0 0 -0.1"/>
          </body>
        </body>
      </frame>
    </body>
  </worldbody>
</mujoco>
"""


def mujoco_model(path):
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT  # contacts, limits
    return model


def full_inertia(model, data) -> np.ndarray:
    M = np.zeros((model.nv, model.nv))
    try:
        mujoco.mj_fullM(model, data, M)  # MuJoCo 4
    except TypeError:
        mujoco.mj_fullM(model, M, data.qM)  # MuJoCo 3
    return M


def rotation_wxyz(quat) -> np.ndarray:
    """R of the unit quaternion (w, x, y, z), written out here."""
    w, x, y, z = np.asarray(quat) / np.linalg.norm(quat)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def mujoco_joints(model) -> list[str]:
    """MuJoCo's joint names in qpos order, the free joint left out."""
    return [model.joint(i).name for i in range(model.njnt) if model.jnt_type[i] != mujoco.mjtJoint.mjJNT_FREE]


def compare(robot, model, joint_names=None, states: int = 4, seed: int = 0) -> float:
    """Largest relative difference of MuJoCo's M and inverse dynamics from armdyn's."""
    data = mujoco.MjData(model)
    names = mujoco_joints(model) if joint_names is None else joint_names
    perm = np.array([list(robot.coordinate_names).index(n) for n in names])
    rng = np.random.default_rng(seed)
    worst = 0.0
    for _ in range(states):
        q = numeric.random_configuration(robot, rng)
        v, a = rng.uniform(-1.5, 1.5, (2, robot.nv))
        qpos, qvel, qacc = to_mujoco_state(robot, q, v, a, joint_names=names)
        data.qpos[:], data.qvel[:] = qpos, qvel
        mujoco.mj_forward(model, data)
        M = full_inertia(model, data)
        T = np.zeros((robot.nv, robot.nv))  # v = T qvel
        T[:3, :3] = rotation_wxyz(qpos[3:7]).T
        T[3:6, 3:6] = np.eye(3)
        T[6 + perm, 6 + np.arange(len(perm))] = 1.0
        Ma = T.T @ numeric.crba(robot, q) @ T
        data.qacc[:] = qacc
        mujoco.mj_inverse(model, data)
        tau = numeric.rnea(robot, q, v, a)
        qfrc = to_mujoco_force(robot, q, tau, joint_names=names)
        scale = max(1.0, np.abs(M).max(), np.abs(data.qfrc_inverse).max())
        diff = max(np.abs(M - Ma).max(), np.abs(qfrc - data.qfrc_inverse).max()) / scale
        assert np.isfinite(diff)
        worst = max(worst, diff)
    return worst


def write(tmp_path, text: str, name: str = "robot.xml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def load_quiet(path, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MjcfIgnoredWarning)
        return armdyn.load(path, **options)


# ------------------------------------------------------------ hand-written models


@pytest.mark.parametrize("free", ["<freejoint name='root'/>", "<joint name='root' type='free'/>"])
def test_free_root_body_against_mujoco(tmp_path, free):
    path = write(tmp_path, QUADRUPED.replace("FREE", free))
    with pytest.warns(MjcfIgnoredWarning, match="bodies fixed to the world beside the floating base"):
        robot = armdyn.load(path)
    model = mujoco_model(path)
    assert robot.floating and robot.base == "torso" and robot.nq == model.nq and robot.nv == model.nv
    assert "world" not in robot.links
    # armdyn orders the legs as Pinocchio (by joint name), MuJoCo as written
    assert robot.meta["mujoco_joints"] == mujoco_joints(model)
    assert list(robot.coordinate_names) != mujoco_joints(model)
    # the body's pose as written is MuJoCo's qpos0 (w x y z)
    position, quat = robot.meta["base_pose"]
    assert np.allclose(position + quat, model.qpos0[:7], atol=1e-15, rtol=0)
    assert compare(robot, model) < TOL


def test_state_conversion_is_invertible_and_dual(tmp_path):
    robot = load_quiet(write(tmp_path, QUADRUPED.replace("FREE", "<freejoint/>")))
    rng = np.random.default_rng(4)
    Q = np.array([numeric.random_configuration(robot, rng) for _ in range(5)])
    V, A, tau = rng.uniform(-1, 1, (3, 5, robot.nv))
    qpos, qvel, qacc = to_mujoco_state(robot, Q, V, A)
    back = from_mujoco_state(robot, qpos, qvel, qacc)
    for x, y in zip(back, (Q, V, A)):
        assert np.abs(x - y).max() < 1e-14
    qfrc = to_mujoco_force(robot, Q, tau)
    assert np.abs(from_mujoco_force(robot, qpos, qfrc) - tau).max() < 1e-14
    # the pairs are dual: the power is the same in either layout
    assert np.abs(np.sum(qfrc * qvel, axis=1) - np.sum(tau * V, axis=1)).max() < 1e-14
    # the quaternion's order, by hand
    assert np.array_equal(qpos[:, 3], Q[:, 6]) and np.array_equal(qpos[:, 4:7], Q[:, 3:6])
    with pytest.raises(ValueError, match="joint_names"):
        to_mujoco_state(robot, Q[0], V[0], joint_names=["a", "b"])


def test_weld_and_root_joint_options(tmp_path):
    path = write(tmp_path, QUADRUPED.replace("FREE", "<freejoint/>"))
    floating = load_quiet(path)
    assert load_quiet(path, root_joint="free-flyer").floating
    welded = load_quiet(path, floating="weld")
    assert not welded.floating and welded.dof == floating.dof and welded.base == "world"
    from armdyn.show import table

    assert "base (floating)" in table(floating) and "base (fixed)" in table(welded)


# ------------------------------------------------------------ example-robot-data

#: example-robot-data's floating robots whose URDF MuJoCo's compiler accepts (anymal's and
#: icub's inertias it refuses), without joint friction (MuJoCo's is a constraint) and
#: without massless links of nonzero inertia (bolt's feet: MuJoCo drops that inertia)
ERD = {
    "solo12": "solo_description/robots/solo12.urdf",
    "a1": "a1_description/urdf/a1.urdf",
    "go2": "go2_description/urdf/go2.urdf",
    "laikago": "laikago_description/urdf/laikago.urdf",
    "g1": "g1_description/urdf/g1_29dof_rev_1_0.urdf",
}


def floating_urdf(urdf, out):
    """``urdf`` for MuJoCo's compiler, floating (:func:`urdf_for_mujoco`), written to ``out``."""
    out.write_text(urdf_for_mujoco(urdf.read_text()))
    return out


@pytest.fixture(params=list(ERD))
def written(request, tmp_path):
    """(name, URDF path, MuJoCo's model compiled from it, the MJCF it writes)."""
    urdf = example_robot_data_dir() / ERD[request.param]
    model = mujoco.MjModel.from_xml_path(str(floating_urdf(urdf, tmp_path / "floating.urdf")))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    mjcf = tmp_path / f"{request.param}.xml"
    mujoco.mj_saveLastXML(str(mjcf), model)
    return request.param, urdf, model, mjcf


def test_mjcf_written_by_mujoco_against_mujoco(written):
    name, _, _, mjcf = written
    robot = load_quiet(mjcf, strict=False)
    model = mujoco_model(mjcf)
    assert robot.floating and robot.nv == model.nv
    assert compare(robot, model) < TOL


def test_urdf_against_mujoco_compiled_from_it(written):
    """armdyn's floating robot from the URDF against MuJoCo's model of the same URDF
    (in memory: full precision), through the conversions with MuJoCo's joint names."""
    _, urdf, model, _ = written
    robot = load_quiet(urdf, strict=False, root_joint="free-flyer")
    assert compare(robot, model, mujoco_joints(model)) < TOL


@needs_pinocchio
def test_mjcf_written_by_mujoco_is_the_urdfs_dynamics(written):
    """armdyn's model of the MJCF MuJoCo writes equals Pinocchio's of the URDF (and
    armdyn's): MuJoCo writes 6 significant digits, so to 1e-5 relative (a 5e-6 rounding
    of masses, positions and principal moments, and of the principal axes)."""
    _, urdf, _, mjcf = written
    from_mjcf = load_quiet(mjcf, strict=False)
    from_urdf = load_quiet(urdf, strict=False, root_joint="free-flyer")
    pmodel = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    pdata = pmodel.createData()
    names = list(pmodel.names)[2:]
    assert sorted(names) == sorted(from_mjcf.coordinate_names)
    perm = [list(from_mjcf.coordinate_names).index(n) for n in names]
    order = np.concatenate([np.arange(6), 6 + np.array(perm)])
    rng = np.random.default_rng(1)
    for _ in range(3):
        q = numeric.random_configuration(from_mjcf, rng)
        v, a = rng.uniform(-1, 1, (2, from_mjcf.nv))
        qp = np.concatenate([q[:7], q[7:][perm]])
        for robot in (from_mjcf, from_urdf):
            M = numeric.crba(robot, q)[np.ix_(order, order)]
            Mp = pin.crba(pmodel, pdata, qp)
            Mp = np.triu(Mp) + np.triu(Mp, 1).T
            tau = numeric.rnea(robot, q, v, a)[order]
            taup = pin.rnea(pmodel, pdata, qp, v[order], a[order])
            tol = 1e-5 if robot is from_mjcf else TOL
            assert np.abs(M - Mp).max() < tol * max(1.0, np.abs(Mp).max())
            assert np.abs(tau - taup).max() < tol * max(1.0, np.abs(taup).max())


# ------------------------------------------------------------ simulation


@pytest.mark.parametrize("source", ["hand", "solo12"])
def test_rollout_against_mujoco_rk4(tmp_path, source):
    """MuJoCo's RK4 (contacts off) and armdyn's from the same state: the same end state.
    The methods differ (MuJoCo integrates the world-frame translation and the rotation
    separately, armdyn the SE(3) exponential with the Munthe-Kaas correction), so they
    agree to their truncation errors, not to rounding: the gap (about 3e-12 over 0.3 s at
    dt = 2 ms) is below 1e-9 and shrinks at least 8-fold when dt halves (16-fold seen:
    both are fourth order, converging to the one solution)."""
    if source == "hand":
        path = write(tmp_path, QUADRUPED.replace("FREE", "<freejoint/>"))
    else:
        urdf = example_robot_data_dir() / ERD["solo12"]
        model = mujoco.MjModel.from_xml_path(str(floating_urdf(urdf, tmp_path / "floating.urdf")))
        path = tmp_path / "solo12.xml"
        mujoco.mj_saveLastXML(str(path), model)
    robot = load_quiet(path, strict=False)
    rng = np.random.default_rng(5)
    q0 = numeric.random_configuration(robot, rng)
    v0 = rng.uniform(-2, 2, robot.nv)
    gaps = []
    for dt in (2e-3, 1e-3):
        model = mujoco_model(path)
        model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
        model.opt.timestep = dt
        data = mujoco.MjData(model)
        data.qpos[:], data.qvel[:] = to_mujoco_state(robot, q0, v0)
        steps = round(0.3 / dt)
        for _ in range(steps):
            mujoco.mj_step(model, data)
        run = simulate(robot, q0, v0, dt=dt, steps=steps)
        q, v = from_mujoco_state(robot, data.qpos.copy(), data.qvel.copy())
        gap = max(np.abs(numeric.difference(robot, run.q_final, q)).max(), np.abs(run.qd_final - v).max())
        gaps.append(gap / max(1.0, np.abs(v).max()))
    assert gaps[0] < 1e-9
    assert gaps[1] < gaps[0] / 8


# ------------------------------------------------------------------ bad input

FREE_BODY = "<body name='base'>{}<inertial pos='0 0 0' mass='1' diaginertia='1 1 1'/>{}</body>"


def mjcf(free: str = "<freejoint name='f'/>", inside: str = "", beside: str = "", head: str = "") -> str:
    return f"<mujoco>{head}\n<worldbody>{FREE_BODY.format(free, inside)}\n{beside}</worldbody></mujoco>"


LEG = "<body name='leg'><joint name='{}' {}/><inertial pos='0 0 0' mass='1' diaginertia='1 1 1'/></body>"


@pytest.mark.parametrize(
    "text, element, words",
    [
        (mjcf(inside=LEG.format("s", "type='ball' springdamper='1 1'")), "<joint name='s'>", "springdamper"),
        (
            mjcf("", inside=LEG.format("f", "type='free'")),
            "<joint name='f'>",
            "free joint in a body that is not a child of the world body",
        ),
        (mjcf("<freejoint name='f' align='true'/>"), "<freejoint name='f'>", "align"),
        (
            mjcf("<joint name='f' type='free'/>", head="<default><joint damping='0.5'/></default>"),
            "<joint name='f'>",
            "damping on the free joint .* <freejoint/> takes no defaults",
        ),
        (mjcf("<freejoint name='f'/><joint name='h'/>"), "<freejoint name='f'>", "must be its body's only joint"),
    ],
)
def test_refusals_name_file_line_and_element(tmp_path, text, element, words):
    path = write(tmp_path, text)
    with pytest.raises(ModelError, match=words) as err:
        load_quiet(path)
    assert str(err.value).startswith(f"{path}:") and element in str(err.value)


def test_freejoint_takes_no_defaults_and_its_pos_is_ignored(tmp_path):
    head = "<default><joint damping='0.5' armature='0.1'/></default>"
    robot = load_quiet(write(tmp_path, mjcf("<freejoint/>", inside=LEG.format("k", ""), head=head)))
    assert robot.floating and float(robot.joints[0].damping) == 0.5
    with pytest.warns(MjcfIgnoredWarning, match="free joint pos"):
        load_mjcf(mjcf("<joint type='free' pos='1 0 0'/>"))


def test_readme_legged_robots_block_runs(tmp_path):
    """README's "Legged robots" / "From MJCF" Python block, run as written in a directory holding
    example-robot-data's solo12.urdf: MuJoCo's M equals armdyn's to 1e-12 and the free
    fall keeps its energy."""
    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    section = readme.split("## Legged robots", 1)[1].split("### From MJCF", 1)[1]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    (tmp_path / "solo12.urdf").write_text((example_robot_data_dir() / ERD["solo12"]).read_text())
    env = {**os.environ, "PYTHONPATH": str(Path(armdyn.__file__).parent.parent)}
    done = subprocess.run(
        [sys.executable, "-W", "ignore", "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    mass_matrix_gap, drift = (float(line) for line in done.stdout.split())
    assert mass_matrix_gap < 1e-12 and drift < 1e-10
