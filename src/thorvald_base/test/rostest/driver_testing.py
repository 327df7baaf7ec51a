"""Shared helpers of the base_driver rostests (imported by the rostest_*.py test nodes beside it).

The tests run on a machine shared with other work, so nothing here sleeps for a fixed time to let
something happen: :meth:`Topic.wait_for` polls until a deadline, and every deadline is generous.
Expected values come from the robot's geometry on the parameter server (the YAML the launch file
loaded), never from the code under test.
"""

import math
import threading
import time

import rospy
import yaml
from geometry_msgs.msg import Twist

from thorvald_base.conversions import quaternion_yaw

STARTUP_TIMEOUT = 40.0  # [s] for nodes to come up while the machine is busy
WAIT = 5.0  # [s] default deadline for something that normally takes a few cycles
STREAM_HZ = 20.0  # [Hz] command stream: well inside base_driver's 0.5 s command timeout
TOL = 1e-6  # commands are computed in floating point from the same geometry


def twist(vx=0.0, vy=0.0, wz=0.0):
    msg = Twist()
    msg.linear.x, msg.linear.y, msg.angular.z = vx, vy, wz
    return msg


class Topic:
    """Records every message of a topic with its wall-clock receive time [s]."""

    def __init__(self, name, msg_type, queue_size=200):
        self.name = name
        self._lock = threading.Lock()
        self._messages = []
        self.sub = rospy.Subscriber(name, msg_type, self._on_message, queue_size=queue_size)

    def _on_message(self, msg):
        with self._lock:
            self._messages.append((time.time(), msg))

    def since(self, wall_time):
        """Messages received after wall_time [s], oldest first."""
        with self._lock:
            return [m for t, m in self._messages if t > wall_time]

    def all(self):
        with self._lock:
            return [m for _, m in self._messages]

    def latest(self):
        with self._lock:
            return self._messages[-1][1] if self._messages else None

    def wait_for(self, predicate=lambda m: True, timeout=WAIT, since=None):
        """The first message received after since (default: now) that satisfies predicate, or None."""
        start = time.time() if since is None else since
        deadline = time.time() + timeout
        checked = 0
        while True:
            with self._lock:
                fresh = [(t, m) for t, m in self._messages[checked:]]
                checked = len(self._messages)
            for t, m in fresh:
                if t > start and predicate(m):
                    return m
            if time.time() > deadline:
                return None
            time.sleep(0.01)


class CommandStream:
    """Publishes one Twist repeatedly from a thread, as a teleop or navigation node would."""

    def __init__(self, topic, hz=STREAM_HZ):
        self.pub = rospy.Publisher(topic, Twist, queue_size=10)
        self.period = 1.0 / hz
        self._msg = None
        self._lock = threading.Lock()
        self.last_publish = None  # wall time [s] of the latest publication
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self):
        while not rospy.is_shutdown():
            with self._lock:
                if self._msg is not None:
                    self.last_publish = time.time()
                    self.pub.publish(self._msg)
            time.sleep(self.period)

    def send(self, msg):
        """Streams msg from now on (and publishes it at once)."""
        with self._lock:
            self._msg = msg
            self.last_publish = time.time()
            self.pub.publish(msg)

    def stop(self):
        """Stops streaming; returns the wall time [s] just before the last message was published.

        Before, not after: the node may receive and stamp a message before publish() returns here
        (one CI run stamped a command 44 us before the time taken after publishing it)."""
        with self._lock:
            self._msg = None
            return self.last_publish

    def wait_for_subscriber(self, timeout=STARTUP_TIMEOUT):
        deadline = time.time() + timeout
        while time.time() < deadline and not self.pub.get_num_connections():
            time.sleep(0.05)
        return self.pub.get_num_connections() > 0


def driver_stream(first):
    """The command stream into base_driver (twist_mux/cmd_vel), once base_driver subscribes to it and
    has published on first (a Topic)."""
    cmd = CommandStream("twist_mux/cmd_vel")
    assert cmd.wait_for_subscriber(), "base_driver did not subscribe to twist_mux/cmd_vel"
    assert first.wait_for(timeout=STARTUP_TIMEOUT, since=0), f"no {first.name} from base_driver"
    return cmd


def driver_service(name, srv_type):
    """A proxy of base_driver's service name, once it is advertised."""
    rospy.wait_for_service("base_driver/" + name, timeout=STARTUP_TIMEOUT)
    return rospy.ServiceProxy("base_driver/" + name, srv_type)


def drives_from_params(driver="base_driver"):
    """The drive dicts of the robot file the driver was started with (its ~robot_model, which the
    launch file sets before any node runs), in drive-index order, read here with plain YAML."""
    with open(rospy.get_param(driver + "/robot_model")) as f:
        drives = yaml.safe_load(f)["motor_drives"]
    names = sorted(drives, key=lambda n: int(n[len("drive") :]))
    return [drives[n] for n in names]


def contact_velocity(drive, vx, vy, wz):
    """Velocity [m/s] of the drive's contact point (x, y) on a rigid body moving with the twist."""
    return vx - wz * drive["y"], vy + wz * drive["x"]


def expected_commands(drives, vx, vy, wz):
    """[(steering [rad], rim speed [m/s])] for every drive: each wheel rolls along its point's velocity.

    Valid while no wheel needs more than 90 degrees of steering (no 180-degree inversion).
    """
    out = []
    for d in drives:
        ux, uy = contact_velocity(d, vx, vy, wz)
        out.append((math.atan2(uy, ux), math.hypot(ux, uy)))
    return out


def max_wheel_speed(drive):
    """Highest rim speed [m/s]: prp_max_rpm motor turns per minute through gear prp_gr_rt on r_wheel."""
    return drive["prp_max_rpm"] / drive["prp_gr_rt"] * 2.0 * math.pi / 60.0 * drive["r_wheel"]


def commands_are(msg, expected, tol=TOL):
    """Whether a joint_commands BaseState carries the expected [(steering, speed)]."""
    if msg is None or len(msg.prop_speed) != len(expected) or len(msg.steer_pos) != len(expected):
        return False
    return all(
        abs(s - es) <= tol and abs(v - ev) <= tol for s, v, (es, ev) in zip(msg.steer_pos, msg.prop_speed, expected)
    )


def speeds_are(msg, speed, tol=TOL):
    return msg is not None and len(msg.prop_speed) > 0 and all(abs(v - speed) <= tol for v in msg.prop_speed)


def yaw_of(pose):
    return quaternion_yaw(pose.orientation)


def describe(msg):
    """A short text of a BaseState for assertion messages."""
    if msg is None:
        return "no message"
    return f"steer_pos {[round(v, 4) for v in msg.steer_pos]} prop_speed {[round(v, 4) for v in msg.prop_speed]}"
