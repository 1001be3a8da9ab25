"""Plots of a simulation (:class:`armdyn.simulate.Trajectory`) with matplotlib.

``plot_trajectory(run, out="run.png")`` draws five panels against time (s):
joint positions q (rad or m), velocities qd, torques tau (N m or N), the kinetic,
potential and total energy (J), and the integration error in energy: for a passive run
the drift of the total energy ``(E(t) - E(0)) / max(|E(0)|, max T)``, with torques
applied the work-energy balance ``(E(t) - E(0) - W(t)) / scale`` (``W`` the work of
the torques, :attr:`armdyn.simulate.Trajectory.work`); either should stay tiny for an
arm without joint friction.
"""

from __future__ import annotations

import numpy as np

__all__ = ["plot_trajectory"]

#: a floating base's configuration coordinates (position, quaternion x y z w)
FLOATING_Q_NAMES = ("base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw")


def plot_trajectory(run, out=None, *, state: int = 0, title: str | None = None):
    """Figure of ``run`` (one state of a batch: row ``state``); saved to ``out`` (PNG, SVG,
    PDF by extension) if given, written to a temporary file first so that an error
    leaves nothing half-written. Returns the figure (closed when saved)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def pick(a):
        if a is None:
            return None
        a = np.asarray(a)
        batch = run.q.ndim == 3
        if batch and not 0 <= state < run.q.shape[0]:
            raise ValueError(f"state {state} out of range 0..{run.q.shape[0] - 1}")
        return a[state] if batch else a

    t = run.t
    q, qd, tau = pick(run.q), pick(run.qd), pick(run.tau)
    kinetic, potential = pick(run.kinetic), pick(run.potential)
    names = run.coordinate_names or [f"q{i}" for i in range(q.shape[1])]
    panels = 5 if kinetic is not None else 3
    fig, axes = plt.subplots(panels, 1, figsize=(8, 2.1 * panels), sharex=True)
    # a floating base: q has its position and quaternion, the velocities its twist (names)
    q_names = names if q.shape[1] == len(names) else [*FLOATING_Q_NAMES, *names[6:]]
    for ax, values, label in zip(axes, (q, qd, tau), ("q (rad, m)", "qd (rad/s, m/s)", "tau (N m, N)")):
        for i, name in enumerate(q_names if values is q else names):
            ax.plot(t, values[:, i], label=name, linewidth=1.2)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, ncol=min(len(names), 4), loc="upper right")
    if kinetic is not None:
        total = kinetic + potential
        ax = axes[3]
        ax.plot(t, kinetic, label="kinetic T")
        ax.plot(t, potential, label="potential V")
        ax.plot(t, total, label="total E = T + V", color="black", linewidth=1.5)
        ax.set_ylabel("energy (J)")
        ax.legend(fontsize=7, loc="upper right")
        ax.grid(alpha=0.3)
        work = pick(run.work) if run.work is not None else np.zeros_like(t)
        passive = not np.any(np.nan_to_num(tau))
        scale = max(abs(total[0]), np.nanmax(kinetic), np.nanmax(np.abs(work)), 1e-300)
        error = (total - total[0] - (0 if passive else work)) / scale
        ax = axes[4]
        ax.plot(t, error, color="tab:red")
        if passive:
            ax.set_ylabel("(E - E0) / scale")
            ax.set_title(f"energy drift: max |E - E0| / scale = {np.nanmax(np.abs(error)):.2e}", fontsize=9)
        else:
            ax.set_ylabel("(E - E0 - W) / scale")
            ax.set_title(
                f"energy balance (W: work of tau): max |E - E0 - W| / scale = {np.nanmax(np.abs(error)):.2e}",
                fontsize=9,
            )
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("t (s)")
    method = {"rk4": "RK4", "euler": "semi-implicit Euler"}.get(run.method, run.method)
    step = f"dt = {run.dt:g} s" if np.isfinite(run.dt) else "adaptive step"
    fig.suptitle(title or f"simulation: {method}, {step}", fontsize=11)
    fig.tight_layout()
    if out is not None:
        from pathlib import Path

        from ._io_atomic import atomic_write

        fmt = Path(out).suffix[1:].lower() or "png"  # as before: no extension writes PNG
        try:
            atomic_write(out, lambda tmp: fig.savefig(tmp, dpi=100, format=fmt))
        finally:
            plt.close(fig)
    return fig
