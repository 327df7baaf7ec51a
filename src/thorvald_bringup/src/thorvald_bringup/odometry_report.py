"""The paper's odometry verification (section 3.3.2), as numbers: pure, from recorded series.

A drive is recorded as the commands, base_driver's odometry (``odometry/base_raw``), ground truth
(``odometry/gazebo``) and base_driver's measured drive states (``base_state``), and, as the paper
measured it, an RTK-GNSS fix (``gps/fix``, 10 Hz, 2 cm) and the IMU's yaw (``imu/data``): the report
gives odometry's figures against both, the simulator's true pose and RTK-GNSS. Both odometry
estimators are replayed from the same drive states through the calculator base_driver uses (the
one of thorvald_base, loaded by its plugin name), so they are compared on one drive; the replayed
``lsq`` must agree with what base_driver published live, which checks the replay itself.

Every path is expressed in the frame of its own pose at the start of the manoeuvre (the first
non-zero command), as the paper's Figure 8 starts both paths at one point: ground truth lives in the
simulator's odom frame, odometry in base_driver's, and each drifts apart before the start (spawn,
settling) in ways the experiment is not about.
"""

import bisect
import math
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

from thorvald_base.bag_topics import lost_messages, lost_sentence
from thorvald_base.kinematics import DriveState
from thorvald_model.datum import WGS84_A, WGS84_E2, earth_radii  # noqa: F401  (the constants: for tests)

from .errors import ReportError

# The paper's figures for its six-wheeled robot on tarmac (section 3.3.2).
PAPER_TRUTH_DISTANCE = 80.2  # [m] by RTK-GNSS
PAPER_ODOMETRY_DISTANCE = 81.0  # [m]
PAPER_END_POINT_DIFFERENCE = 2.2  # [m]
PAPER_DURATION = 77.0  # [s]
PAPER_SEED = 0  # the paper estimator's random pairs, for a reproducible report
REST = 1.5  # [s] after the last command: base_driver's wheels have ramped down
# Against RTK-GNSS, distances are measured of every path alike: at the fixes' instants, averaged over
# GNSS_SMOOTHING consecutive ones (0.5 s at 10 Hz), between points at least GNSS_SPACING [m] apart. Summed
# between raw consecutive fixes (0.1 m apart at 1 m/s), 2 cm of noise per axis adds 0.0008 / (2 d)
# to each d: +4 %, and a robot standing still would seem to move. Averaged over 5, two neighbours
# differ by noise of 2 x 0.0004 / 25 per axis: +0.16 % a 0.1 m step; the spacing keeps a standing
# robot still and cuts corners by at most 0.1 (sqrt 2 - 1) = 0.04 m a right angle.
GNSS_SPACING = 0.1
GNSS_SMOOTHING = 5
SHORT_DRIVE = 0.97  # ground truth below this share of the planned distance: the drive fell behind


@dataclass
class Path:
    """Poses and body-frame velocities over time (an odometry topic, or a replayed estimator)."""

    t: List[float] = field(default_factory=list)  # [s]
    x: List[float] = field(default_factory=list)  # [m]
    y: List[float] = field(default_factory=list)
    yaw: List[float] = field(default_factory=list)  # [rad]
    vx: List[float] = field(default_factory=list)  # [m/s] in base_link
    vy: List[float] = field(default_factory=list)
    wz: List[float] = field(default_factory=list)  # [rad/s]

    def append(self, t: float, pose: Tuple[float, float, float], twist: Tuple[float, float, float]) -> None:
        """One sample: pose (x, y, yaw) and twist (vx, vy, wz)."""
        for name, value in zip(("t", "x", "y", "yaw", "vx", "vy", "wz"), (t, *pose, *twist)):
            getattr(self, name).append(float(value))

    def __len__(self) -> int:
        return len(self.t)


