"""``rosrun thorvald_sim can_emulator ROBOT.yaml``: a robot's CAN devices on an SLCAN hub.

Every motor controller, battery and IO board of the robot file answers on a bus that other
processes join through pseudo-terminals: port k is ``LINK_DIR/portk`` (a link to its
``/dev/pts/N``), opened as an SLCAN adapter, e.g. base_driver with ``can_interface_type:=slcan
can_interface_name:=/tmp/thorvald_can/port0``; an implement or a sniffer on the next port.

With a ROS master, fault injection as services (without one, the emulator runs on its own):

* ``~<device>/silence`` (std_srvs/SetBool): a device stops sending (true) or resumes; devices are
  the drives' names (their motor controller), ``battery_K`` and ``io_I``;
* ``~corrupt`` (std_srvs/Trigger): the next 20 frames the devices send are malformed;
* ``~portK/drop`` (std_srvs/Trigger): port K's pseudo-terminal closes, as an adapter unplugged,
  and comes back at the same link after ``--reconnect-after`` seconds.
"""

import argparse
import os
import signal
import sys
import threading
import time

from thorvald_model import load_robot_config
from thorvald_model.errors import ConfigError

from .emulator import CanEmulator
from .hub import Hub

STEP = 0.005  # [s] between emulator steps (devices report every 20 ms and more)


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="can_emulator", description=__doc__.split("\n")[0])
    parser.add_argument("robot", help="the robot configuration file (YAML)")
    parser.add_argument("--ports", type=int, default=2, help="SLCAN pseudo-terminals (2)")
    parser.add_argument("--link-dir", default="/tmp/thorvald_can", help="where port0, port1 ... link to them")
    parser.add_argument("--reconnect-after", type=float, default=2.0, help="[s] a dropped port is back after")
    parser.add_argument("--seed", type=int, default=0)
    return parser.parse_args([a for a in argv if not a.startswith("__")])  # roslaunch's __name:= ...


class EmulatorNode:
    def __init__(self, args):
        self.args = args
        self.config = load_robot_config(args.robot)
        self.hub = Hub(f"thorvald-emulator-{os.getpid()}", args.ports, args.link_dir)
        self.emulator = CanEmulator(self.config, self.hub.participant(), seed=args.seed)
        self.lock = threading.Lock()
        self.reopen_at = {}  # port index -> monotonic time
        self.running = True

    def advertise(self):
        import rospy  # noqa: PLC0415
        from std_srvs.srv import SetBool, SetBoolResponse, Trigger, TriggerResponse  # noqa: PLC0415

        # service name -> the emulator's device name
        devices = {c.name: c.name for c in self.emulator.controllers.values()}
        devices.update({f"battery_{k}": f"battery {k}" for k in self.emulator.batteries})
        devices.update({f"io_{k}": f"io {k}" for k in self.emulator.ios})

        def silence(name):
            def call(req):
                with self.lock:
                    if req.data:
                        self.emulator.silence(devices[name])
                    else:
                        self.emulator.resume(devices[name])
                return SetBoolResponse(True, f"{name} {'silenced' if req.data else 'resumed'}")

            return call

        def corrupt(_req):
            with self.lock:
                self.emulator.corrupt(20)
            return TriggerResponse(True, "the next 20 frames are malformed")

        def drop(k):
            def call(_req):
                self.hub.drop(k)
                with self.lock:
                    self.reopen_at[k] = time.monotonic() + self.args.reconnect_after
                return TriggerResponse(True, f"port{k} closed; back in {self.args.reconnect_after:g} s")

            return call

        self.services = [rospy.Service(f"~{n}/silence", SetBool, silence(n)) for n in devices]
        self.services.append(rospy.Service("~corrupt", Trigger, corrupt))
        self.services += [rospy.Service(f"~port{k}/drop", Trigger, drop(k)) for k in range(len(self.hub.ports))]

    def run(self):
        start = time.monotonic()
        next_step = start
        while self.running:
            with self.lock:  # the fault services change ports and devices: never in the middle of a pump
                self.hub.pump(timeout=0.001)
                now = time.monotonic()
                if now >= next_step:
                    self.emulator.step(now - start)
                    next_step = max(next_step + STEP, now)
                for k, when in list(self.reopen_at.items()):
                    if now >= when:
                        self.hub.restore(k)
                        del self.reopen_at[k]
        e = self.emulator
        # what the bus carried, said once at the end: a soak beside busy loops reads it (bench/can_soak.py)
        print(f"can_emulator: {self.hub.summary()}; devices: {e.received} frames in, {e.sent} out", flush=True)
        self.hub.close()


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        node = EmulatorNode(args)
    except ConfigError as e:
        print(f"can_emulator: {e}", file=sys.stderr)
        return 2
    ports = ", ".join(f"{p.link or p.path} -> {p.path}" for p in node.hub.ports)
    with_ros = False
    try:
        import rosgraph  # noqa: PLC0415

        with_ros = rosgraph.is_master_online()
    except ImportError:
        pass
    if with_ros:
        import rospy  # noqa: PLC0415

        rospy.init_node("can_emulator", disable_signals=True)
        node.advertise()
        rospy.loginfo(
            "can_emulator: %s: %d motor controller(s), SLCAN ports %s",
            args.robot,
            len(node.emulator.controllers),
            ports,
        )
    else:
        print(f"can_emulator: {args.robot}: SLCAN ports {ports} (no ROS master: no fault services)", flush=True)

    def stop(*_):
        node.running = False

    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    node.run()
    if with_ros:
        import rospy  # noqa: PLC0415

        rospy.signal_shutdown("done")
    return 0
