"""Pinocchio's per-call C++ times (rnea, computeRNEADerivatives, computeABADerivatives,
computeMinverse) on UR5, Panda and iiwa14: the reference rates of the batch target in
benchmarks/bench_derivatives.py.

    python benchmarks/pinocchio_cpp/run.py [--number 20000] [--repeat 21]

The pip ``pin`` package ships Pinocchio's headers (and Boost's) under its cmeel prefix;
Eigen's come with ``pip install cmeel-eigen`` (same prefix, include/eigen3). When they are
there, ``bench.cpp`` is compiled once (g++ -O3 -march=native -DNDEBUG, header-only: every
algorithm is instantiated for this machine) into a cache directory under the system's
temporary directory; when they are not, this says so and returns nothing (a benchmark
only: CI need not run it).

The models are those Pinocchio's own URDF parser builds (``pin.buildModelFromUrdf``) from
the URDFs benchmarks/arms.py checks our arms against: example-robot-data's UR5 and Panda
(fingers locked, ``pin.buildReducedModel``) and shared/data's iiwa14. They are handed to the
C++ program as a small text description (bench.cpp says the format), so the C++ side needs
no URDF library; the program's tau at its first state is compared with Pinocchio's Python
``rnea`` on the same model (to 1e-12) before its times are used.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.join(HERE, "bench.cpp")
ALGORITHMS = ("rnea", "rnea_derivatives", "aba_derivatives", "minverse")


def prefix() -> str | None:
    """The cmeel prefix holding Pinocchio's headers, or None without Pinocchio."""
    try:
        import pinocchio
    except ImportError:
        return None
    return os.path.abspath(os.path.join(os.path.dirname(pinocchio.__file__), "..", "..", "..", ".."))


def missing_headers(root: str | None) -> str | None:
    """What is missing to compile bench.cpp, or None."""
    if root is None:
        return "Pinocchio (pip install pin) is not installed"
    if shutil.which("g++") is None:
        return "g++ is not installed"
    needs = {
        "Pinocchio": "include/pinocchio/algorithm/rnea-derivatives.hpp",
        "Boost": "include/boost/variant.hpp",
        "Eigen (pip install cmeel-eigen)": "include/eigen3/Eigen/Core",
    }
    for what, rel in needs.items():
        if not os.path.exists(os.path.join(root, rel)):
            return f"{what} headers are missing ({os.path.join(root, rel)})"
    return None


