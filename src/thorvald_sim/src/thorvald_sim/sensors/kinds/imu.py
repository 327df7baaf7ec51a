"""The IMU: ``imu`` (sensor_msgs/Imu), from a Gazebo ``imu`` sensor with gazebo_ros_imu_sensor or the
model plugin gazebo_ros_imu (of the link ``bodyName``)."""

from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from .block import (
    FRAME_AS_IS,
    NON_NEGATIVE,
    Element,
    Found,
    Pose,
    SensorSpec,
    Vec3,
    read_namespace,
    read_pose,
    read_rate,
    unpack,
)
from .kind import SensorKind, no_display
from .model import Quat, Sensor, p, unrotate

IMU_SENSOR_PLUGINS = ("libgazebo_ros_imu_sensor.so",)
MODEL_IMU_PLUGINS = ("libgazebo_ros_imu.so",)


@dataclass(frozen=True)
class ImuConfig:
    noise: float = 0.0  # gaussianNoise: the stddev added to every component (as gazebo_ros's plugins)
    rpy_offset: Vec3 = (0.0, 0.0, 0.0)  # [rad] applied to the orientation


def _imu_sensor(found: Found) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = unpack(found)
    plugin.required("frameName", "gazebo_ros_imu_sensor needs it (it refuses to load)")
    # the plugin's own updateRateHZ (default 1 Hz) paces the messages, within the sensor's update_rate
    plugin_rate = read_rate(plugin, "updateRateHZ", 1.0)
    effective = min(r for r in (plugin_rate, rate) if r > 0) if (plugin_rate > 0 or rate > 0) else 0.0
    config = ImuConfig(
        plugin.number("gaussianNoise", 0.0, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1]), plugin.vector("rpyOffset")
    )
    return SensorSpec(
        "imu", name, link, read_pose(sensor), effective, filename, {"imu": plugin.text("topicName", "imu_data")},
        plugin.text("frameName"), FRAME_AS_IS, read_namespace(plugin), config,
    )  # fmt: skip


def _model_imu(plugin: Element, root_link: str, filename: str, name: str) -> SensorSpec:
    plugin.required("bodyName", "gazebo_ros_imu needs the link to measure")
    body = plugin.text("bodyName")
    plugin.required("topicName", "gazebo_ros_imu needs it")
    rate = read_rate(plugin, "updateRate", 0.0) if plugin.has("updateRate") else read_rate(plugin, "update_rate", 0.0)
    config = ImuConfig(
        plugin.number("gaussianNoise", 0.0, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1]), plugin.vector("rpyOffset")
    )
    return SensorSpec(
        "imu", name, body, Pose(plugin.vector("xyzOffset")), rate, filename, {"imu": plugin.text("topicName")},
        plugin.text("frameName", body), FRAME_AS_IS, read_namespace(plugin), config,
    )  # fmt: skip


@dataclass(frozen=True)
class ImuReading:
    orientation: Quat  # x, y, z, w: the sensor frame in the world
    angular_velocity: Vec3  # [rad/s] sensor axes
    linear_acceleration: Vec3  # [m/s^2] sensor axes, proper acceleration (gravity included)
    noise: float


class Imu(Sensor):
    """Reads the mount's orientation in the world (its ``rpyOffset`` applied), its angular velocity and
    its proper acceleration (the mean acceleration since the last reading, minus the world's gravity:
    +9.81 m/s^2 up at rest, and whatever set_physics_properties made it), in the sensor's axes;
    gaussianNoise on every component."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.gravity = np.array([0.0, 0.0, -self.context.gravity])  # [m/s^2] world axes
        self.last: Optional[Tuple[float, np.ndarray]] = None  # (time, velocity) of the last reading
        self.offset_rotation = p.getQuaternionFromEuler(self.spec.config.rpy_offset)

    def world_gravity(self, gravity) -> None:
        self.gravity = np.array(gravity, dtype=float)

    def read(self, now: float) -> ImuReading:
        c: ImuConfig = self.spec.config
        (_, quat), v, w = self.kinematics()
        if self.last is not None and now - self.last[0] > 1e-9 and now - self.last[0] < 1.0:
            a = (v - self.last[1]) / (now - self.last[0])
        else:
            a = np.zeros(3)
        self.last = (now, v)
        proper = a - self.gravity
        acc = unrotate(quat, proper)
        gyro = unrotate(quat, w)
        _, orientation = p.multiplyTransforms((0, 0, 0), self.offset_rotation, (0, 0, 0), quat)
        if c.noise > 0:
            acc = acc + self.rng.normal(0.0, c.noise, 3)
            gyro = gyro + self.rng.normal(0.0, c.noise, 3)
            q = np.asarray(orientation) + self.rng.normal(0.0, c.noise, 4)
            orientation = tuple(q / np.linalg.norm(q))
        return ImuReading(tuple(orientation), tuple(gyro), tuple(acc), c.noise)


def imu_messages(out, r: ImuReading, wanted):
    msg = out.message("imu")
    msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = r.orientation
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = r.angular_velocity
    msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = r.linear_acceleration
    n2 = r.noise * r.noise
    diagonal = [n2, 0.0, 0.0, 0.0, n2, 0.0, 0.0, 0.0, n2]
    msg.orientation_covariance = diagonal
    msg.angular_velocity_covariance = diagonal
    msg.linear_acceleration_covariance = diagonal
    yield "imu", msg


IMU = SensorKind(
    "imu",
    blocks="`imu` + `libgazebo_ros_imu_sensor.so`; model plugin `libgazebo_ros_imu.so`",
    published="`sensor_msgs/Imu`: orientation in the world, angular velocity, proper acceleration (+9.81 m/s² up "
    "at rest)",
    model=Imu,
    roles={"imu": "sensor_msgs/Imu"},
    messages=imu_messages,
    displays=no_display,
    sensors=(("imu", IMU_SENSOR_PLUGINS),),
    read_sensor=_imu_sensor,
    model_plugins=MODEL_IMU_PLUGINS,
    read_model_plugin=_model_imu,
    example="""<gazebo reference="sensor_link"><sensor type="imu" name="imu"><update_rate>100</update_rate>
<plugin name="imu" filename="libgazebo_ros_imu_sensor.so"><topicName>imu/data</topicName>
<updateRateHZ>100</updateRateHZ><frameName>sensor_link</frameName><gaussianNoise>0.002</gaussianNoise></plugin></sensor></gazebo>""",
)
