"""The GNSS: ``gps`` (sensor_msgs/NavSatFix, and hector's geometry_msgs/Vector3Stamped velocity),
from the model plugin hector_gazebo_ros_gps or a Gazebo ``gps`` sensor with gazebo_ros_gps_sensor."""

import math
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from thorvald_model.datum import Datum, earth_radii

from ...errors import BlockError
from .block import (
    FRAME_AS_IS,
    FRAME_TF_RESOLVE,
    Element,
    Found,
    Pose,
    SensorSpec,
    Vec3,
    read_namespace,
    read_noise,
    read_pose,
    read_rate,
    unpack,
)
from .kind import SensorKind, no_display
from .model import Sensor

GPS_SENSOR_PLUGINS = ("libgazebo_ros_gps_sensor.so",)
MODEL_GPS_PLUGINS = ("libhector_gazebo_ros_gps.so",)
# hector_gazebo_ros_gps's defaults (its source): a reference in Germany, x pointing north
HECTOR_REFERENCE = (49.9, 8.9, 0.0, 0.0)  # latitude [deg], longitude [deg], heading [deg], altitude [m]
HECTOR_RATE = 4.0  # [Hz]
HECTOR_DRIFT_FREQUENCY = 1.0 / 3600.0  # [1/s]: SensorModel's default time constant of an hour


@dataclass(frozen=True)
class ErrorModel:
    """hector_gazebo_plugins' SensorModel per axis: offset, a drift (a first-order Gauss-Markov process
    of standard deviation ``drift`` and frequency ``drift_frequency``) and white gaussian noise."""

    offset: Vec3 = (0.0, 0.0, 0.0)
    drift: Vec3 = (0.0, 0.0, 0.0)
    drift_frequency: Vec3 = (HECTOR_DRIFT_FREQUENCY,) * 3
    gaussian_noise: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class GpsConfig:
    reference: Optional[Tuple[float, float, float, float]]  # (lat, lon, heading [deg], alt [m]); None: the datum's
    position: ErrorModel = ErrorModel()
    velocity: ErrorModel = ErrorModel()
    status: int = 0  # sensor_msgs/NavSatStatus STATUS_FIX
    service: int = 0  # hector's default (the gps sensor: SERVICE_GPS)
    hector: bool = True  # hector's axes and velocity topic; False: gazebo_ros_gps_sensor (no velocity)


def _gps_sensor(found: Found) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = unpack(found)
    noise = 0.0
    gps = sensor.child("gps")
    if gps is not None:
        horizontal = gps.child("position_sensing/horizontal")
        if horizontal is not None:
            noise = read_noise(horizontal)[1]
    model = ErrorModel(gaussian_noise=(noise, noise, noise))
    config = GpsConfig(None, model, ErrorModel(), status=0, service=1, hector=False)
    return SensorSpec(
        "gps", name, link, read_pose(sensor), rate, filename, {"fix": plugin.text("topicName", "gps/fix")},
        plugin.text("frameName", link), FRAME_TF_RESOLVE, read_namespace(plugin), config,
    )  # fmt: skip


def _error_model(plugin: Element, prefix: str) -> ErrorModel:
    def named(key: str) -> str:
        return prefix + key[0].upper() + key[1:] if prefix else key

    for key in ("drift", "driftFrequency", "gaussianNoise"):
        vec = plugin.vector(named(key))
        if any(v < 0 for v in vec):
            raise BlockError(f"{plugin.path}/{named(key)}", f"{vec!r} must be >= 0")
    return ErrorModel(
        plugin.vector(named("offset")),
        plugin.vector(named("drift")),
        plugin.vector(named("driftFrequency"), (HECTOR_DRIFT_FREQUENCY,) * 3),
        plugin.vector(named("gaussianNoise")),
    )


def _hector_gps(plugin: Element, root_link: str, filename: str, name: str) -> SensorSpec:
    given = [
        plugin.has(k) for k in ("referenceLatitude", "referenceLongitude", "referenceHeading", "referenceAltitude")
    ]
    reference = None
    if any(given):
        reference = (
            plugin.number("referenceLatitude", HECTOR_REFERENCE[0], rule="must be in [-90, 90]",
                          check=lambda v: -90 <= v <= 90),
            plugin.number("referenceLongitude", HECTOR_REFERENCE[1]),
            plugin.number("referenceHeading", HECTOR_REFERENCE[2]),
            plugin.number("referenceAltitude", HECTOR_REFERENCE[3]),
        )  # fmt: skip
    config = GpsConfig(
        reference,
        _error_model(plugin, ""),
        _error_model(plugin, "velocity"),
        status=int(plugin.number("status", 0.0)),
        service=int(plugin.number("service", 0.0)),
        hector=True,
    )
    body = plugin.text("bodyName", root_link) or root_link
    topics = {"fix": plugin.text("topicName", "fix"), "velocity": plugin.text("velocityTopicName", "fix_velocity")}
    return SensorSpec(
        "gps", name, body, Pose(), read_rate(plugin, "updateRate", HECTOR_RATE), filename, topics,
        plugin.text("frameId", "/world"), FRAME_AS_IS, read_namespace(plugin), config,
    )  # fmt: skip


