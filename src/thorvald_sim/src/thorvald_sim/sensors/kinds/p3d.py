"""Ground truth of a link: ``p3d`` (nav_msgs/Odometry), from the model plugin gazebo_ros_p3d."""

from dataclasses import dataclass
from typing import Optional

import numpy as np

from .block import FRAME_TF_RESOLVE, NON_NEGATIVE, Element, Pose, SensorSpec, Vec3, read_namespace, read_rate
from .kind import SensorKind, no_display
from .model import Quat, Sensor, p, unrotate

MODEL_P3D_PLUGINS = ("libgazebo_ros_p3d.so",)


@dataclass(frozen=True)
class P3dConfig:
    reference_frame: str  # "world" or a link of the robot
    xyz_offsets: Vec3 = (0.0, 0.0, 0.0)
    rpy_offsets: Vec3 = (0.0, 0.0, 0.0)
    noise: float = 0.0


def _p3d(plugin: Element, root_link: str, filename: str, name: str) -> SensorSpec:
    plugin.required("bodyName", "gazebo_ros_p3d needs the link to report")
    plugin.required("topicName", "gazebo_ros_p3d needs it")
    body = plugin.text("bodyName")
    frame = plugin.text("frameName", "world")
    reference = "world" if frame.strip("/") in ("world", "map", "") else frame.strip("/")
    config = P3dConfig(
        reference,
        plugin.vector("xyzOffsets"),
        plugin.vector("rpyOffsets"),
        plugin.number("gaussianNoise", 0.0, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1]),
    )
    return SensorSpec(
        "p3d", name, body, Pose(), read_rate(plugin, "updateRate", 0.0), filename,
        {"odometry": plugin.text("topicName")}, frame, FRAME_TF_RESOLVE, read_namespace(plugin), config,
        child_frame=body,
    )  # fmt: skip


@dataclass(frozen=True)
class LinkTruth:
    position: Vec3
    orientation: Quat
    linear: Vec3  # [m/s] in the reference frame's axes
    angular: Vec3  # [rad/s]
    noise: float


class P3d(Sensor):
    """Reports a link's pose and twist in the world, or in another link of the robot (MountError if
    the robot has no such link), with its offsets."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        c: P3dConfig = self.spec.config
        self.reference: Optional[Sensor] = None  # the reference link's mount; None: the world
        if c.reference_frame != "world":
            mount = self.context.mount(c.reference_frame)
            self.reference = Sensor(self.spec, self.robot, mount, self.noise, self.dt, context=self.context)
        self.offset_rotation = p.getQuaternionFromEuler(c.rpy_offsets)

    def read(self, now: float) -> LinkTruth:
        c: P3dConfig = self.spec.config
        (pos, quat), v, w = self.kinematics()
        if self.reference is not None:
            (rpos, rquat), rv, rw = self.reference.kinematics()
            relative = np.asarray(pos) - np.asarray(rpos)
            v = unrotate(rquat, v - rv - np.cross(rw, relative))
            w = unrotate(rquat, w - rw)
            inv = p.invertTransform(rpos, rquat)
            pos, quat = p.multiplyTransforms(*inv, pos, quat)
        position = np.asarray(pos) + np.asarray(c.xyz_offsets)
        _, orientation = p.multiplyTransforms((0, 0, 0), self.offset_rotation, (0, 0, 0), quat)
        if c.noise > 0:
            position = position + self.rng.normal(0.0, c.noise, 3)
            v = v + self.rng.normal(0.0, c.noise, 3)
            w = w + self.rng.normal(0.0, c.noise, 3)
        return LinkTruth(tuple(position), tuple(orientation), tuple(v), tuple(w), c.noise)


def p3d_messages(out, t: LinkTruth, wanted):
    msg = out.message("odometry")
    msg.child_frame_id = out.spec.child_frame
    pose, twist = msg.pose.pose, msg.twist.twist
    pose.position.x, pose.position.y, pose.position.z = t.position
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = t.orientation
    twist.linear.x, twist.linear.y, twist.linear.z = t.linear
    twist.angular.x, twist.angular.y, twist.angular.z = t.angular
    n2 = t.noise * t.noise
    covariance = [0.0] * 36
    for k in range(6):
        covariance[7 * k] = n2
    msg.pose.covariance = covariance
    msg.twist.covariance = list(covariance)
    yield "odometry", msg


P3D = SensorKind(
    "p3d",
    blocks="model plugin `libgazebo_ros_p3d.so`",
    published="`nav_msgs/Odometry` of `bodyName` in `frameName` (world)",
    model=P3d,
    roles={"odometry": "nav_msgs/Odometry"},
    messages=p3d_messages,
    displays=no_display,
    model_plugins=MODEL_P3D_PLUGINS,
    read_model_plugin=_p3d,
    example="""<gazebo><plugin name="truth" filename="libgazebo_ros_p3d.so"><updateRate>50</updateRate>
<bodyName>sensor_link</bodyName><topicName>ground_truth</topicName><frameName>world</frameName></plugin></gazebo>""",
)
