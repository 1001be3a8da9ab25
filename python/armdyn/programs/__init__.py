"""Straight-line programs for the dynamics, and the passes that make them short.

The operation-count optimiser: each quantity becomes a :class:`~armdyn.programs.program.Program`
(named temporaries, zeros and ones propagated), built by Khalil's customized algorithms
and the special forms that shorten them; :mod:`armdyn.printing` only prints programs.

* :mod:`~armdyn.programs.program`: the program, its builder and its operation counts;
* :mod:`~armdyn.programs.vectors`: 3-vector arithmetic that skips zeros and ones;
* :mod:`~armdyn.programs.customized_ne`: tau (and g) by the customized Newton-Euler,
  the driver over the per-link forms below;
* :mod:`~armdyn.programs.parallel_joints`: runs of parallel joints by their compound angle;
* :mod:`~armdyn.programs.two_rate_link`: a link turning at two rates on two axes (the
  second link of an arm, the links further along its run) in closed form;
* :mod:`~armdyn.programs.leaf_frames`: a leaf link's frame turned to put its first moment on y;
* :mod:`~armdyn.programs.grouping`: Khalil's grouped inertial parameters;
* :mod:`~armdyn.programs.base_parameters`: the customized algorithms at the base parameters;
* :mod:`~armdyn.programs.composite_mass_matrix`: M by composite links;
* :mod:`~armdyn.programs.coriolis_program`: C from M's program, differentiated line by line.

Nothing here imports :mod:`armdyn.printing`; of :mod:`armdyn.symbolic`, only its
expression-DAG helpers (:mod:`armdyn.symbolic.dag`).
"""
