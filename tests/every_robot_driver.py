#!/usr/bin/env python3
"""Drives robots already spawned in the simulator through a short pattern and prints, as JSON, each
leg's motion by odometry (``/<robot>/odometry/base_raw``) and by ground truth (``odometry/gazebo``).

    python3 tests/every_robot_driver.py NAME=CONFIG.yaml [NAME=CONFIG.yaml ...]

Run by tests/test_every_robot_in_simulator.py in a process of its own (rospy initialises a node once
per process, and pytest runs other tests in its own), on the ROS master of ``ROS_MASTER_URI`` where
simulator.launch and robot.launch per robot (namespace NAME) are coming up. Everything runs on
simulated time, the simulator's ``/clock``: wall-clock deadlines only bound how long it may take.

The pattern (``plan_for``), driven by all robots at once, in each robot's base_link:

- ``forward``: vx 0.5 m/s for 3 s;
- ``turn``: 0.5 rad/s for 3 s about the point of the robot's fixed axle line nearest to base_link
  (its origin when no wheel is fixed: a spin in place), a twist every layout realises;
- ``crab``: vx = vy = 0.35 m/s for 3 s, 45 degrees to the left, for robots without a fixed axle.

Each leg ends with zero commands for PAUSE s (the robot stops, the wheels re-steer), and is measured
from the poses before it to those after the pause: length, direction in the start pose's heading,
and turn. Whether a robot has a fixed axle comes from its configuration through the one loader and
``thorvald_model.layout.common_axle``, as base_driver's verification plan decides it.
"""

import json
import math
import sys
import threading
import time
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import rosgraph
import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from thorvald_base.conversions import quaternion_yaw
from thorvald_model import load_robot_config
from thorvald_model.layout import common_axle
from thorvald_testing.topics import Latest

SPEED = 0.5  # [m/s] forward
TURN_RATE = 0.5  # [rad/s]
CRAB = 0.35  # [m/s] each of vx and vy
LEG = 3.0  # [s] simulated, each leg
PAUSE = 1.0  # [s] simulated, zero commands after each leg
SETTLE = 1.0  # [s] simulated, standing before the first leg (the robots drop onto the ground)
COMMAND_PERIOD = 0.05  # [s] simulated: commands at 20 Hz
STARTUP = 150.0  # [s] wall, for the master, the simulator, every robot's nodes and spawn
WALL_LIMIT = 90.0  # [s] wall, for any one simulated wait
LEG_KINDS = ("forward", "turn", "crab")  # in the order driven; a robot without a leg stands still during it


@dataclass(frozen=True)
class Leg:
    name: str  # forward, turn, crab
    twist: Tuple[float, float, float]  # (vx [m/s], vy [m/s], wz [rad/s]) in base_link
    seconds: float


def plan_for(config) -> List[Leg]:
    """The legs this robot drives: forward and turn; crab too when no wheel is fixed to an axle."""
    axle, _ = common_axle(config.drives, config.passive_wheels)
    legs = [Leg("forward", (SPEED, 0.0, 0.0), LEG)]
    if axle is None:
        legs.append(Leg("turn", (0.0, 0.0, TURN_RATE), LEG))
        legs.append(Leg("crab", (CRAB, CRAB, 0.0), LEG))
    else:
        # rotation about the foot of the perpendicular from base_link's origin to the axle line:
        # base_link's velocity is w z x (origin - centre) = w (cy, -cx)
        t = -(axle.x * axle.dx + axle.y * axle.dy)
        cx, cy = axle.x + t * axle.dx, axle.y + t * axle.dy
        legs.append(Leg("turn", (TURN_RATE * cy + 0.0, -TURN_RATE * cx + 0.0, TURN_RATE), LEG))  # no -0.0
    return legs


def planar(odom) -> Tuple[float, float, float]:
    p = odom.pose.pose
    return p.position.x, p.position.y, quaternion_yaw(p.orientation)


