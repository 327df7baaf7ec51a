"""One robot in a pybullet world: loaded from its URDF, driven by torque-limited motors, measured.

No ROS here: the simulator node converts messages. The pybullet client id is passed in.

* Loading: ``URDF_USE_INERTIA_FROM_FILE`` (masses and inertias from the URDF),
  ``URDF_USE_IMPLICIT_CYLINDER`` (wheels roll as true cylinders, at exactly r omega),
  ``URDF_MERGE_FIXED_LINKS`` (the frame's fixed modules become one rigid body: about three times
  faster to step, and nothing of the frame moves anyway).
* Motors (the URDF's limits, which the generator derives from the configuration): each steering
  joint is a position servo with the joint's effort as torque limit and the commanded (or the
  joint's) speed limit; each wheel a velocity motor with the joint's effort as torque limit. The
  URDF's joint damping and friction are the original's figures for Gazebo's synchronising plugin;
  on motors they would fight the torque limits (and explicit damping of 100 N m s/rad on a
  0.12 kg m^2 wheel is unstable at 240 Hz), so driven joints get none.
* Wheels touch the ground with thin discs (``TYRE_CONTACT_WIDTH``, 1 cm): pybullet touches a
  cylinder lying on a plane at one rim, so a full-width wheel's contact lay 8 cm beside its centre
  line, which turned a differential robot's arcs 3 % tight and walked a spinning robot off its spot.
* Suspension joints are springs and dampers (``<springStiffness>`` and the joint's damping),
  applied every step. Passive joints (casters, support wheels) turn freely against their URDF
  friction.
* Every link has lateral friction 1.0, so a contact's friction (pybullet multiplies the two
  bodies') is the world surface's, and no velocity damping (pybullet's default drag of 0.04 /s).
* Ground truth is base_link's pose and twist: pybullet reports the base's centre of mass, so the
  URDF's inertial offset (all merged modules' centre of mass) is composed out.
* As built (:mod:`thorvald_sim.physics.as_built`, optional): wheels of their true rolling radii (the
  collision cylinders; the controllers still convert with the configured radius, as real ones do),
  steering modules homed off by their offsets (a command of a goes to a + offset, a measured a + offset
  reads a), the encoders' whole counts and whole motor rpm in what is reported, measurements (drive
  states, motor currents) reported ``delay`` late (the newest one at least that old), and a load of
  ``mass_offset`` on the frame.
"""

import math
import os
import tempfile
import xml.etree.ElementTree as ET
from collections import deque
from dataclasses import dataclass
from typing import List, Optional, Sequence, Set, Tuple, Union

from thorvald_base.bases import MeasuredDrive
from thorvald_model.motors import winding_current

from ..bullet import pybullet as p
from ..bullet import quiet_stdout
from .as_built import BuiltDrive, SimAsBuilt
from .description import (
    DescriptionError,
    RobotDescription,
    centre_fixed_links,
    narrow_tyres,
    set_wheel_radii,
)

LOAD_FLAGS = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_IMPLICIT_CYLINDER | p.URDF_MERGE_FIXED_LINKS
LINK_FRICTION = 1.0
STEERING_POSITION_GAIN = 0.5  # pybullet's servo gain: fraction of the position error closed per step
TYRE_CONTACT_WIDTH = 0.01  # [m]: the wheels' collision discs (see with_tyre_contact)
FOLLOW_HEADROOM = 2.0  # following states, the steering servo may turn this much faster than the drive


GRAVITY = 9.81  # [m/s^2]: a tyre's deflection is rated under its share of the weight at standard gravity
NO_REPORT = MeasuredDrive(math.nan, math.nan, math.nan, math.nan)  # a silenced drive's encoders


@dataclass(frozen=True)
class Pose2D:
    """A spawn pose: base_link at (x, y, z) [m] turned by yaw [rad] (and tilted by roll and pitch
    [rad], for a robot set down on a slope; its odom frame stays level)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    yaw: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0

    @property
    def quaternion(self) -> Tuple[float, float, float, float]:
        return tuple(p.getQuaternionFromEuler((self.roll, self.pitch, self.yaw)))


@dataclass(frozen=True)
class MotorLoad:
    """One drive's motors at an instant: torques [N m] and rates [rad/s] at the wheel and the steering axis."""

    wheel_torque: float
    wheel_rate: float
    steering_torque: float
    steering_rate: float


