"""Where a scenario drives a candidate: a simulation of the candidate's own in a world the scenario
writes (:class:`Lab`, :class:`LabSession`), on the simulator library's runner
(:class:`thorvald_sim.runner.RobotSession`): the candidate's own base_driver core on drives measured
from the simulated joints, in lockstep, seeded, without a ROS master.

Not pure: it runs pybullet (one DIRECT client a session, closed at its end).
"""

import math
from typing import Callable, List, Mapping, Optional, Sequence, Tuple

import pybullet as p

from thorvald_sim.robot import MotorLoad
from thorvald_sim.runner import RobotSession, RunOptions
from thorvald_sim.world import parse_world

from .scenarios.kind import Pose, Twist


class LabSession:
    """One drive: the candidate spawned in a world; base_link's pose recorded at every control instant."""

    def __init__(self, robot_file: str, options: RunOptions, world: Mapping, name: str):
        self._session = RobotSession(robot_file, options, parse_world(dict(world), source=name))
        self.track: List[Pose] = []
        self.outline = self._outline()

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
        position, orientation = self._session.robot.world_pose()
        roll, pitch, yaw = p.getEulerFromQuaternion(orientation)
        # pybullet's pitch is about y, positive nose down; a climb is nose up
        return Pose(self._session.time, position[0], position[1], position[2], roll, -pitch, yaw)

    def motor_loads(self) -> List[MotorLoad]:
        return self._session.robot.motor_torques()

    def push(self, force: Optional[Sequence[float]], at: Sequence[float] = (0.0, 0.0, 0.0)) -> None:
        self._session.push(force, at)

    def _outline(self) -> Tuple[Tuple[float, float], ...]:
        """The corners in plan of every link's bounding box at the spawn pose, in base_link [m]: the
        robot's outermost points (the frame, the wheels, what it carries)."""
        robot = self._session.robot
        (x0, y0, _), orientation = robot.world_pose()
        yaw = p.getEulerFromQuaternion(orientation)[2]
        c, s = math.cos(yaw), math.sin(yaw)
        points = []
        for link in range(-1, p.getNumJoints(robot.body, physicsClientId=robot.client)):
            lo, hi = p.getAABB(robot.body, link, physicsClientId=robot.client)
            for x, y in ((lo[0], lo[1]), (lo[0], hi[1]), (hi[0], lo[1]), (hi[0], hi[1])):
                dx, dy = x - x0, y - y0
                points.append((c * dx + s * dy, -s * dx + c * dy))
        return tuple(points)

    def close(self) -> None:
        self._session.close()

    def __enter__(self) -> "LabSession":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class Lab:
    """Makes the sessions of one candidate's runs: its robot file, as-built and seed."""

    def __init__(self, robot_file: str, as_built: str = "", seed: int = 0, physics_rate: float = 240.0):
        self.robot_file = robot_file
        self.as_built = as_built
        self.seed = seed
        self.physics_rate = physics_rate
        self.sessions = 0  # made so far: each a spawn in a world of its own

    def session(
        self, world: Mapping, *, x: float = 0.0, y: float = 0.0, z: float = 0.0, yaw: float = 0.0, roll: float = 0.0
    ) -> LabSession:
        self.sessions += 1
        options = RunOptions(
            as_built=self.as_built, seed=self.seed, x=x, y=y, z=z, yaw=yaw, roll=roll, physics_rate=self.physics_rate
        )
        return LabSession(self.robot_file, options, world, name=f"<scenario world {self.sessions}>")