def delta(start: Sequence[float], end: Sequence[float]) -> Tuple[float, float, float]:
    """The motion from pose start to pose end (x, y, yaw): length [m], direction in start's heading
    [rad], turn [rad]. The same in any two frames that differ by a rigid move."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    direction = math.remainder(math.atan2(dy, dx) - start[2], 2 * math.pi)
    return math.hypot(dx, dy), direction, math.remainder(end[2] - start[2], 2 * math.pi)


class Commanders:
    """Streams every robot's twist on its nav_vel at 20 Hz of simulated time, from one thread."""

    def __init__(self, names):
        self.pubs = {n: rospy.Publisher(f"/{n}/nav_vel", Twist, queue_size=1) for n in names}
        self.twists: Dict[str, Optional[Tuple[float, float, float]]] = {n: None for n in names}
        self._lock = threading.Lock()
        threading.Thread(target=self._run, daemon=True).start()

    def _run(self):
        last = None
        while not rospy.is_shutdown():
            now = rospy.get_time()
            if last is None or now - last >= COMMAND_PERIOD or now < last:
                last = now
                with self._lock:
                    twists = dict(self.twists)
                for name, twist in twists.items():
                    if twist is not None:
                        msg = Twist()
                        msg.linear.x, msg.linear.y, msg.angular.z = twist
                        self.pubs[name].publish(msg)
            time.sleep(0.002)

    def send(self, name, twist):
        with self._lock:
            self.twists[name] = tuple(twist)

    def unsubscribed(self):
        return [n for n, p in self.pubs.items() if p.get_num_connections() == 0]


def sim_sleep(seconds):
    """Waits for seconds of simulated time, within a wall-clock limit."""
    end = rospy.get_time() + seconds
    deadline = time.monotonic() + WALL_LIMIT
    while rospy.get_time() < end:
        if time.monotonic() > deadline:
            raise RuntimeError(f"simulated time stalled at {rospy.get_time():.2f} s (waiting for {end:.2f} s)")
        time.sleep(0.005)


def wait_until(predicate, deadline, what):
    while not predicate():
        if time.monotonic() > deadline:
            raise RuntimeError(f"timed out waiting for {what}")
        time.sleep(0.1)


def main(argv) -> int:
    robots = dict(a.split("=", 1) for a in argv)
    plans = {name: plan_for(load_robot_config(path)) for name, path in robots.items()}
    wall0 = time.monotonic()
    deadline = wall0 + STARTUP

    master = rosgraph.Master("/every_robot_driver")

    def sim_time_set():
        try:
            return master.is_online() and master.hasParam("/use_sim_time")
        except Exception:  # the master is still coming up
            return False

    wait_until(sim_time_set, deadline, "the ROS master and /use_sim_time")

    rospy.init_node("every_robot_driver", disable_signals=True)
    truth = {n: Latest(f"/{n}/odometry/gazebo", Odometry) for n in robots}
    odometry = {n: Latest(f"/{n}/odometry/base_raw", Odometry) for n in robots}
    commanders = Commanders(robots)

    def missing():
        return (
            [f"/{n}/odometry/gazebo" for n, s in truth.items() if s.get() is None]
            + [f"/{n}/odometry/base_raw" for n, s in odometry.items() if s.get() is None]
            + [f"a subscriber of /{n}/nav_vel" for n in commanders.unsubscribed()]
        )

    try:
        wait_until(lambda: not missing(), deadline, "every robot")
    except RuntimeError:
        raise RuntimeError(f"within {STARTUP:.0f} s, nothing on: {', '.join(missing())}") from None
    for n in robots:
        commanders.send(n, (0.0, 0.0, 0.0))
    sim_sleep(SETTLE)
    started = time.monotonic()
    sim_start = rospy.get_time()

    results: Dict[str, List[dict]] = {n: [] for n in robots}
    for kind in LEG_KINDS:
        legs = {n: leg for n, plan in plans.items() for leg in plan if leg.name == kind}
        if not legs:
            continue
        start = {n: (planar(truth[n].get()), planar(odometry[n].get())) for n in legs}
        for n, leg in legs.items():
            commanders.send(n, leg.twist)
        sim_sleep(max(leg.seconds for leg in legs.values()))
        for n in legs:
            commanders.send(n, (0.0, 0.0, 0.0))
        sim_sleep(PAUSE)
        for n, leg in legs.items():
            results[n].append(
                {
                    "leg": kind,
                    "twist": list(leg.twist),
                    "seconds": leg.seconds,
                    "truth": list(delta(start[n][0], planar(truth[n].get()))),
                    "odometry": list(delta(start[n][1], planar(odometry[n].get()))),
                }
            )
    report = {
        "robots": results,
        "startup_wall": started - wall0,
        "pattern_sim": rospy.get_time() - sim_start,
        "pattern_wall": time.monotonic() - started,
    }
    print(json.dumps(report), flush=True)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except RuntimeError as e:
        print(f"every_robot_driver: {e}", file=sys.stderr)
        sys.exit(1)
