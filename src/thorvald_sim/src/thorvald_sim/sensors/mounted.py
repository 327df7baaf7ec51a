"""The robot's sensors in the pybullet world: what each measures, when, with its noise. No ROS here.

A :class:`~thorvald_sim.sensors.kinds.model.Sensor` is made from a
:class:`~thorvald_sim.sensors.blocks.SensorSpec` and the robot it is on, by the model of its kind
(:mod:`thorvald_sim.sensors.kinds`: each kind's module says what its model measures). It is mounted
on the link its Gazebo block names: pybullet merges links fixed to each other
(``URDF_MERGE_FIXED_LINKS``), so the mount is the nearest link pybullet kept (the base, or the child
of a moving joint) and the fixed joints' origins between, composed with the block's ``<pose>``.

Measurements are taken at the sensor's rate on simulated time (``due``): the next instant is the
last one plus the period, so 40 Hz gives 40 measurements per simulated second whatever the physics
rate; a sensor nobody reads is not measured at all (the simulator node asks ``due`` only while
the sensor has subscribers) and starts again from the instant it is read again.

A sensor the robot goes without is a :class:`DisabledSensor`: refused at spawn (its block breaks
a rule, :mod:`thorvald_sim.sensors.blocks`, or its link cannot be mounted) or disabled when a
reading of it failed (``thorvald_sim.node.sensor_io``); the simulator reports each on /diagnostics
(:func:`disabled_report`) from then on.

Every sensor's noise comes from its own generator, seeded from the simulation's seed, the
robot's and sensor's names and the instant of the reading; readings fall on the multiples of the
sensor's period. A run therefore repeats whenever its subscribers came (see InstantNoise).
"""

import re
import time
import traceback
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple, Union

from thorvald_model.datum import WGS84_A, WGS84_E2, earth_radii  # noqa: F401  (the constants: for tests)

from ..errors import MountError
from ..physics.description import ParentJoint, link_tree
from .blocks import Datum, SensorBlocks, SensorSpec
from .kinds import kind_named
from .kinds.camera import Camera, Frame, depth_to_points
from .kinds.gnss import Gnss, GnssReading
from .kinds.imu import Imu, ImuReading
from .kinds.lidar import RAY_BATCH, Lidar, Scan, beams, ranges_from_hits
from .kinds.model import IDENTITY, InstantNoise, ModelContext, Sensor, Transform, compose, transform
from .kinds.p3d import LinkTruth, P3d


def find_mount(
    tree: Dict[str, ParentJoint], joint_index: Dict[str, int], link: str, offset: Transform = IDENTITY
) -> Tuple[int, Transform]:
    """(pybullet link index, sensor frame in that link's frame) of a sensor on ``link``: up the fixed
    joints to the nearest link pybullet kept (-1: the base)."""
    chain = offset
    seen = set()
    while link in tree:
        joint = tree[link]
        if joint.type != "fixed" and joint.joint in joint_index:
            return joint_index[joint.joint], chain
        if link in seen:
            raise MountError(f"link {link} is in a loop of joints")
        seen.add(link)
        chain = compose(transform(joint.origin.xyz, joint.origin.rpy), chain)
        link = joint.parent
    return -1, chain


@dataclass(frozen=True)
class MountProblem:
    """A sensor whose link cannot be mounted on the loaded robot."""

    spec: SensorSpec
    problem: str

    def __str__(self) -> str:
        return f"{self.spec.describe()}: {self.problem}"


def build_sensors(
    specs: Sequence[SensorSpec],
    robot,
    links: Union[str, Dict[str, ParentJoint]],
    *,
    seed: int = 0,
    dt: float,
    gravity: float = 9.81,
    datum: Optional[Datum] = None,
) -> Tuple[List[Sensor], List[MountProblem]]:
    """The robot's sensors from its specs and its link tree (or its description's text, parsed for it),
    each made by its kind's model; (sensors, problems) where a problem names a sensor whose link (or
    a link its model needs) cannot be mounted (the others are kept)."""
    specs = tuple(specs)
    tree = link_tree(links) if isinstance(links, str) else links
    # the robot's links: every child, every parent (the root among them) and the sensors' own
    known = {*tree, *(joint.parent for joint in tree.values()), *(spec.link for spec in specs)}

    def mount(link: str) -> Tuple[int, Transform]:
        """A link of the robot as a model may ask for it (a p3d's reference frame)."""
        if link not in known:
            raise MountError(f"frameName {link!r} is neither world nor a link of the robot")
        return find_mount(tree, robot.joint_index, link)

    context = ModelContext(gravity=gravity, datum=datum, mount=mount)
    sensors, problems = [], []
    for spec in specs:
        try:
            at = find_mount(tree, robot.joint_index, spec.link, transform(spec.pose.xyz, spec.pose.rpy))
            noise = InstantNoise(seed, robot.name, spec.name + "@" + spec.link)
            sensors.append(kind_named(spec.kind).model(spec, robot, at, noise, dt, context=context))
        except MountError as e:
            problems.append(MountProblem(spec, str(e)))
    return sensors, problems


# ---------------------------------------------------------------------------------------------
# What sensors cost (the simulator's /diagnostics)
# ---------------------------------------------------------------------------------------------
OK, WARN, ERROR = 0, 1, 2  # diagnostic_msgs/DiagnosticStatus levels


