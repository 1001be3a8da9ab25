"""Generated code for the dynamics of a robot: C99, Python or NumPy. :func:`codegen` is
exported as ``armdyn.codegen``; this package prints programs and compiles the C.

    code = armdyn.codegen(robot, what=("tau", "M", "C", "g"), lang="c")   # GeneratedCode
    print(code.source)              # readable: named temporaries, op counts in the header
    code.op_counts["tau"]           # {'mul': ..., 'add': ..., 'sin_cos': ..., 'total': ...}
    lib = armdyn.printing.compile(robot.bind(), what=("tau", "M"))  # system C compiler
    tau = lib.tau(q, qd, qdd)       # q, qd, qdd: (dof,) or (N, dof) float64

Where each quantity comes from (all with the barycentric / standard inertial parameters
of each link, the architecture's order: mass, first moment m c, inertia about the link origin):

* tau: customized Newton-Euler (:mod:`armdyn.programs.customized_ne`);
* g:   the same recursion with ``qd = qdd = 0``; bias: with ``qdd = 0``;
* M:   composite links (:mod:`armdyn.programs.composite_mass_matrix`);
* C:   the Christoffel symbols of that M, its program differentiated line by line
  (:mod:`armdyn.programs.coriolis_program`);
* regressor: ``armdyn.identification.regressor(robot).Y`` (dof x P) through SymPy's
  common-subexpression elimination.

tau, g, M and C are evaluated at Khalil's grouped parameters
(:mod:`armdyn.programs.grouping`: what of a link's inertia rides on its parent moved
there, exactly), computed once per parameter set in the header; the zeros they leave
(``M_j = MZ_j = YY_j = 0`` behind a revolute joint) propagate, so fewer operations run
per state. For tau and g each leaf link's frame is also turned about its joint axis so
that its first moment lies on y (:mod:`armdyn.programs.leaf_frames`; the angle ``th`` and
the turned parameters are computed once per parameter set, the joint angle becomes
``q + th``). Joint friction, rotor inertia and torque offsets, where the model has them, are
added as docs/architecture.md writes them: all to tau, ``Ia`` to M's diagonal, the offset to g.

``base=True`` (needs :mod:`armdyn.identification`): the base parameters ``beta`` are the
inputs. When each groups standard parameters onto one whose regressor column it keeps
(Khalil's grouping), tau, g, M and C come from the same customized algorithms evaluated
at that point (:mod:`armdyn.programs.base_parameters`); otherwise from ``Y_base beta`` through CSE.
The regressor becomes the base regressor.

A model whose parameters are bound to numbers gives code with the numbers folded in (the
inertial constants included); otherwise every free symbol is an entry of the parameter
vector ``p``, in :attr:`GeneratedCode.parameters` order (the header lists them, with the
definition of each barycentric one in the model's parameters).

Conventions: ``M(q) qdd + C(q, qd) qd + g(q) = tau``, SI units, radians, joints in
``robot.coordinate_names`` order; batches are ``(N, dof)`` row-major. ``bias`` is
``C(q, qd) qd + g(q)`` (the same recursion with ``qdd = 0``).

A floating base (``root_joint="free-flyer"``) or joints of several coordinates
(:mod:`armdyn.printing.generate_floating`): the functions take Pinocchio's ``q`` (nq,),
``v`` and ``a`` (nv,) (every quaternion x, y, z, w normalised in the code: the rotation of
``q/|q|``) and give tau, M, g and bias in Pinocchio's order (the default ``what``); C,
the regressor and ``base=True`` are refused with the reason.
"""

from __future__ import annotations

from ..programs.program import Program
from .compile import CompiledCode, compile
from .generate import LANGUAGES, QUANTITIES, GeneratedCode, codegen, write_files

__all__ = ["codegen", "compile", "GeneratedCode", "CompiledCode", "Program", "QUANTITIES", "LANGUAGES", "write_files"]
