"""armdyn: dynamics of robot arms, derived symbolically and computed numerically."""
from .errors import ModelError, UnboundParameterError
from . import inertia
from .model import Joint, Link, Robot

__all__ = ["inertia", "ModelError", "UnboundParameterError", "Joint", "Link", "Robot"]