Vec3 = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]


def point_velocity(v: Vec3, w: Vec3, com: Vec3, point: Vec3) -> Vec3:
    """The velocity of a rigid body's point from its centre of mass's velocity v and its angular
    velocity w (one frame's axes): v + w x (point - com)."""
    r = (point[0] - com[0], point[1] - com[1], point[2] - com[2])
    return (
        v[0] + w[1] * r[2] - w[2] * r[1],
        v[1] + w[2] * r[0] - w[0] * r[2],
        v[2] + w[0] * r[1] - w[1] * r[0],
    )


class SimRobot:
    def __init__(
        self,
        client: int,
        name: str,
        description: RobotDescription,
        urdf: Union[str, ET.Element],
        pose: Pose2D,
        *,
        tyre_contact_width: float = TYRE_CONTACT_WIDTH,
        as_built: Optional[SimAsBuilt] = None,
    ):
        if as_built is not None and len(as_built.drives) != len(description.drives):
            raise DescriptionError(
                f"the as-built robot has {len(as_built.drives)} drives, the description {len(description.drives)}"
            )
        self.as_built = as_built
        self.built: List[BuiltDrive] = (
            list(as_built.drives) if as_built else [BuiltDrive(d.wheel_radius, 0.0) for d in description.drives]
        )
        self._history = deque()  # (time, drive states) measured, while reports are delayed
        self.silenced: Set[int] = set()  # drives whose encoders report nothing (silence)
        self._current_history = deque()  # (time, drive currents) likewise
        self._drive_joints = None  # the joints a drive state reads, in one getJointStates call
        self.client = client
        self.name = name
        self.description = description
        self.spawn_pose = pose
        self.missing_meshes = ()  # the description's elements whose mesh could not be found (Simulation.spawn)
        self.sensors = []  # thorvald_sim.sensors.mounted.Sensor of its Gazebo sensor blocks (Simulation.spawn)
        self.sensor_blocks = None  # thorvald_sim.sensors.blocks.SensorBlocks: also what is not simulated
        self.sensor_problems = []  # sensors that could not be mounted
        wheels = [d.wheel_joint for d in description.drives]
        wheels += [j.name for j in description.passive_wheels]
        radii = {
            d.wheel_joint: b.r_wheel for d, b in zip(description.drives, self.built) if b.r_wheel != d.wheel_radius
        }
        # a parsed <robot> (SpawnedDescription.for_pybullet) is the robot's own, changed in place
        tree = ET.fromstring(urdf) if isinstance(urdf, str) else urdf
        set_wheel_radii(tree, radii)
        narrow_tyres(tree, wheels, tyre_contact_width)
        centre_fixed_links(tree)  # LOAD_FLAGS merges fixed links: each mass where the description has it
        text = ET.tostring(tree, encoding="unicode")
        with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as f:
            f.write(text)
        try:
            orientation = pose.quaternion
            with quiet_stdout():
                self.body = p.loadURDF(
                    f.name, (pose.x, pose.y, pose.z), orientation, flags=LOAD_FLAGS, physicsClientId=client
                )
        except p.error as e:
            raise DescriptionError(f"pybullet cannot load the description ({e})") from None
        finally:
            os.unlink(f.name)
        self.joint_index = {}
        for j in range(p.getNumJoints(self.body, physicsClientId=client)):
            self.joint_index[p.getJointInfo(self.body, j, physicsClientId=client)[1].decode()] = j
        if as_built is not None and as_built.mass_offset > 0:  # a load at the frame's centre of mass
            mass = p.getDynamicsInfo(self.body, -1, physicsClientId=client)[0]
            p.changeDynamics(self.body, -1, mass=mass + as_built.mass_offset, physicsClientId=client)
        dyn = p.getDynamicsInfo(self.body, -1, physicsClientId=client)
        self._inertial = (tuple(dyn[3]), tuple(dyn[4]))  # centre of mass in base_link
        self._to_base_link = p.invertTransform(*self._inertial)
        self._setup_joints()
        if as_built is not None and as_built.tyre_deflection > 0:
            self._soften_tyres(as_built.tyre_deflection)
        self._odom = ((pose.x, pose.y, 0.0), p.getQuaternionFromEuler((0.0, 0.0, pose.yaw)))
        self._odom_inverse = p.invertTransform(*self._odom)

    # ---- set-up ---------------------------------------------------------------------------
    def _soften_tyres(self, deflection: float) -> None:
        """Pneumatic tyres: each wheel's contact gives deflection [m] under its share of the robot's
        weight (a spring of that share over deflection, critically damped for the share's mass), so the
        weight spreads over every wheel as tyres spread it. The wheel still rolls on its radius. Every
        wheel on the ground: the drives' and the passive ones (a caster's wheel, not its swivel; rigid
        casters under a frame on soft drive tyres lifted one another as the frame rocked)."""
        c, body = self.client, self.body
        links = range(-1, p.getNumJoints(body, physicsClientId=c))
        passive = [self.joint_index[j.name] for j in self.description.passive_wheels if j.name in self.joint_index]
        wheels = [joint for joint, _, _ in self.wheels] + passive
        share = sum(p.getDynamicsInfo(body, link, physicsClientId=c)[0] for link in links) / len(wheels)  # [kg]
        stiffness = share * GRAVITY / deflection
        damping = 2.0 * math.sqrt(stiffness * share)
        for joint in wheels:
            p.changeDynamics(body, joint, contactStiffness=stiffness, contactDamping=damping, physicsClientId=c)

    def _setup_joints(self) -> None:
        c, body, d = self.client, self.body, self.description
        # pybullet gives every body a velocity damping of 0.04 /s, a drag no robot has. Damping belongs
        # to the multibody (its base): on a link, changeDynamics with linearDamping/angularDamping
        # silently drops the call's other settings, which left the wheels' friction at 0.5 (every
        # world's grip under a wheel halved) until the two were set apart
        p.changeDynamics(body, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=c)
        for link in range(-1, p.getNumJoints(body, physicsClientId=c)):
            p.changeDynamics(body, link, lateralFriction=LINK_FRICTION, physicsClientId=c)
        self.steering = []  # (joint index, effort, velocity limit) per drive; None for type 1
        self.wheels = []  # (joint index, effort, radius) per drive
        self.accelerations = [drive.max_acceleration for drive in d.drives]  # [m/s^2]
        self._target = [0.0] * len(d.drives)  # commanded rim speeds [m/s]
        self._speed = [0.0] * len(d.drives)  # the wheels' motor targets on their way there [m/s]
        for drive in d.drives:
            w = d.joints[drive.wheel_joint]
            self.wheels.append((self._index(drive.wheel_joint), w.effort, drive.wheel_radius))
            if drive.steerable:
                s = d.joints[drive.steering_joint]
                self.steering.append((self._index(drive.steering_joint), s.effort, s.velocity))
            else:
                self.steering.append(None)
        motors = [w[0] for w in self.wheels] + [s[0] for s in self.steering if s is not None]
        self.springs = [(self._index(s.joint), s) for s in d.springs if s.joint in self.joint_index]
        for j in motors + [j for j, _ in self.springs]:
            p.changeDynamics(body, j, jointDamping=0.0, physicsClientId=c)
        for j, _ in self.springs:
            p.setJointMotorControl2(body, j, p.VELOCITY_CONTROL, force=0.0, physicsClientId=c)
        self.passive = [(self._index(j.name), j) for j in d.passive_joints if j.name in self.joint_index]
        for j, info in self.passive:
            p.setJointMotorControl2(
                body, j, p.VELOCITY_CONTROL, targetVelocity=0.0, force=info.friction, physicsClientId=c
            )
        self.hold()

    def _index(self, joint: str) -> int:
        if joint not in self.joint_index:
            raise DescriptionError(f"joint {joint!r} is not a moving joint of the loaded robot")
        return self.joint_index[joint]

    # ---- commands -------------------------------------------------------------------------
    def command(
        self,
        steering: Sequence[float],
        speeds: Sequence[float],
        max_steering_speeds: Optional[Sequence[float]] = None,
    ) -> None:
        """Steering positions [rad] and wheel rim speeds [m/s], one per drive in drive order.

        Commands and states differ: a command (base_driver's drive_commands) carries the steering's
        speed limit per drive in max_steering_speeds [rad/s], and its wheel speeds are reached as a
        drive controller reaches them, ramping at the drive's max_acceleration. States to follow
        (base_state, without limits) slew and ramp within the drives' limits already: their wheel
        speeds apply at once, and the steering servo gets FOLLOW_HEADROOM times the joint's limit
        to catch up the stream's latency instead of trailing it through every slew.
        """
        n = len(self.wheels)
        if len(steering) != n or len(speeds) != n:
            raise ValueError(f"{self.name}: {n} drives, got {len(steering)} steering and {len(speeds)} speed values")
        c, body = self.client, self.body
        ramped = bool(max_steering_speeds)
        for k in range(n):
            self._target[k] = speeds[k]
            if not ramped or self.accelerations[k] <= 0:
                self._set_wheel(k, speeds[k])
            if self.steering[k] is None:
                continue
            joint, effort, limit = self.steering[k]
            if max_steering_speeds and max_steering_speeds[k] > 0:
                speed = max_steering_speeds[k]
            else:
                speed = FOLLOW_HEADROOM * limit
            p.setJointMotorControl2(
                body,
                joint,
                p.POSITION_CONTROL,
                targetPosition=steering[k] + self.built[k].steering_offset,
                force=effort,
                maxVelocity=speed if speed > 0 else 100.0,
                positionGain=STEERING_POSITION_GAIN,
                physicsClientId=c,
            )

    def _set_wheel(self, k: int, speed: float) -> None:
        wheel, effort, radius = self.wheels[k]
        self._speed[k] = speed
        p.setJointMotorControl2(
            self.body,
            wheel,
            p.VELOCITY_CONTROL,
            targetVelocity=speed / radius,
            force=effort,
            physicsClientId=self.client,
        )

    def before_step(self, dt: float) -> None:
        """Called before every physics step of dt [s]: wheels ramp towards commanded speeds, springs push."""
        for k, (target, now) in enumerate(zip(self._target, self._speed)):
            if target != now:
                step = self.accelerations[k] * dt
                self._set_wheel(k, target if abs(target - now) <= step else now + (step if target > now else -step))
        self.apply_springs()

    def hold(self) -> None:
        """Wheels stopped (their motors brake), steering held where it is."""
        states = self._joint_drive_states()
        self.command([s.steering - b.steering_offset for s, b in zip(states, self.built)], [0.0] * len(states))

    def apply_springs(self) -> None:
        """The suspension's spring and damper forces for the next step (called before every step)."""
        if not self.springs:
            return
        c, body = self.client, self.body
        joints = [j for j, _ in self.springs]
        states = p.getJointStates(body, joints, physicsClientId=c)
        forces = [-s.stiffness * (q[0] - s.reference) - s.damping * q[1] for (_, s), q in zip(self.springs, states)]
        p.setJointMotorControlArray(body, joints, p.TORQUE_CONTROL, forces=forces, physicsClientId=c)

    # ---- measurements -------------------------------------------------------------------------
    def drive_states(self, now: Optional[float] = None) -> List[MeasuredDrive]:
        """What each drive's encoders measure: steering angle and rate, wheel angle and rim speed (the
        configured radius times the wheel's turning rate, as the controller converts it). As built:
        through each drive's homing error and encoder counts, and, with a delay, the newest
        measurement taken at least that long before now [s] (simulated time). A silenced drive
        reports no number (NaN), as drive_states carries it."""
        if self.as_built is None:
            states = self._joint_drive_states()
        else:
            states = [
                MeasuredDrive(*b.measured(s.steering, s.speed, s.wheel_angle, s.steering_speed))
                for s, b in zip(self._joint_drive_states(), self.built)
            ]
            states = self._reported(self._history, now, states)
        if self.silenced:
            states = [NO_REPORT if k in self.silenced else s for k, s in enumerate(states)]
        return states

    def silence(self, drive: int, silent: bool = True) -> None:
        """Drive index drive's encoders stop reporting (silent) or report again: the fault a CAN
        controller that went quiet gives base_driver, while its motors still follow commands."""
        if not 0 <= drive < len(self.description.drives):
            raise IndexError(f"no drive {drive}: the robot has {len(self.description.drives)}")
        (self.silenced.add if silent else self.silenced.discard)(drive)

    def _reported(self, history: deque, now: Optional[float], measured):
        """As built with a delay: the newest of the measurements kept in history taken at least the delay
        before now [s] (measured is taken now); without one (or without now), measured."""
        if self.as_built is None or self.as_built.delay <= 0 or now is None:
            return measured
        history.append((now, measured))
        while len(history) > 1 and history[1][0] <= now - self.as_built.delay + 1e-9:  # 1 ns: rounding
            history.popleft()
        return history[0][1]

    def _joint_drive_states(self) -> List[MeasuredDrive]:
        """The drives' joints as they are (no encoder, no delay, no homing error)."""
        if self._drive_joints is None:  # every drive's wheel, then its steering if it steers: one call a reading
            self._drive_joints = [w for w, _, _ in self.wheels] + [s[0] for s in self.steering if s is not None]
        if not self._drive_joints:  # a passive model: pybullet reads no joints as None
            return []
        read = iter(p.getJointStates(self.body, self._drive_joints, physicsClientId=self.client))
        wheels = [next(read) for _ in self.wheels]
        out = []
        for (_, _, radius), steer, w in zip(self.wheels, self.steering, wheels):
            s = next(read) if steer is not None else (0.0, 0.0)
            out.append(MeasuredDrive(s[0], w[1] * radius, w[0], s[1]))
        return out

    def motor_torques(self) -> List[MotorLoad]:
        """What each drive's motors deliver at the last step: the wheel's torque [N m] and turning rate
        [rad/s] at the wheel, and the steering's about its axis (0 for a drive that does not steer):
        the joints' motor torques the solver applied (pybullet's applied joint motor torque), what a
        real drive's motor currents measure through its torque constant and gear."""
        if self._drive_joints is None:
            self._joint_drive_states()
        if not self._drive_joints:
            return []
        read = iter(p.getJointStates(self.body, self._drive_joints, physicsClientId=self.client))
        wheels = [next(read) for _ in self.wheels]
        out = []
        for steer, w in zip(self.steering, wheels):
            s = next(read) if steer is not None else (0.0, 0.0, None, 0.0)
            out.append(MotorLoad(w[3], w[1], s[3], s[1]))
        return out

    def drive_currents(self, now: Optional[float] = None) -> List[Tuple[float, float]]:
        """What each drive's motor controller measures of its motors: (propulsion, steering) winding
        currents [A], the joints' motor torques and rates (:meth:`motor_torques`) through the drive's
        motors and gears (:func:`thorvald_model.motors.winding_current`, with the description's motor
        constants, the robot file's). Positive when the torque turns the wheel forward, or to the
        left; 0 steering amps for a drive that does not steer. As built, reported with the drive
        states' delay (over the same controllers); the true radii change the torques, not the model."""
        currents = []
        for drive, load in zip(self.description.drives, self.motor_torques()):
            prop = winding_current(drive.propulsion_motor, load.wheel_torque, load.wheel_rate)
            steer = (
                winding_current(drive.steering_motor, load.steering_torque, load.steering_rate)
                if drive.steerable
                else 0.0
            )
            currents.append((prop, steer))
        return self._reported(self._current_history, now, currents)

    def wheel_loads(self) -> List[float]:
        """[N] the normal force the world puts on each drive's wheel at the last step (its contact
        points' sum; 0 for a wheel off the ground): how a rigid frame's weight is shared."""
        loads = []
        for joint, _, _ in self.wheels:
            contacts = p.getContactPoints(self.body, linkIndexA=joint, physicsClientId=self.client)
            loads.append(float(sum(cp[9] for cp in contacts)))
        return loads

    def joint_states(self, joints: Sequence[int]) -> List[Tuple[float, float]]:
        """(position, velocity) of the given joint indices."""
        return [tuple(s[:2]) for s in p.getJointStates(self.body, list(joints), physicsClientId=self.client)]

    def world_pose(self) -> Tuple[Vec3, Quat]:
        """base_link in the world."""
        com, orn = p.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        pos, quat = p.multiplyTransforms(com, orn, *self._to_base_link)
        return tuple(pos), tuple(quat)

    def frame_state(self) -> Tuple[Tuple[Vec3, Quat], Vec3, Vec3]:
        """base_link in the world, its origin's velocity and the angular velocity (world axes): the
        Gazebo API's model state, read with three calls."""
        c = self.client
        com, orn = p.getBasePositionAndOrientation(self.body, physicsClientId=c)
        pos, quat = p.multiplyTransforms(com, orn, *self._to_base_link)
        v, w = p.getBaseVelocity(self.body, physicsClientId=c)
        return (tuple(pos), tuple(quat)), point_velocity(v, w, com, pos), tuple(w)

    def odom_pose(self) -> Tuple[Vec3, Quat]:
        """base_link in the robot's odom frame, which is the spawn pose on the ground."""
        pos, quat = p.multiplyTransforms(*self._odom_inverse, *self.world_pose())
        return tuple(pos), tuple(quat)

    def body_twist(self) -> Tuple[Vec3, Vec3]:
        """base_link's linear [m/s] and angular [rad/s] velocity, in base_link."""
        c = self.client
        com, orn = p.getBasePositionAndOrientation(self.body, physicsClientId=c)
        v, w = p.getBaseVelocity(self.body, physicsClientId=c)
        origin, _ = p.multiplyTransforms(com, orn, *self._to_base_link)
        v_origin = point_velocity(v, w, com, origin)
        inverse = p.invertTransform((0.0, 0.0, 0.0), orn)
        lin, _ = p.multiplyTransforms(*inverse, v_origin, (0.0, 0.0, 0.0, 1.0))
        ang, _ = p.multiplyTransforms(*inverse, w, (0.0, 0.0, 0.0, 1.0))
        return tuple(lin), tuple(ang)

    def link_state(self, index: int) -> Tuple[Vec3, Quat, Vec3, Vec3, Vec3]:
        """A loaded link's frame in the world, its centre of mass and velocities: (frame position,
        frame orientation, centre of mass [m], linear velocity of the centre of mass [m/s], angular
        velocity [rad/s]), all in world axes. index -1 is the base (base_link and every link merged
        into it)."""
        c = self.client
        if index < 0:
            com, orn = p.getBasePositionAndOrientation(self.body, physicsClientId=c)
            v, w = p.getBaseVelocity(self.body, physicsClientId=c)
            pos, quat = p.multiplyTransforms(com, orn, *self._to_base_link)
            return tuple(pos), tuple(quat), tuple(com), tuple(v), tuple(w)
        state = p.getLinkState(self.body, index, computeLinkVelocity=1, computeForwardKinematics=1, physicsClientId=c)
        return tuple(state[4]), tuple(state[5]), tuple(state[0]), tuple(state[6]), tuple(state[7])

    # ---- life -------------------------------------------------------------------------------
    def reset(self) -> None:
        """Back to the spawn pose, at rest, joints at 0, wheels stopped."""
        c, pose = self.client, self.spawn_pose
        link = ((pose.x, pose.y, pose.z), pose.quaternion)
        com, orn = p.multiplyTransforms(*link, *self._inertial)
        p.resetBasePositionAndOrientation(self.body, com, orn, physicsClientId=c)
        p.resetBaseVelocity(self.body, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), physicsClientId=c)
        for j in self.joint_index.values():
            p.resetJointState(self.body, j, 0.0, 0.0, physicsClientId=c)
        self._history.clear()
        self._current_history.clear()
        self.hold()

    def remove(self) -> None:
        p.removeBody(self.body, physicsClientId=self.client)


def yaw_of(quat: Quat) -> float:
    x, y, z, w = quat
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