def read_due(
    sensors: Sequence[Sensor], wanted: Sequence[int], now: float, active: Dict[Tuple[str, int], bool], robot: str
) -> Dict[int, tuple]:
    """The sensors' one schedule, wherever they are read (the node's client or a physics worker's),
    after a physics step at simulated time now [s]: a sensor not in wanted (no readers) pauses its
    schedule the first step it has none; one in wanted is read when due. Returns, by index, ("read",
    reading, CPU [s]) or ("failed", the error's type and text, its traceback): one sensor's failure
    must not stop the simulation, and the node disables it alone. active: each (robot, index)'s readers
    at its last step, kept by the caller."""
    out = {}
    for k, sensor in enumerate(sensors):
        key = (robot, k)
        if k not in wanted:
            if active.get(key):
                sensor.schedule.pause()
                active[key] = False
            continue
        active[key] = True
        if not sensor.due(now):
            continue
        start = time.thread_time()
        try:
            reading = sensor.read(now)
        except Exception as e:  # whatever one sensor raises disables it alone (the node says so)
            out[k] = ("failed", f"{type(e).__name__}: {e}", traceback.format_exc())
            continue
        out[k] = ("read", reading, time.thread_time() - start)
    return out


@dataclass(frozen=True)
class SensorUse:
    """One sensor over a window of the simulation."""

    name: str  # how the report names it, e.g. "laser front_lidar (/thorvald_001/scan)"
    rate: float  # [Hz] asked; 0: every physics step
    cpu: float  # [s] of CPU spent measuring and publishing in the window
    readings: int


def sensor_report(
    uses: List[SensorUse], simulated: float, physics_rate: float, real_time_factor: float
) -> Tuple[int, str, Dict[str, str]]:
    """(level, message, values) of the sensors read in a window of ``simulated`` seconds.

    A sensor cannot hold its rate when it is asked for more than the physics rate (it is measured
    once a step at most), or when its own CPU per simulated second exceeds the wall time a
    simulated second may take at the real-time factor asked (it alone slows the simulation below
    it); either is a warning naming the sensor.
    """
    values: Dict[str, str] = {}
    late = []
    total = 0.0
    for use in uses:
        cpu = use.cpu / simulated if simulated > 0 else 0.0
        rate = use.readings / simulated if simulated > 0 else 0.0
        asked = use.rate if use.rate > 0 else physics_rate
        total += cpu
        values[f"{use.name}: CPU per simulated second [s]"] = f"{cpu:.5f}"
        values[f"{use.name}: rate [Hz]"] = f"{rate:.1f} of {asked:g}"
        if use.rate > physics_rate:
            late.append(f"{use.name} asks {use.rate:g} Hz, above the physics rate {physics_rate:g} Hz")
        elif real_time_factor > 0 and cpu * real_time_factor > 1.0:
            late.append(
                f"{use.name} costs {cpu:.2f} s of CPU per simulated second: not at {real_time_factor:g} x real time"
            )
    n = len(uses)
    message = f"{n} sensor{'' if n == 1 else 's'} read, {total:.4f} s CPU per simulated second"
    if late:
        return WARN, message + "; cannot hold its rate: " + "; ".join(late), values
    return OK, message, values


# ---------------------------------------------------------------------------------------------
# Sensors a robot goes without (the simulator's /diagnostics)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DisabledSensor:
    """A sensor the robot goes without: refused at spawn (``since`` None) or disabled when a reading
    of it failed (``since``: the simulated instant of that reading [s])."""

    name: str  # the sensor's (or model plugin's) name
    what: str  # the refusal (link, element path, rule) or the sensor and the error its reading raised
    topics: Tuple[str, ...] = ()  # resolved; none for a block refused before its topics were read
    since: Optional[float] = None


_BLOCK_NAME = re.compile(r"^(?:sensor|plugin)\[@name='([^']*)'\]")


def refused_sensors(blocks: Optional[SensorBlocks], problems) -> Tuple[DisabledSensor, ...]:
    """The sensors a robot spawned without: its refused blocks and its sensors that could not be mounted."""
    out = []
    for refused in blocks.refused if blocks is not None else ():
        match = _BLOCK_NAME.match(refused.path)
        out.append(DisabledSensor(match.group(1) if match else refused.path, str(refused)))
    out += [DisabledSensor(problem.spec.name, str(problem)) for problem in problems]
    return tuple(out)


def disabled_report(robot: str, sensor: DisabledSensor) -> Tuple[int, str, Dict[str, str]]:
    """(level, message, values) of a sensor the robot goes without: an error, as long as the robot is there."""
    topics = ", ".join(sensor.topics) or "none"
    if sensor.since is None:
        message = f"{robot}: sensor {sensor.name} refused at spawn: {sensor.what}"
    else:
        message = f"{robot}: sensor {sensor.name} ({topics}) disabled at {sensor.since:.3f} s: {sensor.what}"
    values = {"robot": robot, "sensor": sensor.name, "topics": topics, "why": sensor.what}
    if sensor.since is not None:
        values["disabled at [s]"] = f"{sensor.since:.3f}"
    return ERROR, message, values


__all__ = [
    "IDENTITY",
    "RAY_BATCH",
    "Camera",
    "DisabledSensor",
    "Frame",
    "Gnss",
    "GnssReading",
    "Imu",
    "ImuReading",
    "InstantNoise",
    "Lidar",
    "LinkTruth",
    "MountProblem",
    "P3d",
    "Scan",
    "Sensor",
    "SensorUse",
    "beams",
    "build_sensors",
    "depth_to_points",
    "disabled_report",
    "find_mount",
    "ranges_from_hits",
    "read_due",
    "refused_sensors",
    "sensor_report",
]
