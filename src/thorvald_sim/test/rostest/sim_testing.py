"""Shared helpers of the simulator's rostests (imported by the rostest_*.py test nodes beside it).

Everything runs on simulated time (/use_sim_time, the simulator's /clock): a test waits for the
simulator's time to pass, never for a number of wall seconds. Wall-clock deadlines only bound how
long a test may take on a busy machine.
"""

import math
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from thorvald_base.conversions import quaternion_yaw
from thorvald_testing import topics

STARTUP = 120.0  # [s] wall, for the simulator, the robots' nodes and their spawns on a busy machine
WALL_LIMIT = 120.0  # [s] wall, for a test's simulated wait


def planar(odom):
    """(x, y, yaw) of an Odometry's pose."""
    p = odom.pose.pose
    return p.position.x, p.position.y, quaternion_yaw(p.orientation)


def delta(start, end):
    """The motion from pose start to pose end, (x, y, yaw) each: its length [m], its direction in
    start's heading [rad], and the turn [rad]. Comparable between frames that differ by a rigid move."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    direction = math.atan2(dy, dx) - start[2]
    turn = math.remainder(end[2] - start[2], 2 * math.pi)
    return math.hypot(dx, dy), math.remainder(direction, 2 * math.pi), turn


class Latest(topics.Latest):
    """thorvald_testing's Latest, of Odometry unless told, waiting STARTUP by default."""

    def __init__(self, topic, msg_type=Odometry):
        super().__init__(topic, msg_type)

    def wait(self, timeout=STARTUP):
        return super().wait(timeout)


def sim_sleep(seconds):
    """Waits for seconds of simulated time, within a wall-clock limit."""
    end = rospy.get_time() + seconds
    deadline = time.time() + WALL_LIMIT
    while rospy.get_time() < end:
        if time.time() > deadline or rospy.is_shutdown():
            raise AssertionError(f"simulated time stalled at {rospy.get_time():.2f} s (waiting for {end:.2f} s)")
        time.sleep(0.005)


class Commander:
    """Streams a Twist on a topic at 20 Hz of simulated time, as a navigation stack would."""

    def __init__(self, topic):
        self.pub = rospy.Publisher(topic, Twist, queue_size=1)
        self._twist = None
        self._lock = threading.Lock()
        threading.Thread(target=self._run, daemon=True).start()

    def _run(self):
        last = None
        while not rospy.is_shutdown():
            now = rospy.get_time()
            with self._lock:
                twist = self._twist
            if twist is not None and (last is None or now - last >= 0.05 or now < last):
                self.pub.publish(twist)
                last = now
            time.sleep(0.002)

    def send(self, vx=0.0, vy=0.0, wz=0.0):
        t = Twist()
        t.linear.x, t.linear.y, t.angular.z = vx, vy, wz
        with self._lock:
            self._twist = t

    def stop(self):
        """Zero, then silence."""
        self.send()
        sim_sleep(0.2)
        with self._lock:
            self._twist = None

    def wait_for_subscriber(self, timeout=STARTUP):
        deadline = time.time() + timeout
        while time.time() < deadline and self.pub.get_num_connections() == 0:
            time.sleep(0.05)
        assert self.pub.get_num_connections() > 0, f"nobody subscribes to {self.pub.resolved_name}"


def drive(commander, twist, seconds, truth, odometry, *, settle=1.0):
    """Commands twist for seconds, then zero until the robot settles; returns the ground-truth and the
    odometry motion (length, direction, turn) from just before to after."""
    truth0, odom0 = planar(truth.get()), planar(odometry.get())
    commander.send(*twist)
    sim_sleep(seconds)
    commander.send()
    sim_sleep(settle)
    return delta(truth0, planar(truth.get())), delta(odom0, planar(odometry.get()))