@dataclass
class Recording:
    """One drive as recorded: each list in time order."""

    commands: List[Tuple[float, float, float, float]]  # (t, vx, vy, wz) as sent to the robot
    truth: Path  # odometry/gazebo
    odometry: Path  # odometry/base_raw, as base_driver published it
    states: List[Tuple[float, Tuple[float, ...], Tuple[float, ...]]]  # (t, steering [rad], rim speed [m/s])
    robot: str = ""
    source: str = ""  # the bag file
    gnss: Path = field(default_factory=Path)  # RTK-GNSS positions with the IMU's yaw (gnss_path); may be empty
    sequences: dict = field(default_factory=dict)  # topic -> the header.seq of each message recorded


def check_complete(recording: Recording) -> None:
    """ReportError when a message the report reads was published and not recorded: every control
    instant's drive states, odometry and ground truth must be in the bag, or the figures (the paper
    estimator's replay above all) would silently differ from a complete recording's."""
    lost = lost_messages(recording.sequences)
    if lost:
        raise ReportError(
            f"{recording.source}: the recording is incomplete ({lost_sentence(lost)}): a reader fell behind "
            "and dropped messages, so the figures would differ from a complete run's; record again"
        )


@dataclass(frozen=True)
class Figures:
    """One path's figures against ground truth."""

    distance: float  # [m]
    distance_error: float  # [%] of the ground-truth distance (nan for ground truth itself)
    end_point_difference: float  # [m] from ground truth's end point
    heading_difference: float  # [rad] at the end, from ground truth's heading


@dataclass
class Report:
    recording: Recording
    start: float  # [s] first non-zero command
    end: float  # [s] REST after the last non-zero command (or the end of the recording)
    paths: dict  # name -> Path, aligned at the start: "ground truth", "odometry lsq", "odometry paper"
    figures: dict  # name -> Figures
    replay_agreement: float  # [m] largest distance between replayed lsq and base_driver's odometry
    planned_distance: float = math.nan  # [m] of the manoeuvre's plan, when the recording drove it
    missing_states: int = 0  # base_driver cycles with odometry but no base_state in the recording
    figures_gnss: dict = field(default_factory=dict)  # name -> Figures against RTK-GNSS (when recorded)


def manoeuvre_start(commands: Sequence[Tuple[float, float, float, float]]) -> float:
    for t, vx, vy, wz in commands:
        if vx or vy or wz:
            return t
    raise ReportError("no non-zero velocity command in the recording: nothing was driven")


def manoeuvre_end(commands: Sequence[Tuple[float, float, float, float]], rest: float = REST) -> float:
    """rest [s] after the last non-zero command: the robot has stopped, the recording may go on."""
    last = max((t for t, vx, vy, wz in commands if vx or vy or wz), default=None)
    if last is None:
        raise ReportError("no non-zero velocity command in the recording: nothing was driven")
    return last + rest


def replay(calculator, states: Sequence[Tuple[float, Sequence[float], Sequence[float]]]) -> Path:
    """base_driver's odometry recomputed from its measured drive states with this calculator."""
    path = Path()
    for t, steering, speed in states:
        odom = calculator.calculate_odometry([DriveState(a, v, 0.0) for a, v in zip(steering, speed)], t)
        pose, twist = odom.pose, odom.twist
        path.append(t, (pose.x, pose.y, pose.yaw), (twist.vx, twist.vy, twist.wz))
    return path


def pose_at(path: Path, t: float) -> Tuple[float, float, float]:
    """The pose of the last sample at or before t (the first one if t is earlier)."""
    i = max(0, bisect.bisect_right(path.t, t) - 1)
    return path.x[i], path.y[i], path.yaw[i]


