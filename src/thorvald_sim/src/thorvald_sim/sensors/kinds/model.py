"""What every kind of simulated sensor is built on: :class:`Sensor` (mounted on a link of a robot in
pybullet, measured on its rate's grid of simulated time, its noise drawn per instant), the transforms
between a link and a sensor frame, and :class:`ModelContext` (what a model may need beyond its block:
gravity, the GNSS datum, other links of the robot). No ROS here; pybullet is imported when a model
first calls it (``p``), so that the blocks' readers, which import this module, stay pure.
"""

import zlib
from dataclasses import dataclass
from typing import Callable, Optional, Tuple

import numpy as np

from thorvald_base.rate_grid import RateGrid
from thorvald_model.datum import Datum

from .block import SensorSpec


class _Pybullet:
    """pybullet, imported when a model first calls it: the kinds' block readers beside the models
    (thorvald_sim.sensors.blocks, the description, the RViz configuration) never load it. Each name
    is looked up once, then held as an attribute."""

    def __getattr__(self, name: str):
        from ...bullet import pybullet  # noqa: PLC0415 (on purpose: see the class's docstring)

        value = getattr(pybullet, name)
        setattr(self, name, value)
        return value


p = _Pybullet()  # the kinds' models call pybullet through this

Vec3 = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]
Transform = Tuple[Vec3, Quat]
IDENTITY: Transform = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


@dataclass(frozen=True)
class ModelContext:
    """What a sensor's model may need beyond its block: the world's gravity [m/s^2], the GNSS datum
    (None: a block's own reference or hector's) and ``mount(link)``, (pybullet link index, the link's
    frame in it) of another link of the robot (MountError if it has none)."""

    gravity: float = 9.81
    datum: Optional[Datum] = None
    mount: Optional[Callable[[str], Tuple[int, Transform]]] = None


def transform(xyz: Vec3, rpy: Vec3) -> Transform:
    return tuple(xyz), tuple(p.getQuaternionFromEuler(rpy))


def compose(a: Transform, b: Transform) -> Transform:
    pos, quat = p.multiplyTransforms(a[0], a[1], b[0], b[1])
    return tuple(pos), tuple(quat)


def rotate(quat: Quat, v) -> np.ndarray:
    m = np.asarray(p.getMatrixFromQuaternion(quat)).reshape(3, 3)
    return m @ np.asarray(v, dtype=float)


def unrotate(quat: Quat, v) -> np.ndarray:
    m = np.asarray(p.getMatrixFromQuaternion(quat)).reshape(3, 3)
    return m.T @ np.asarray(v, dtype=float)


class InstantNoise:
    """A sensor's random numbers, drawn afresh at each instant: what is drawn at an instant depends
    on the seed, the robot's and sensor's names and the instant alone, not on when the sensor began
    to be read (subscribers come when they come), so a run repeats. A counter-based generator
    (Philox): the instant is the counter's second word (the first counts the draws within it), so
    two instants' draws never overlap; repositioning costs a couple of microseconds."""

    BLOCK = 32768  # standard normals drawn at once by normals()

    def __init__(self, seed: int, robot: str, sensor: str):
        self.key = np.array(
            [int(seed) & 0xFFFFFFFFFFFFFFFF, (zlib.crc32(robot.encode()) << 32) | zlib.crc32(sensor.encode())],
            dtype=np.uint64,
        )
        self.bits = np.random.Philox(key=self.key)
        self.generator = np.random.Generator(self.bits)
        self._block: Tuple[int, int, Optional[np.ndarray]] = (-1, 0, None)  # (block, n, its normals)

    def at(self, instant: int) -> np.random.Generator:
        """The generator positioned at the start of instant's draws (a whole number: the physics step)."""
        return self._position(instant, 0)

    def _position(self, word: int, kind: int) -> np.random.Generator:
        self.bits.state = {
            "bit_generator": "Philox",
            "state": {
                "counter": np.array([0, word & 0xFFFFFFFFFFFFFFFF, kind, 0], dtype=np.uint64),
                "key": self.key,
            },
            "buffer": np.zeros(4, dtype=np.uint64),
            "buffer_pos": 4,
            "has_uint32": 0,
            "uinteger": 0,
        }
        return self.generator

    def normals(self, reading: int, n: int) -> np.ndarray:
        """n standard normals of a reading (its index on the sensor's schedule: Sensor.reading), which
        depend on the seed, the names, n and the reading alone. They are drawn for BLOCK // n
        consecutive readings at once (the counter's third word 1 keeps them apart from at()'s): a
        lidar's 720 draws a scan cost a tenth of drawing them scan by scan. The array is the block's:
        read it, do not keep it."""
        per_block = max(1, self.BLOCK // n)
        block, slot = divmod(reading, per_block)
        cached, cached_n, draws = self._block
        if draws is None or cached != block or cached_n != n:
            draws = self._position(block, 1).standard_normal((per_block, n))
            self._block = (block, n, draws)
        return draws[slot]


class Sensor:
    """One sensor on one robot. ``read(now)`` measures and returns a reading (see the subclasses)."""

    def __init__(
        self,
        spec: SensorSpec,
        robot,
        mount: Tuple[int, Transform],
        noise: "InstantNoise",
        dt: float,
        *,
        context: ModelContext = ModelContext(),
    ):
        self.spec = spec
        self.robot = robot
        self.link_index, self.offset = mount
        self.noise = noise
        self.rng = noise.at(0)  # repositioned at each reading's instant by due()
        self.reading = 0  # the reading's index on the schedule's grid (the physics step's at rate 0), by due()
        self.dt = dt
        self.context = context
        self.schedule = RateGrid(spec.rate, dt)  # a rate above the physics rate: once a step

    @property
    def client(self) -> int:
        return self.robot.client

    def world_gravity(self, gravity: Tuple[float, float, float]) -> None:
        """The world's gravity [m/s^2] (a vector, world axes) changed, by the Gazebo API's
        set_physics_properties: a model that reads it follows (the IMU); the others ignore it."""

    def due(self, now: float) -> bool:
        """Whether a reading is due at now; if so, the noise is that instant's."""
        if not self.schedule.due(now):
            return False
        self.rng = self.noise.at(round(now / self.dt))
        self.reading = self.schedule.index  # the multiple of the period served (the step's, at rate 0)
        return True

    def pose(self) -> Transform:
        """The sensor frame in the world."""
        pos, quat, _, _, _ = self.robot.link_state(self.link_index)
        return compose((pos, quat), self.offset)

    def kinematics(self) -> Tuple[Transform, np.ndarray, np.ndarray]:
        """(sensor frame in the world, its point's velocity, angular velocity), world axes."""
        pos, quat, com, v, w = self.robot.link_state(self.link_index)
        frame = compose((pos, quat), self.offset)
        rx, ry, rz = frame[0][0] - com[0], frame[0][1] - com[1], frame[0][2] - com[2]
        wx, wy, wz = w
        # v + w x r, in floats: numpy's cross on 3-vectors cost more than the rest of an IMU reading
        point = (v[0] + wy * rz - wz * ry, v[1] + wz * rx - wx * rz, v[2] + wx * ry - wy * rx)
        return frame, np.array(point), np.array(w)

    def read(self, now: float):
        """A measurement at simulated time now [s] (what it costs is the caller's to count)."""
        raise NotImplementedError
