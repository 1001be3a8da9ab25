"""Identify the base parameters of a PUMA 560 with friction and rotor inertia.

    PYTHONPATH=python python examples/identification.py

1. The model: the bundled PUMA 560 with its published inertial values, plus per joint a
   viscous friction Fv, a Coulomb friction Fc and a rotor inertia Ia (the "true" robot).
2. The base parameters, exact and symbolic (Khalil's grouping), and their true values.
3. Torques simulated along 400 random states with the Rust rnea, plus Gaussian noise
   (sigma 0.01 N m); the base regressor evaluated at the same states by the Rust
   regressor; the base parameters recovered by least squares and compared with the truth.
"""

import warnings
from dataclasses import replace

import numpy as np

import armdyn
from armdyn import numeric as num
from armdyn.identification import base_parameters
from armdyn.model import Robot

rng = np.random.default_rng(0)
with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # the published PUMA set breaks a triangle inequality
    arm = armdyn.load("puma560", strict=False).bind()
    joints = [
        replace(j, damping=rng.uniform(0.5, 2), friction=rng.uniform(0.5, 2), armature=rng.uniform(0.1, 1))
        if j.movable
        else j
        for j in arm.joints
    ]
    arm = Robot(arm.name, arm.links.values(), joints, arm.gravity, strict=False)

base = base_parameters(arm)  # exact: grouped in the standard parameters' symbols
print(f"{len(base.names)} base parameters, e.g. {base.names[0]} = {base.beta[0]}")
truth = np.array([float(v) for v in base.values])

N = 400
Q, QD, QDD = rng.uniform(-np.pi, np.pi, (N, 6)), rng.uniform(-2, 2, (N, 6)), rng.uniform(-4, 4, (N, 6))
tau = num.rnea(arm, Q, QD, QDD) + rng.normal(0.0, 0.01, (N, 6))  # "measured" torques
W = num.regressor(arm, Q, QD, QDD)[:, :, base.columns].reshape(N * 6, -1)  # stacked base regressor
estimate, *_ = np.linalg.lstsq(W, tau.ravel(), rcond=None)

print(f"{'name':>6} {'true':>10} {'estimate':>10}")
for name, t, e in list(zip(base.names, truth, estimate))[:8]:
    print(f"{name:>6} {t:10.4f} {e:10.4f}")
print(f"max |estimate - true| over all {len(truth)}: {np.abs(estimate - truth).max():.2e}")
print(f"condition number of the stacked base regressor: {np.linalg.cond(W):.1f}")