def aligned(path: Path, start: float, end: float) -> Path:
    """The samples in [start, end], as poses in the frame of the pose at start."""
    x0, y0, yaw0 = pose_at(path, start)
    c, s = math.cos(yaw0), math.sin(yaw0)
    out = Path()
    for i, t in enumerate(path.t):
        if start <= t <= end:
            dx, dy = path.x[i] - x0, path.y[i] - y0
            pose = (c * dx + s * dy, -s * dx + c * dy, math.remainder(path.yaw[i] - yaw0, 2 * math.pi))
            out.append(t, pose, (path.vx[i], path.vy[i], path.wz[i]))
    if not out.t or out.t[0] != start:  # the pose at start itself, so every path starts at the origin
        out.t.insert(0, start)
        for name in ("x", "y", "yaw"):
            getattr(out, name).insert(0, 0.0)
        for name in ("vx", "vy", "wz"):
            values = getattr(out, name)
            values.insert(0, values[0] if values else 0.0)
    return out


def path_length(path: Path) -> float:
    return sum(math.hypot(x1 - x0, y1 - y0) for x0, y0, x1, y1 in zip(path.x, path.y, path.x[1:], path.y[1:]))


def figures_of(path: Path, truth: Path, length=path_length) -> Figures:
    """path's figures against truth; length: how a path's distance is measured (of both)."""
    d, dt = length(path), length(truth)
    return Figures(
        d,
        (d - dt) / dt * 100.0 if path is not truth and dt > 0 else math.nan,
        math.hypot(path.x[-1] - truth.x[-1], path.y[-1] - truth.y[-1]),
        math.remainder(path.yaw[-1] - truth.yaw[-1], 2 * math.pi),
    )


def spaced_length(path: Path, spacing: float = GNSS_SPACING) -> float:
    """A noisy path's length between points at least spacing [m] apart (and its last point)."""
    if not len(path):
        return 0.0
    total, kx, ky = 0.0, path.x[0], path.y[0]
    for x, y in zip(path.x, path.y):
        d = math.hypot(x - kx, y - ky)
        if d >= spacing:
            total, kx, ky = total + d, x, y
    return total + math.hypot(path.x[-1] - kx, path.y[-1] - ky)


def gnss_local(
    latitude: float, longitude: float, lat0: float, lon0: float, heading: float = 0.0
) -> Tuple[float, float]:
    """A fix [deg] as (x, y) [m] of the simulator's world about (lat0, lon0): hector_gazebo_plugins'
    mapping inverted (its x along the reference heading [deg], y to the left of it: with heading 0,
    x north and y west), with the WGS84 radii of curvature at lat0."""
    radius_north, radius_east = earth_radii(lat0)
    north = math.radians(latitude - lat0) * radius_north
    west = -math.radians(longitude - lon0) * radius_east
    h = math.radians(heading)
    return math.cos(h) * north - math.sin(h) * west, math.sin(h) * north + math.cos(h) * west


def gnss_path(
    fixes: Sequence[Tuple[float, float, float]], yaws: Sequence[Tuple[float, float]], heading: float = 0.0
) -> Path:
    """RTK-GNSS as a path: fixes (t, latitude, longitude) in metres about the first one (gnss_local), each
    with the yaw of the IMU's latest reading (t, yaw) at or before it; no twist. The antenna is taken
    to stand over base_link (odometry_report.launch mounts it there)."""
    path = Path()
    if not fixes or not yaws:
        return path
    _, lat0, lon0 = fixes[0]
    times = [t for t, _ in yaws]
    for t, lat, lon in fixes:
        i = bisect.bisect_right(times, t) - 1
        if i < 0:
            continue
        path.append(t, (*gnss_local(lat, lon, lat0, lon0, heading), yaws[i][1]), (0.0, 0.0, 0.0))
    return path


def resampled(path: Path, times: Sequence[float]) -> Path:
    """The path's poses at the given times (each the last sample at or before it)."""
    out = Path()
    for t in times:
        out.append(t, pose_at(path, t), (0.0, 0.0, 0.0))
    return out


