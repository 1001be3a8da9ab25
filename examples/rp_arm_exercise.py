"""The exercise armdyn was built for (Robot Modeling and Control, assignment 7), checked.

    python examples/rp_arm_exercise.py

7-3  the parallel axis theorem, for a symbolic cloud of point masses;
7-4  the RP arm's equations of motion by iterated Newton-Euler, step by step;
     the rotational kinetic energy 1/2 w^T I w is the same in any frame;
     and the check of 7-4 by Lagrange's method.
"""

import sympy as sp

import armdyn
from armdyn import inertia
from armdyn.model import rpy_matrix
from armdyn.symbolic.agreement import trig_reduce
from armdyn.symbolic.report import steps_lines, tau_lines

# --- 7-3: I_P = I_C + M (|d|^2 1 - d d^T) for three point masses, exactly -----------------
ms = sp.symbols("m1:4", positive=True)
pts = [sp.Matrix(sp.symbols(f"x{i} y{i} z{i}")) for i in range(1, 4)]
M = sum(ms)
c = sum((m * p for m, p in zip(ms, pts)), sp.zeros(3, 1)) / M  # centre of mass
d = sp.Matrix(sp.symbols("dx dy dz"))  # from C to P
I_C = sum((inertia.point_inertia(m, p - c) for m, p in zip(ms, pts)), sp.zeros(3, 3))
I_P = sum((inertia.point_inertia(m, p - (c + d)) for m, p in zip(ms, pts)), sp.zeros(3, 3))
assert sp.simplify(I_P - inertia.parallel_axis(I_C, M, -d)) == sp.zeros(3, 3)
print("7-3: parallel axis theorem holds for a symbolic cloud of point masses")

# --- 7-4: Newton-Euler, every step, and the final torques ---------------------------------
robot = armdyn.load("rp-arm")
ne = armdyn.derive(robot, "newton-euler")
print("\n7-4: iterated Newton-Euler (vectors in each link's own frame)")
print("\n".join(steps_lines(ne)))

# --- rotational energy: the same in the link frame and in any other -------------------------
w = sp.Matrix(sp.symbols("w_x w_y w_z"))
Ixx, Iyy, Izz, Ixy, Ixz, Iyz = sp.symbols("Ixx Iyy Izz Ixy Ixz Iyz")
I_body = sp.Matrix([[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]])
R = rpy_matrix(*sp.symbols("roll pitch yaw"))
E_body = inertia.rotational_energy(I_body, w)
E_other = inertia.rotational_energy(inertia.rotate(I_body, R), R * w)
assert trig_reduce(E_body - E_other, sp.Matrix(sp.symbols("roll pitch yaw"))) == 0
print("\nE_rot = 1/2 w^T I w is unchanged by a change of frame (I -> R I R^T, w -> R w)")

# --- the check by Lagrange's method ----------------------------------------------------------
la = armdyn.derive(robot, "lagrange")
print("\nLagrange's method:")
print("\n".join(steps_lines(la)))
print("\nBoth methods give:")
print("\n".join(tau_lines(ne)))
print()
print(armdyn.check(ne, la).text())