def gps_reference(spec: SensorSpec, datum: Optional[Datum]) -> Tuple[float, float, float, float]:
    """(lat, lon, heading [deg], alt) of a GNSS: its own, else the datum's, else hector's default."""
    config = spec.config
    if config.reference is not None:
        return config.reference
    return datum.reference if datum is not None else HECTOR_REFERENCE


@dataclass(frozen=True)
class GnssReading:
    latitude: float  # [deg]
    longitude: float  # [deg]
    altitude: float  # [m]
    velocity: Vec3  # [m/s] in hector's axes (x the reference heading, y left of it, z up)
    covariance: Vec3  # diagonal [m^2]: drift^2 + noise^2 per axis (hector's)


class _ErrorProcess:
    """hector's SensorModel on three axes: value + offset + drift (Gauss-Markov) + white noise."""

    def __init__(self, model, rng: np.random.Generator):
        self.model = model
        self.rng = rng
        self.drift = np.zeros(3)

    def __call__(self, value: np.ndarray, dt: float) -> np.ndarray:
        m = self.model
        sigma, freq = np.asarray(m.drift), np.asarray(m.drift_frequency)
        if dt > 0 and np.any(sigma > 0):
            decay = np.exp(-dt * freq)
            self.drift = decay * self.drift + sigma * np.sqrt(1.0 - decay * decay) * self.rng.standard_normal(3)
        noise = np.asarray(m.gaussian_noise)
        white = noise * self.rng.standard_normal(3) if np.any(noise > 0) else 0.0
        return value + np.asarray(m.offset) + self.drift + white


class Gnss(Sensor):
    """Reads the mount's position and velocity in the world through hector's error model (an offset, a
    Gauss-Markov drift and white noise per axis) and converts them with hector's convention: world x
    is the reference heading's direction (compass, 0 = north), y 90 degrees to its left, latitude and
    longitude from the WGS84 radii at the reference latitude."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        c: GpsConfig = self.spec.config
        self.reference = gps_reference(self.spec, self.context.datum)
        self.radius_north, self.radius_east = earth_radii(self.reference[0])
        self.position_error = _ErrorProcess(c.position, self.rng)
        self.velocity_error = _ErrorProcess(c.velocity, self.rng)
        self.last_time: Optional[float] = None

    def read(self, now: float) -> GnssReading:
        c: GpsConfig = self.spec.config
        (pos, _), v, _ = self.kinematics()
        dt = 0.0 if self.last_time is None else now - self.last_time
        self.last_time = now
        velocity = self.velocity_error(v, dt)
        # hector: a velocity drift integrates into the position's drift
        self.position_error.drift = self.position_error.drift + dt * self.velocity_error.drift
        position = self.position_error(np.asarray(pos), dt)
        lat0, lon0, heading_deg, alt0 = self.reference
        h = math.radians(heading_deg)
        x, y, z = position
        latitude = lat0 + (math.cos(h) * x + math.sin(h) * y) / self.radius_north * 180.0 / math.pi
        longitude = lon0 - (-math.sin(h) * x + math.cos(h) * y) / self.radius_east * 180.0 / math.pi
        vel = (
            math.cos(h) * velocity[0] + math.sin(h) * velocity[1],
            -math.sin(h) * velocity[0] + math.cos(h) * velocity[1],
            float(velocity[2]),
        )
        covariance = tuple(float(d * d + n * n) for d, n in zip(c.position.drift, c.position.gaussian_noise))
        return GnssReading(latitude, longitude, alt0 + z, vel, covariance)


def gps_messages(out, r: GnssReading, wanted):
    c: GpsConfig = out.spec.config
    fix = out.message("fix")
    fix.status.status, fix.status.service = c.status, c.service
    fix.latitude, fix.longitude, fix.altitude = r.latitude, r.longitude, r.altitude
    fix.position_covariance = [r.covariance[0], 0.0, 0.0, 0.0, r.covariance[1], 0.0, 0.0, 0.0, r.covariance[2]]
    fix.position_covariance_type = type(fix).COVARIANCE_TYPE_DIAGONAL_KNOWN
    yield "fix", fix
    if out.publishes("velocity"):
        velocity = out.message("velocity")
        velocity.vector.x, velocity.vector.y, velocity.vector.z = r.velocity
        yield "velocity", velocity


GPS = SensorKind(
    "gps",
    blocks="model plugin `libhector_gazebo_ros_gps.so`; `gps` + `libgazebo_ros_gps_sensor.so`",
    published="`sensor_msgs/NavSatFix` (`fix`), hector's `geometry_msgs/Vector3Stamped` velocity (`fix_velocity`); "
    "hector's error model (offset, drift, driftFrequency, gaussianNoise)",
    model=Gnss,
    roles={"fix": "sensor_msgs/NavSatFix", "velocity": "geometry_msgs/Vector3Stamped"},
    messages=gps_messages,
    displays=no_display,
    sensors=(("gps", GPS_SENSOR_PLUGINS),),
    read_sensor=_gps_sensor,
    model_plugins=MODEL_GPS_PLUGINS,
    read_model_plugin=_hector_gps,
    example="""<gazebo><plugin name="gnss" filename="libhector_gazebo_ros_gps.so"><updateRate>10</updateRate>
<bodyName>sensor_link</bodyName><frameId>sensor_link</frameId><topicName>fix</topicName>
<velocityTopicName>fix_velocity</velocityTopicName><gaussianNoise>0.02</gaussianNoise><status>2</status>
</plugin></gazebo>""",
)