def smoothed(path: Path, window: int = GNSS_SMOOTHING) -> Path:
    """The path with each position the mean of window consecutive ones centred on it (fewer at the ends)."""
    out = Path()
    n, half = len(path), window // 2
    for i in range(n):
        lo, hi = max(0, i - half), min(n, i + half + 1)
        x = sum(path.x[lo:hi]) / (hi - lo)
        y = sum(path.y[lo:hi]) / (hi - lo)
        out.append(path.t[i], (x, y, path.yaw[i]), (path.vx[i], path.vy[i], path.wz[i]))
    return out


def make_report(recording: Recording, calculators: dict) -> Report:
    """The report of a recording; calculators: estimator name -> a fresh calculator for the robot."""
    for name, series in (("odometry/gazebo", recording.truth), ("odometry/base_raw", recording.odometry)):
        if not len(series):
            raise ReportError(f"no {name} in the recording")
    if not recording.states:
        raise ReportError("no base_state in the recording")
    start = manoeuvre_start(recording.commands)
    for name, first in (
        ("odometry/gazebo", recording.truth.t[0]),
        ("odometry/base_raw", recording.odometry.t[0]),
        ("base_state", recording.states[0][0]),
    ):
        if first > start:  # its pose at the start is unknown: aligning at its first sample would cut the path
            raise ReportError(
                f"{name} was recorded from {first:.2f} s only, {first - start:.2f} s after the manoeuvre started "
                f"({start:.2f} s): the recorder connected to it late"
            )
    end = min(
        manoeuvre_end(recording.commands), recording.truth.t[-1], recording.odometry.t[-1], recording.states[-1][0]
    )
    if end <= start:
        raise ReportError(f"the recording ends ({end:.2f} s) before the manoeuvre starts ({start:.2f} s)")
    truth = aligned(recording.truth, start, end)
    paths = {"ground truth": truth}
    replayed = {name: aligned(replay(calc, recording.states), start, end) for name, calc in calculators.items()}
    # lsq is what base_driver published (what its users see); its replay checks the replay
    paths["odometry lsq"] = aligned(recording.odometry, start, end)
    for name, path in replayed.items():
        paths.setdefault("odometry " + name, path)
    agreement = _largest_gap(replayed["lsq"], paths["odometry lsq"]) if "lsq" in replayed else math.nan
    figures = {name: figures_of(path, truth) for name, path in paths.items()}
    report = Report(recording, start, end, paths, figures, agreement)
    if len(recording.gnss) and recording.gnss.t[0] <= start:
        gnss = aligned(recording.gnss, start, end)
        report.paths["RTK-GNSS"] = gnss

        def length(p: Path) -> float:  # every path as the fixes see it: at their instants, averaged, spaced
            return spaced_length(smoothed(p if p is gnss else resampled(p, gnss.t)))

        report.figures_gnss = {
            name: figures_of(path, gnss, length) for name, path in (("RTK-GNSS", gnss), *paths.items())
        }
    # a loaded machine may drop messages on the way to rosbag; the replay then differs where they are missing
    report.missing_states = len(set(recording.odometry.t) - {s[0] for s in recording.states})
    return report


def _largest_gap(a: Path, b: Path) -> float:
    """Largest distance between a and b at b's sample times."""
    gap = 0.0
    for t, x, y in zip(b.t, b.x, b.y):
        ax, ay, _ = pose_at(a, t)
        gap = max(gap, math.hypot(ax - x, ay - y))
    return gap


