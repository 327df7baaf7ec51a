"""Figures 8 and 9 of the paper from a Report, as PNG files (matplotlib's Agg: no display needed).

Figure 8: the paths by ground truth, by RTK-GNSS (when recorded) and by each odometry estimator, start
and end marked (the figures in the legend are against the simulator's true pose).
Figure 9: vx, vy and wz over time: the command, base_driver's odometry (lsq) and ground truth.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # after choosing the backend

STYLES = {
    "ground truth": {"color": "black", "linewidth": 1.6},
    "odometry lsq": {"color": "tab:blue", "linewidth": 1.2},
    "odometry paper": {"color": "tab:orange", "linewidth": 1.0, "linestyle": "--"},
    "command": {"color": "tab:green", "linewidth": 1.0, "linestyle": ":"},
    "RTK-GNSS": {"color": "tab:gray", "linewidth": 0.8, "marker": ".", "markersize": 1.5},
}


def figure8(report, path: str) -> str:
    fig, ax = plt.subplots(figsize=(7, 7), dpi=100)
    for name, p in report.paths.items():
        fig_ = report.figures.get(name)
        label = (
            name
            if fig_ is None or name == "ground truth"
            else f"{name} ({fig_.distance_error:+.2f} %, end {fig_.end_point_difference:.2f} m)"
        )
        ax.plot(p.x, p.y, label=label, **STYLES.get(name, {}))
        ax.plot(p.x[-1], p.y[-1], marker="s", color=STYLES.get(name, {}).get("color"), markersize=6)
    ax.plot(0.0, 0.0, marker="o", color="tab:red", markersize=8, linestyle="none", label="start")
    ax.plot([], [], marker="s", color="gray", linestyle="none", label="end")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m] (start pose's frame)")
    ax.set_ylabel("y [m]")
    ax.set_title(f"Figure 8: paths of {report.recording.robot or 'the robot'}")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def figure9(report, path: str) -> str:
    fig, axes = plt.subplots(3, 1, figsize=(10, 7.5), dpi=100, sharex=True)
    t0 = report.start
    commands = [c for c in report.recording.commands if report.start - 1.0 <= c[0] <= report.end]
    ct = [c[0] - t0 for c in commands]
    shown = ("ground truth", "odometry lsq")
    for ax, field, index, unit in zip(axes, ("vx", "vy", "wz"), (1, 2, 3), ("m/s", "m/s", "rad/s")):
        ax.step(ct, [c[index] for c in commands], where="post", label="command", **STYLES["command"])
        for name in shown:
            p = report.paths[name]
            ax.plot([t - t0 for t in p.t], getattr(p, field), label=name, **STYLES[name])
        ax.set_ylabel(f"{field} [{unit}]")
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=8, ncol=3)
    axes[0].set_title(f"Figure 9: velocities of {report.recording.robot or 'the robot'} in base_link")
    axes[-1].set_xlabel("time since the first command [s]")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path
