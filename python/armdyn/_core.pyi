"""Type stub of the compiled Rust extension (crates/armdyn-py): the public wrappers in
armdyn.numeric carry the documented signatures; this stub only names the compiled
class and lets everything else through as Any."""

from typing import Any

class ModelBuilder:
    """Builds a NumericModel joint by joint (crates/armdyn-py/src/builder.rs)."""

    def __init__(self, name: str, gravity: Any, base: str, floating: bool = False) -> None: ...
    def set_base_body(self, mass: Any, com: Any, inertia: Any) -> None: ...
    def add_joint(
        self,
        name: str,
        parent: str,
        child: str,
        kind: str,
        rotation: Any,
        xyz: Any,
        axis: Any,
        coordinates: list[str],
        dynamics: Any = None,
    ) -> int: ...
    def append_body(self, joint: int, mass: Any, com: Any, inertia: Any) -> None: ...
    def build(self) -> NumericModel: ...

class NumericModel:
    """A robot compiled for numeric evaluation (see armdyn.numeric.compile_model; built
    by ModelBuilder)."""

    @property
    def dof(self) -> int: ...
    @property
    def nlinks(self) -> int: ...
    @property
    def name(self) -> str: ...
    @property
    def link_names(self) -> list[str]: ...
    @property
    def coordinate_names(self) -> list[str]: ...
    @property
    def gravity(self) -> tuple[float, float, float]: ...
    @property
    def floating(self) -> bool: ...
    @property
    def nq(self) -> int: ...
    @property
    def nv(self) -> int: ...
    def __getattr__(self, name: str) -> Any: ...

# armdyn.centroidal (crates/armdyn-py/src/centroidal.rs)
def center_of_mass(model: NumericModel, q: Any, threads: int | None = None) -> Any: ...
def com_jacobian(model: NumericModel, q: Any, threads: int | None = None) -> Any: ...
def centroidal_map(model: NumericModel, q: Any, threads: int | None = None) -> Any: ...
def centroidal_momentum(model: NumericModel, q: Any, v: Any, threads: int | None = None) -> Any: ...
def centroidal_momentum_rate(model: NumericModel, q: Any, v: Any, a: Any, threads: int | None = None) -> Any: ...
def centroidal_map_rate(model: NumericModel, q: Any, v: Any, threads: int | None = None) -> Any: ...

# The derivative entries (crates/armdyn-py/src/derivatives.rs; a floating model's in
# floating_derivatives.rs). With ``n = model.dof``: a fixed base takes q, qd and the third
# array as (n,) or (N, n) and returns (n, n) or (N, n, n) matrices; a floating base
# (``model.floating``) takes q in the configuration space, (nq,) = (7 + n,), qd and the
# third array in the velocity space, (nv,) = (6 + n,), or (N, nq) and (N, nv), and returns
# (nv, nv) or (N, nv, nv) matrices, d/dq on the tangent space (along integrate(q, dq)),
# and takes f_ext (nlinks, 6) (or (N, nlinks, 6)) in the link frames only (frame="local").
# ``model`` must be a NumericModel: anything else is a TypeError (armdyn.numeric relies on it).

def rnea_derivatives(
    model: Any,
    q: Any,
    qd: Any,
    qdd: Any,
    f_ext: Any = None,
    frame: str = "local",
    threads: int | None = None,
    out: Any = None,
) -> tuple[Any, Any, Any]:
    """``(dtau_dq, dtau_dqd, M)`` (see above; armdyn.numeric.rnea_derivatives)."""

def aba_derivatives(
    model: Any,
    q: Any,
    qd: Any,
    tau: Any,
    f_ext: Any = None,
    frame: str = "local",
    threads: int | None = None,
    out: Any = None,
) -> tuple[Any, Any, Any]:
    """``(dqdd_dq, dqdd_dqd, Minv)`` (see above; armdyn.numeric.aba_derivatives)."""

def minverse(model: Any, q: Any, threads: int | None = None, out: Any = None) -> Any:
    """M^-1, (n, n) or, floating, (nv, nv), with a leading N for a batch."""

# The configuration manifold's maps of the integrators (crates/armdyn-py/src/simulate.rs),
# row by row: q (N, nq), xi, theta, v (N, nv), a floating base's included.
def _manifold_integrate(model: NumericModel, q: Any, xi: Any) -> Any:
    """``q (+) xi`` (N, nq), as armdyn.configuration.integrate."""

def _manifold_local_rate(model: NumericModel, theta: Any, v: Any) -> Any:
    """Runge-Kutta-Munthe-Kaas's ``dexp^-1_{-theta}(v)`` to fourth order (N, nv)."""

def __getattr__(name: str) -> Any: ...