def format_report(report: Report, targets: Optional[Tuple[float, float]] = None, paper: bool = True) -> str:
    """The table printed by odometry_report; targets: (distance error [%], end point [m]) for lsq; paper:
    the drive is the paper's manoeuvre, beside whose figures it is printed (another drive is not)."""
    rec = report.recording
    f = report.figures
    truth = f["ground truth"]
    names = [n for n in ("ground truth", "odometry lsq", "odometry paper") if n in f]
    head = f"{'':30}" + "".join(f"{n:>16}" for n in names) + (f"{'the paper':>22}" if paper else "")
    paper_cols = {
        "distance [m]": f"{PAPER_TRUTH_DISTANCE:.1f} / {PAPER_ODOMETRY_DISTANCE:.1f}",
        "distance error [%]": f"{(PAPER_ODOMETRY_DISTANCE - PAPER_TRUTH_DISTANCE) / PAPER_TRUTH_DISTANCE * 100:+.1f}",
        "end-point difference [m]": f"{PAPER_END_POINT_DIFFERENCE:.1f}",
        "heading at the end [deg]": "-",
    }

    def row(label, fmt, getter):
        cells = []
        for n in names:
            value = getter(f[n])
            cells.append(f"{'-' if math.isnan(value) else format(value, fmt):>16}")
        return f"  {label:28}" + "".join(cells) + (f"{paper_cols[label]:>22}" if paper else "")

    duration = f" (the paper: about {PAPER_DURATION:.0f} s)" if paper else ""
    lines = [
        f"Odometry report: {rec.robot or 'robot'}" + (f" ({rec.source})" if rec.source else ""),
        f"  manoeuvre {report.end - report.start:.1f} s from the first command{duration}; paths aligned at their "
        "start pose",
        head,
        row("distance [m]", ".2f", lambda g: g.distance),
        row("distance error [%]", "+.2f", lambda g: g.distance_error),
        row("end-point difference [m]", ".3f", lambda g: math.nan if g is truth else g.end_point_difference),
        row(
            "heading at the end [deg]", "+.2f", lambda g: math.nan if g is truth else math.degrees(g.heading_difference)
        ),
    ]
    if paper:
        lines.append("  (the paper's column: RTK-GNSS / odometry of its six-wheeled robot on tarmac, Figures 8 and 9)")
    if not math.isnan(report.replay_agreement):
        lines.append(
            f"  odometry lsq replayed from base_state agrees with base_driver's odometry/base_raw within "
            f"{report.replay_agreement * 1000:.1f} mm; paper estimator seeded with {PAPER_SEED}"
        )
        if report.missing_states:
            lines[-1] += f" ({report.missing_states} base_state messages missing from the recording)"
    if not math.isnan(report.planned_distance):
        lines.append(f"  distance by the manoeuvre's plan {report.planned_distance:.2f} m")
        if truth.distance < SHORT_DRIVE * report.planned_distance:
            lines[-1] += (
                f"; WARNING: ground truth drove only {truth.distance / report.planned_distance:.0%} of it: the "
                "commands fell behind the simulator, base_driver stopped the wheels at its command timeout "
                "(a loaded machine: try --real-time-factor 2)"
            )
    g = report.figures_gnss
    if g:
        names = [n for n in ("RTK-GNSS", "ground truth", "odometry lsq", "odometry paper") if n in g]
        lines += [
            f"  against RTK-GNSS (10 Hz, 2 cm) and the IMU's yaw, as the paper measured (distances between "
            f"points {GNSS_SPACING:g} m apart, the fixes averaged over {GNSS_SMOOTHING}):",
            f"{'':30}" + "".join(f"{n:>16}" for n in names),
        ]
        for label, fmt, getter in (
            ("distance [m]", ".2f", lambda v: v.distance),
            ("distance error [%]", "+.2f", lambda v: v.distance_error),
            ("end-point difference [m]", ".3f", lambda v: v.end_point_difference),
            ("heading at the end [deg]", "+.2f", lambda v: math.degrees(v.heading_difference)),
        ):
            cells = [math.nan if (n == "RTK-GNSS" and label != "distance [m]") else getter(g[n]) for n in names]
            lines.append(f"  {label:28}" + "".join(f"{'-' if math.isnan(c) else format(c, fmt):>16}" for c in cells))
    if targets is not None and "odometry lsq" in f:
        err, end = targets
        lsq = f["odometry lsq"]
        ok = abs(lsq.distance_error) < err and lsq.end_point_difference < end
        lines.append(
            f"  targets for lsq: |distance error| < {err:g} %, end point < {end:g} m: {'met' if ok else 'MISSED'}"
        )
    return "\n".join(lines)
