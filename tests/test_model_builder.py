"""armdyn.numeric.ModelBuilder: a model built joint by joint (Pinocchio's addJoint /
appendBodyToJoint), each wrong call refused where it is made, naming the joint.

Second opinion: a two-link planar arm's M(q) written here by hand, and Pinocchio's
model built by the same calls."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from optional import needs_pinocchio, pin

import armdyn.numeric as an

EYE = np.eye(3).tolist()


def _two_link(m1=1.5, m2=0.8, l1=0.6, c1=0.3, c2=0.25, i1=0.02, i2=0.01, floating=False):
    b = an.ModelBuilder("two-link", [0.0, -9.81, 0.0], "base", floating=floating)
    b.set_base_body(3.0, [0.0, 0.0, 0.0], np.diag([0.1, 0.1, 0.1]).tolist())
    k = b.add_joint("shoulder", "base", "upper", "revolute", EYE, [0, 0, 0], [0, 0, 1], ["q1"])
    b.append_body(k, m1, [c1, 0.0, 0.0], np.diag([0.0, 0.0, i1]).tolist())
    k = b.add_joint("elbow", "upper", "fore", "revolute", EYE, [l1, 0, 0], [0, 0, 1], ["q2"], [0.05, 0.0, 0.0, 0.0])
    b.append_body(k, m2, [c2, 0.0, 0.0], np.diag([0.0, 0.0, i2]).tolist())
    return b


def test_two_link_arm_mass_matrix_by_hand():
    m1, m2, l1, c1, c2, i1, i2 = 1.5, 0.8, 0.6, 0.3, 0.25, 0.02, 0.01
    model = _two_link().build()
    assert (model.dof, model.link_names, model.coordinate_names) == (2, ["base", "upper", "fore"], ["q1", "q2"])
    for q2 in np.linspace(-3, 3, 7):
        c = np.cos(q2)
        m11 = i1 + i2 + m1 * c1**2 + m2 * (l1**2 + c2**2 + 2 * l1 * c2 * c)
        m12 = i2 + m2 * (c2**2 + l1 * c2 * c)
        m22 = i2 + m2 * c2**2 + 0.05  # the elbow's rotor inertia
        np.testing.assert_allclose(model.crba(np.array([0.4, q2])), [[m11, m12], [m12, m22]], rtol=0, atol=1e-12)


def test_a_model_pickles_as_its_calls():
    for floating in (False, True):
        model = _two_link(floating=floating).build()
        again = pickle.loads(pickle.dumps(model))
        assert type(again) is type(model) and again.floating == floating
        q = np.concatenate([[0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 1.0] if floating else [], [0.3, -0.7]])
        np.testing.assert_array_equal(again.crba(q), model.crba(q))
        builder = pickle.loads(pickle.dumps(_two_link(floating=floating)))
        np.testing.assert_array_equal(builder.build().crba(q), model.crba(q))


@pytest.mark.parametrize(
    "call, message",
    [
        (
            lambda b: b.add_joint("j", "nowhere", "x", "revolute", EYE, [0] * 3, [0, 0, 1], ["j"]),
            "parent link 'nowhere'",
        ),
        (lambda b: b.add_joint("j", "base", "upper", "revolute", EYE, [0] * 3, [0, 0, 1], ["j"]), "'upper' is already"),
        (lambda b: b.add_joint("j", "base", "x", "hinge", EYE, [0] * 3, [0, 0, 1], ["j"]), "unknown kind 'hinge'"),
        (lambda b: b.add_joint("j", "base", "x", "spherical", EYE, [0] * 3, [0, 0, 1], ["j"]), "has 3 coordinates"),
        (lambda b: b.append_body(0, 1.0, [0] * 3, EYE), "joint 'shoulder': its child link already has a body"),
        (lambda b: b.append_body(7, 1.0, [0] * 3, EYE), "no joint 7"),
    ],
)
def test_wrong_calls_refused_naming_the_joint(call, message):
    b = _two_link()
    with pytest.raises(ValueError, match=message):
        call(b)


def test_bad_numbers_refused_at_build_naming_the_joint():
    b = _two_link()
    k = b.add_joint("wrist", "fore", "hand", "revolute", EYE, [0.4, 0, 0], [0, 0, 2], ["q3"])
    b.append_body(k, 1.0, [0] * 3, EYE)
    with pytest.raises(ValueError, match=r"joint 'wrist' \(link 'hand'\): axis .* not a unit vector"):
        b.build()
    b = _two_link()
    b.append_body(
        b.add_joint("wrist", "fore", "hand", "revolute", EYE, [0.4, 0, 0], [0, 0, 1], ["q3"]), -1.0, [0] * 3, EYE
    )
    with pytest.raises(ValueError, match=r"joint 'wrist' \(link 'hand'\): negative mass"):
        b.build()


@needs_pinocchio
def test_the_same_calls_as_pinocchio():
    """A ball joint and a slider built here and in Pinocchio by the same calls."""
    rng = np.random.default_rng(3)
    b = an.ModelBuilder("ball-slider", [0.0, 0.0, -9.81], "base")
    model = pin.Model()
    model.gravity = pin.Motion(np.array([0, 0, -9.81, 0, 0, 0]))
    parent = 0
    for name, kind, pin_kind, coords in (
        ("ball", "spherical", pin.JointModelSpherical(), ["wx", "wy", "wz"]),
        ("slide", "prismatic", pin.JointModelPX(), ["s"]),
    ):
        R, p = pin.SE3.Random().rotation, rng.normal(size=3)
        k = b.add_joint(
            name,
            "base" if parent == 0 else "ball-link",
            f"{name}-link",
            kind,
            R.tolist(),
            p.tolist(),
            [1, 0, 0],
            coords,
        )
        parent = model.addJoint(parent, pin_kind, pin.SE3(R, p), name)
        m, c = rng.uniform(0.5, 2), rng.normal(size=3) * 0.2
        A = rng.normal(size=(3, 3))
        inertia = A @ A.T + np.eye(3) * 0.1
        b.append_body(k, m, c.tolist(), inertia.tolist())
        model.appendBodyToJoint(parent, pin.Inertia(m, c, inertia), pin.SE3.Identity())
    built, data = b.build(), model.createData()
    for _ in range(5):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, a = rng.normal(size=(2, model.nv))
        np.testing.assert_allclose(built.rnea(q, v, a), pin.rnea(model, data, q, v, a), rtol=0, atol=1e-10)
