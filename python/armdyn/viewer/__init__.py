"""A 3-D view of an arm in the browser or in Jupyter (three.js, WebGL).

``view(robot, q=None)`` shows the arm at the joint coordinates ``q`` (a floating robot's
``q`` places its base too);
``animate(robot, times, Q)`` plays a trajectory (play/pause, a time slider, loop), at
most ``max_frames`` frames of it (evenly spread samples of the rows of ``Q``). Both
return a :class:`View`: ``.html()`` is a self-contained page (three.js inlined, nothing
loaded from the network, a Content-Security-Policy that forbids it), ``.save(path)``
writes it and Jupyter shows it (``_repr_html_``: a sandboxed ``<iframe srcdoc>``).

What is drawn: a URDF's ``<visual>`` geometry (boxes, cylinders, spheres; STL, OBJ and
COLLADA meshes, see :mod:`armdyn.viewer.geometry`); for every link without one (and
every YAML/DH model) a grey capsule from its joint's parent frame origin to its own
frame origin. Movable joints are short cylinders along their axes (orange revolute,
purple prismatic) and centres of mass dark spheres whose volume grows with the mass:
always for a model without visual geometry, with ``markers=True`` for one with it.
``frames=True`` adds each link frame's axes (x red, y green, z blue). The camera is
fitted to what the first frame draws; the floor grid lies in the base's xy plane, or
under the lowest point drawn when that is below the base (a legged robot's feet).

The link poses are computed here, by armdyn's forward kinematics
(:func:`armdyn.numeric.forward_kinematics`), and sent as JSON: per frame and link
``x, y, z, qx, qy, qz, qw`` (base frame, metres, rounded to 1e-7). The page's script
only places them. Names reach the page as JSON inside ``<script type="application/json">``
with ``<``, ``>``, ``&``, U+2028 and U+2029 escaped, or as escaped HTML text.

three.js r170 (MIT, its licence beside it) is vendored as its one minified module
``armdyn/viewer_assets/three.module.min.js`` (692 kB): a wheel works offline.
"""

from .geometry import MeshWarning
from .page import CSP, MAX_FRAMES, View, animate, script_json, view

__all__ = ["view", "animate", "View", "MeshWarning", "MAX_FRAMES", "CSP", "script_json"]
