"""armdyn.dask: the numeric API over Dask arrays on a distributed.LocalCluster with two
worker processes (the compiled model pickled to them); results equal the in-process
functions bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

import armdyn
from armdyn import numeric as num
from armdyn.simulate import ComputedTorque, simulate


@pytest.fixture(scope="module")
def client():
    pytest.importorskip("dask.array")
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def ur5():
    return armdyn.load("ur5")


def test_functions_on_cluster_equal_in_process(client, ur5):
    import dask.array as da

    from armdyn import dask as ad

    rng = np.random.default_rng(11)
    q, qd, qdd = rng.uniform(-2, 2, (3, 1003, ur5.dof))
    dq = da.from_array(q, chunks=(250, 6))
    tau = ad.rnea(ur5, dq, qd, qdd)
    assert isinstance(tau, da.Array) and tau.numblocks[0] == 5
    tau_np = tau.compute()
    assert np.array_equal(tau_np, num.rnea(ur5, q, qd, qdd))
    assert np.array_equal(ad.aba(ur5, dq, qd, tau_np).compute(), num.aba(ur5, q, qd, tau_np))
    M = ad.crba(ur5, q, chunks=300)
    assert M.shape == (1003, 6, 6)
    assert np.array_equal(M.compute(), num.crba(ur5, q))
    # the work really ran in the two worker processes
    workers = client.run(lambda: __import__("os").getpid())
    assert len(set(workers.values())) == 2


def test_simulate_on_cluster_equal_in_process(client, ur5):
    from armdyn import dask as ad

    rng = np.random.default_rng(12)
    q0, qd0 = rng.uniform(-1, 1, (2, 37, ur5.dof))
    kw = dict(dt=1e-3, steps=200, stride=20, controller=ComputedTorque(25.0, 10.0, np.full(6, 0.2)))
    lazy = ad.simulate(ur5, q0, qd0, chunks=10, **kw)
    ref = simulate(ur5, q0, qd0, **kw)
    for name in (
        "q",
        "qd",
        "qdd",
        "tau",
        "kinetic",
        "potential",
        "q_final",
        "qd_final",
        "limit_step",
        "limit_joint",
        "nonfinite_step",
    ):
        got = getattr(lazy, name).compute()
        want = getattr(ref, name)
        assert got.shape == want.shape and got.dtype == want.dtype, name
        assert np.array_equal(got, want), name
    np.testing.assert_array_equal(lazy.t, ref.t)
    assert np.all(np.isfinite(ref.q))


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_joints_of_several_coordinates_on_cluster_equal_in_process(client, floating):
    """q nq wide, the others nv (a ball, a hinge, a planar joint, a ball or a free joint;
    with a floating base 7 and 6 more): rnea, aba, crba and a PD run as in process."""
    import dask.array as da
    from test_simulate_joints import chain

    from armdyn import dask as ad
    from armdyn.simulate import PD

    robot = chain(floating)
    rng = np.random.default_rng(13)
    q = np.stack([num.random_configuration(robot, rng) for _ in range(41)])
    qd, qdd = rng.uniform(-1, 1, (2, 41, robot.nv))
    dq = da.from_array(q, chunks=(10, robot.nq))
    tau = ad.rnea(robot, dq, qd, qdd)
    assert tau.shape == (41, robot.nv) and tau.chunks[1] == (robot.nv,)
    tau_np = tau.compute()
    assert np.array_equal(tau_np, num.rnea(robot, q, qd, qdd))
    assert np.array_equal(ad.aba(robot, dq, qd, tau_np).compute(), num.aba(robot, q, qd, tau_np))
    assert np.array_equal(ad.crba(robot, q, chunks=15).compute(), num.crba(robot, q))
    target = num.random_configuration(robot, rng)[7 if floating else 0 :]
    kw = dict(dt=2e-3, steps=40, stride=10, controller=PD(4.0, 1.0, target))
    lazy, ref = ad.simulate(robot, q, qd, chunks=9, **kw), simulate(robot, q, qd, **kw)
    for name in ("q", "qd", "qdd", "tau", "work", "kinetic", "potential", "q_final", "qd_final", "nonfinite_step"):
        got, want = getattr(lazy, name).compute(), getattr(ref, name)
        assert got.shape == want.shape and np.array_equal(got, want), name
    assert lazy.coordinate_names == ref.coordinate_names
    assert ad.simulate(robot, q[:3], dt=2e-3, steps=2).qd.shape == (3, 3, robot.nv)  # qd0 zero, nv wide
    with pytest.raises(ValueError, match=rf"expected \(N, {robot.nq}\)"):
        ad.rnea(robot, qd, qd, qd)


def test_bad_input():
    pytest.importorskip("dask.array")
    from armdyn import dask as ad

    ur5 = armdyn.load("ur5")
    with pytest.raises(ValueError, match="expected \\(N, 6\\)"):
        ad.rnea(ur5, np.zeros((4, 5)), np.zeros((4, 5)), np.zeros((4, 5)))
    with pytest.raises(ValueError, match="does not match"):
        ad.aba(ur5, np.zeros((4, 6)), np.zeros((3, 6)), np.zeros((4, 6)))
    with pytest.raises(ValueError, match="torque must be"):
        ad.simulate(ur5, np.zeros((4, 6)), dt=1e-3, steps=3, torque=lambda t, q, qd: 0)


def test_derivatives_on_cluster_equal_in_process(client, ur5):
    """rnea/aba/gravity derivatives and M^-1 chunked along states (uneven last block), run
    in the two worker processes: equal to the in-process batch calls bit for bit."""
    import dask
    import dask.array as da
    from distributed import get_task_stream

    from armdyn import dask as ad

    rng = np.random.default_rng(13)
    n = 203
    q, qd, qdd = rng.uniform(-2, 2, (3, n, ur5.dof))
    tau = num.rnea(ur5, q, qd, qdd)
    dq = da.from_array(q, chunks=(50, 6))  # blocks of 50, 50, 50, 50, 3 rows

    lazy = ad.rnea_derivatives(ur5, dq, qd, qdd)
    assert all(isinstance(x, da.Array) and x.shape == (n, 6, 6) and x.numblocks == (5, 1, 1) for x in lazy)
    with get_task_stream(client) as stream:
        got = dask.compute(*lazy)
    # the blocks really ran on the cluster's workers (two processes)
    ran_on = {task["worker"] for task in stream.data if "rnea_derivatives" in task["key"][0]}
    assert ran_on and ran_on <= set(client.scheduler_info()["workers"]), stream.data
    want = num.rnea_derivatives(ur5, q, qd, qdd)
    for g, w, name in zip(got, want, ("dtau_dq", "dtau_dqd", "M")):
        assert g.shape == w.shape == (n, 6, 6) and np.all(np.isfinite(g)), name
        assert np.array_equal(g, w), name
    # the third output is M: a second opinion from crba (a different algorithm)
    np.testing.assert_allclose(got[2], num.crba(ur5, q), rtol=1e-12, atol=1e-12)

    got = dask.compute(*ad.aba_derivatives(ur5, q, qd, tau, chunks=64))
    want = num.aba_derivatives(ur5, q, qd, tau)
    for g, w, name in zip(got, want, ("dqdd_dq", "dqdd_dqd", "Minv")):
        assert g.shape == (n, 6, 6) and np.all(np.isfinite(g)), name
        assert np.array_equal(g, w), name

    Minv = ad.minverse(ur5, dq)
    assert Minv.shape == (n, 6, 6) and Minv.chunks[0] == dq.chunks[0]
    Minv = Minv.compute()
    assert np.array_equal(Minv, num.minverse(ur5, q))
    np.testing.assert_allclose(Minv @ num.crba(ur5, q), np.broadcast_to(np.eye(6), (n, 6, 6)), atol=1e-9)

    dg = ad.gravity_derivatives(ur5, dq).compute()
    assert dg.shape == (n, 6, 6) and np.all(np.isfinite(dg))
    assert np.array_equal(dg, num.gravity_derivatives(ur5, q))
    assert np.abs(dg).max() > 1.0  # gravity really depends on q here


def test_derivatives_bad_input():
    pytest.importorskip("dask.array")
    from armdyn import dask as ad

    ur5 = armdyn.load("ur5")
    with pytest.raises(ValueError, match="expected \\(N, 6\\)"):
        ad.minverse(ur5, np.zeros((4, 5)))
    with pytest.raises(ValueError, match="does not match"):
        ad.rnea_derivatives(ur5, np.zeros((4, 6)), np.zeros((3, 6)), np.zeros((4, 6)))
