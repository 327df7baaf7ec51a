"""Where a scenario drives a candidate: a simulation of the candidate's own in a world the scenario
writes (:class:`Lab`, :class:`LabSession`), on the simulator library's runner
(:class:`thorvald_sim.tools.runner.RobotSession`): the candidate's own base_driver core on drives measured
from the simulated joints, in lockstep, seeded, without a ROS master. Everything it reads of the
robot (pose, outline, centre of mass, motor and wheel loads, a picture) the session offers.

Not pure: its session runs pybullet (one DIRECT client a session, closed at its end).
"""

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple

from thorvald_sim.physics.robot import MotorLoad
from thorvald_sim.physics.simulation import Camera, save_png
from thorvald_sim.tools.runner import RobotSession, RunOptions, Sample, urdf_args
from thorvald_sim.world import parse_world

from .design import description_of
from .scenarios.kind import Pose, Twist


class LabSession:
    """One drive: the candidate spawned in a world; base_link's pose recorded at every control instant."""

    def __init__(
        self,
        robot_file: str,
        options: RunOptions,
        world: Mapping,
        name: str,
        label: str = "",
        *,
        urdf: Optional[str] = None,
    ):
        self._session = RobotSession(robot_file, options, parse_world(dict(world), source=name), urdf=urdf)
        self.world = world
        self.label = label  # what the drive is, for the report's maps ("climb 14 deg")
        self.outcome = ""  # what came of it, set by the scenario ("ok", "traction", ...)
        self.shown: Optional[Mapping] = None  # the world the report draws, if not the physics' (plants)
        # what the report draws beside the track, set by the scenario (JSON values): a turn's centre and
        # circles, the plants a turn touched, which try of a series the drive was
        self.marks: Dict[str, Any] = {}
        self.track: List[Pose] = []
        self.outline = self._outline()
        self.centre_of_mass = self._centre_of_mass()
        self.on_close: Optional[Callable[[LabSession], None]] = None

    @property
    def time(self) -> float:
        return self._session.time

    @property
    def config(self):
        return self._session.config

    def run(
        self,
        until: float,
        command: Callable[[float], Optional[Twist]],
        stop: Optional[Callable[["LabSession"], bool]] = None,
    ) -> bool:
        """Steps until simulated time ``until`` [s], base_driver's core given ``command(t)`` at every control
        cycle; ``stop(self)`` after each may end it early (True, returned)."""

        def cycle(_session) -> bool:
            self.track.append(self.pose())
            return stop is not None and stop(self)

        return self._session.run(until, command, cycle)

    def pose(self) -> Pose:
        x, y, z, roll, pitch, yaw = self._session.pose()
        # pybullet's pitch is about y, positive nose down; a climb is nose up
        return Pose(self._session.time, x, y, z, roll, -pitch, yaw)

    def motor_loads(self) -> List[MotorLoad]:
        return self._session.motor_torques()

    def wheel_loads(self) -> List[float]:
        """[N] the ground's normal force on each drive's wheel, in drive order."""
        return self._session.wheel_loads()

    def push(self, force: Optional[Sequence[float]], at: Sequence[float] = (0.0, 0.0, 0.0)) -> None:
        self._session.push(force, at)

    def set_drive_params(self, changes: Sequence[Tuple[int, str, float]]) -> List[str]:
        """Changes the candidate's drive parameters while it runs, as base_driver's ``set_drive_params``
        does on a robot (:meth:`thorvald_base.core.BaseDriverCore.set_drive_params`): each change
        (drive index, key, value) validated as the robot file is, used from the next control cycle on.
        Returns the problems of the changes refused (the others are applied)."""
        return self._session.set_drive_params(changes)

    @property
    def odometry(self) -> List[Sample]:
        """base_driver's odometry (in the odom frame: the spawn pose) at every control instant so far."""
        return self._session.odometry

    def _outline(self) -> Tuple[Tuple[float, float], ...]:
        """The corners in plan of every link's bounding box at the spawn pose, in base_link [m]."""
        return self._session.outline()

    def _centre_of_mass(self) -> Tuple[float, float, float]:
        """[m] the simulated robot's centre of mass in base_link at the spawn pose: every body's mass
        where pybullet holds it: the description's, since the simulator loads each merged link's mass
        at its centre (thorvald_sim.physics.description.centre_fixed_links); measured, so that a fault of the
        loading would show beside the prediction, as pybullet's merge of fixed links did (3.9 cm
        higher on the example three-wheelers)."""
        return self._session.centre_of_mass()

    def picture(self, path: str, width: int = 480, height: int = 360) -> None:
        """A PNG of the robot where it stands, from its front left and above (pybullet's software renderer)."""
        x, y, z = self._session.pose()[:3]
        reach = max(math.hypot(px, py) for px, py in self.outline) + 0.5
        camera = Camera(eye=(x + 1.6 * reach, y + 1.2 * reach, z + 1.3 * reach), target=(x, y, z + 0.45),
                        width=width, height=height, fov=45.0)  # fmt: skip
        save_png(self._session.render(camera), path)

    def close(self) -> None:
        if self.on_close is not None:
            self.on_close(self)
            self.on_close = None
        self._session.close()

    def __enter__(self) -> "LabSession":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


@dataclass(frozen=True)
class Drive:
    """One finished drive, for the report's maps: what it was, its world, how it ended, its track."""

    label: str
    outcome: str
    world: Mapping
    track: Tuple[Pose, ...]
    marks: Mapping = field(default_factory=dict)  # the scenario's (LabSession.marks)


class Lab:
    """Makes the sessions of one candidate's runs: its robot file, as-built and seed; keeps each
    finished drive (:attr:`drives`)."""

    def __init__(self, robot_file: str, as_built: str = "", seed: int = 0, physics_rate: float = 240.0):
        self.robot_file = robot_file
        self.as_built = as_built
        self.seed = seed
        self.physics_rate = physics_rate
        self.sessions = 0  # made so far: each a spawn in a world of its own
        self.drives: List[Drive] = []
        self.simulated = 0.0  # [s] of simulated time over every finished session
        # [m] the simulated robot's centre of mass in base_link (LabSession.centre_of_mass), from the
        # first session: what a scenario compares with its description's; None before any session
        self.centre_of_mass: Optional[Tuple[float, float, float]] = None
        self._urdf: Optional[str] = None  # the robot's description, made at the first session

    def session(
        self,
        world: Mapping,
        *,
        x: float = 0.0,
        y: float = 0.0,
        z: float = 0.0,
        yaw: float = 0.0,
        roll: float = 0.0,
        label: str = "",
    ) -> LabSession:
        self.sessions += 1
        options = RunOptions(
            as_built=self.as_built, seed=self.seed, x=x, y=y, z=z, yaw=yaw, roll=roll, physics_rate=self.physics_rate
        )
        if self._urdf is None:  # one description for every session: their options differ in pose alone
            self._urdf = description_of(self.robot_file, **urdf_args(options))
        name = f"<scenario world {self.sessions}>"
        session = LabSession(self.robot_file, options, world, name=name, label=label, urdf=self._urdf)
        session.on_close = self._keep
        if self.centre_of_mass is None:
            self.centre_of_mass = session.centre_of_mass
        return session

    def _keep(self, session: LabSession) -> None:
        self.simulated += session.time
        world = session.shown if session.shown is not None else session.world
        self.drives.append(Drive(session.label, session.outcome, world, tuple(session.track), dict(session.marks)))