def build(root: str) -> str:
    """Compile bench.cpp (cached by the source's hash); returns the executable's path."""
    with open(SOURCE, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()[:16]
    cache = os.path.join(tempfile.gettempdir(), "armdyn_pinocchio_cpp")
    exe = os.path.join(cache, f"bench-{digest}")
    if os.path.exists(exe):
        return exe
    os.makedirs(cache, exist_ok=True)
    cmd = [
        "g++",
        "-O3",
        "-march=native",
        "-DNDEBUG",
        "-std=c++17",
        # the Boost.MPL limits Pinocchio's CMake config asks of its users (its joint variant
        # has more than Boost's default 20 alternatives)
        "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
        "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
        "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
        "-DBOOST_FUSION_INVOKE_MAX_ARITY=12",
        f"-I{root}/include",
        f"-I{root}/include/eigen3",
        SOURCE,
        "-o",
        exe + ".tmp",
    ]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError("compiling bench.cpp failed:\n" + done.stderr[-3000:])
    os.replace(exe + ".tmp", exe)
    return exe


_TYPES = {
    "JointModelRX": "RX",
    "JointModelRY": "RY",
    "JointModelRZ": "RZ",
    "JointModelRevoluteUnaligned": "RU",
    "JointModelPX": "PX",
    "JointModelPY": "PY",
    "JointModelPZ": "PZ",
    "JointModelPrismaticUnaligned": "PU",
}


def describe(model) -> str:
    """bench.cpp's text description of a Pinocchio model (revolute/prismatic joints only)."""
    lines = ["gravity " + " ".join(repr(float(x)) for x in model.gravity.linear)]
    for j in range(1, model.njoints):
        jm = model.joints[j]
        kind = _TYPES.get(jm.shortname())
        if kind is None:
            raise ValueError(f"joint {model.names[j]}: type {jm.shortname()} is not handled by bench.cpp")
        axis = np.asarray(jm.extract().axis, dtype=float) if kind in ("RU", "PU") else np.zeros(3)
        X, inertia = model.jointPlacements[j], model.inertias[j]
        I = inertia.inertia
        numbers = [
            *axis,
            *X.rotation.reshape(-1),
            *X.translation,
            inertia.mass,
            *inertia.lever,
            I[0, 0],
            I[0, 1],
            I[1, 1],
            I[0, 2],
            I[1, 2],
            I[2, 2],
        ]
        lines.append(f"{model.parents[j]} {kind} " + " ".join(repr(float(x)) for x in numbers))
    return "\n".join(lines) + "\n"


def urdf_models() -> dict:
    """Pinocchio's models of UR5, Panda (fingers locked) and iiwa14, parsed from the URDFs."""
    import pinocchio as pin

    sys.path.insert(0, os.path.dirname(HERE))
    import arms

    pd_full = pin.buildModelFromUrdf(arms._example_robot_data_urdf("panda_description/urdf/panda.urdf"))
    fingers = [pd_full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    return {
        "ur5": pin.buildModelFromUrdf(arms._example_robot_data_urdf("ur_description/urdf/ur5_robot.urdf")),
        "panda": pin.buildReducedModel(pd_full, fingers, pin.neutral(pd_full)),
        "iiwa14": pin.buildModelFromUrdf(arms.IIWA_URDF),
    }


def run(number: int = 20000, repeat: int = 21, models: dict | None = None) -> dict | None:
    """{arm: {algorithm: seconds per call, "nv": n}}, or None (with the reason printed)
    when the headers or the compiler are missing."""
    import pinocchio as pin

    root = prefix()
    why = missing_headers(root)
    if why:
        print(f"Pinocchio C++ timing skipped: {why}")
        return None
    exe = build(root)
    out = {}
    for name, model in (models or urdf_models()).items():
        with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
            f.write(describe(model))
        try:
            done = subprocess.run([exe, f.name, str(number), str(repeat)], capture_output=True, text=True, timeout=900)
        finally:
            os.unlink(f.name)
        if done.returncode != 0:
            raise RuntimeError(f"{name}: bench failed: {done.stderr.strip()}")
        res = json.loads(done.stdout)
        # the C++ model is Pinocchio's Python model: same tau at the program's first state
        data = model.createData()
        tau = pin.rnea(model, data, np.array(res["q0"]), np.array(res["v0"]), np.array(res["a0"]))
        err = np.max(np.abs(tau - np.array(res["tau0"]))) / max(np.max(np.abs(tau)), 1.0)
        if not (np.isfinite(err) and err < 1e-12 and res["nv"] == model.nv):
            raise RuntimeError(f"{name}: the C++ model differs from Pinocchio's Python model (tau error {err:.1e})")
        out[name] = {"nv": res["nv"], **{k: res[k] for k in ALGORITHMS}}
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--number", type=int, default=20000, help="calls per timed run")
    ap.add_argument("--repeat", type=int, default=21, help="timed runs (the median is kept)")
    args = ap.parse_args(argv)
    res = run(args.number, args.repeat)
    if res is None:
        return
    print(
        f"Pinocchio {__import__('pinocchio').__version__} C++ per call (median of {args.repeat} x {args.number}), us:"
    )
    print(f"{'arm':8} {'nv':>3} " + " ".join(f"{a:>17}" for a in ALGORITHMS))
    for name, r in res.items():
        print(f"{name:8} {r['nv']:>3} " + " ".join(f"{r[a] * 1e6:>17.3f}" for a in ALGORITHMS))


if __name__ == "__main__":
    main()
