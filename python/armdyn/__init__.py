"""armdyn: dynamics of robot arms, derived symbolically and computed numerically."""
from .errors import ModelError, UnboundParameterError
from .model import Joint, Link, Robot

__all__ = ["ModelError", "UnboundParameterError", "Joint", "Link", "Robot"]
