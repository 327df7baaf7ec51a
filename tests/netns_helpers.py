"""Helpers of tests/test_network_namespaces.py: a small network of hosts on this machine, and the
processes that run on those hosts.

Two halves in one file:

* in the pytest process (the machine's own network namespace, which it never leaves): ``Network``
  builds network namespaces joined by veth pairs to a Linux bridge in a "switch" namespace, cuts
  and restores links, and tears it all down; ``HostProcess`` runs a command inside one namespace
  (``ip netns exec``) in a session of its own with its output in a file; ``AgentClient`` talks to an
  agent (below) over its stdin/stdout with a wall-clock bound on every answer, so a process stuck
  behind a downed link can never hang the test.
* run as a script inside a namespace (``python3 netns_helpers.py agent --name NAME``): an *agent*,
  a small rospy node that streams Twist commands and records topics (on simulated time), driven by
  one JSON request per line on stdin, answering one JSON line per request on stdout. Also
  ``python3 netns_helpers.py wait-master URI PARAM TIMEOUT``: exits 0 once the master at URI
  answers and holds PARAM (a host's roslaunch starts only then).

Nothing here sends to an address outside the namespaces: the hosts' only interfaces are ``lo``
and one veth each, with no default route, IPv6 off (no neighbour discovery or MLD multicast) and
the multicast flag cleared on every link.
"""

import argparse
import json
import os
import queue
import re
import signal
import subprocess
import sys
import threading
import time
import xmlrpc.client

import rosgraph
import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from tf2_msgs.msg import TFMessage

from thorvald_base.conversions import quaternion_yaw
from thorvald_msgs.msg import BaseState
from thorvald_testing import poll  # noqa: F401  (the suite polls through this module: nh.poll)

PREFIX = "thvnet"  # every namespace of these tests is named PREFIX<pid>-<host>
SUBNET = "10.213.0"  # the hosts' /24 (private, on veth interfaces only)
MASTER_PORT = 11311  # each namespace has its own port space, so the usual port cannot collide
HOSTS = {"r1": 1, "r2": 2, "op": 10}  # host key -> last octet of its address
LOG_TAIL_LINES = 15
ANSI = re.compile(r"\x1b(\[[0-9;]*[A-Za-z]|\][^\x07]*\x07)")  # roslaunch's colours and terminal titles

HERE = os.path.dirname(os.path.abspath(__file__))


class NetnsError(Exception):
    """A network namespace operation failed (with the command and its message)."""


# ---- the pytest side: the network ---------------------------------------------------------------
NETNS_DIR = "/run/netns"  # where `ip netns add` names a namespace


def in_namespace(ns, argv):
    """argv run in network namespace ns. nsenter joins only the network namespace; `ip netns exec`
    and `ip -n` also make / a slave mount, which fails where / is not a mount point (a chroot, as a
    freshly bootstrapped Debian), and nothing here needs their remounted /sys."""
    return ["nsenter", f"--net={NETNS_DIR}/{ns}", *argv]


def ip(*args, check=True, timeout=15.0, ns=None):
    """Runs `ip ARGS` (in network namespace ns, if given); NetnsError with the command and its stderr
    if it fails and check."""
    argv = ["ip", *args] if ns is None else in_namespace(ns, ["ip", *args])
    try:
        out = subprocess.run(argv, capture_output=True, text=True, timeout=timeout)
    except FileNotFoundError:
        raise NetnsError(f"`{argv[0]}` is not installed (Debian packages iproute2, util-linux)") from None
    except subprocess.TimeoutExpired:
        raise NetnsError(f"`{' '.join(argv)}` did not finish within {timeout:.0f} s") from None
    if check and out.returncode != 0:
        raise NetnsError(f"`{' '.join(argv)}` failed (exit {out.returncode}): {out.stderr.strip()}")
    return out


def list_namespaces():
    out = ip("netns", "list", check=False)
    return [line.split()[0] for line in out.stdout.splitlines() if line.strip()]


def namespace_pids(ns):
    out = ip("netns", "pids", ns, check=False)
    return [int(p) for p in out.stdout.split() if p.isdigit()]


def _pytest_alive(pid):
    """Whether pid is a running Python process (a concurrent run of these tests owns its namespaces)."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            cmdline = f.read()
    except OSError:
        return False
    return b"python" in cmdline or b"pytest" in cmdline


def kill_namespace_processes(ns, grace=0.0):
    """SIGKILLs every process inside ns (after SIGTERM and grace [s], if grace); returns the pids found."""
    found = namespace_pids(ns)
    if grace and found:
        for pid in found:
            _signal(pid, signal.SIGTERM)
        deadline = time.monotonic() + grace
        while time.monotonic() < deadline and namespace_pids(ns):
            time.sleep(0.05)
    deadline = time.monotonic() + 10.0
    while True:
        left = namespace_pids(ns)
        if not left or time.monotonic() > deadline:
            return found
        for pid in left:
            _signal(pid, signal.SIGKILL)
        time.sleep(0.05)


def process_alive(pid):
    """Whether pid runs (a zombie waiting for its parent does not)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            state = f.read().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


def _signal(pid, sig):
    try:
        os.kill(pid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def clean_stale_namespaces(own_tag):
    """Deletes namespaces of earlier runs (PREFIX<pid>-... whose pid is no longer a Python process),
    killing what still runs inside them. Returns the names deleted."""
    deleted = []
    for ns in list_namespaces():
        m = re.match(rf"{PREFIX}(\d+)-", ns)
        if not m:
            continue
        if m.group(1) != own_tag and _pytest_alive(int(m.group(1))):
            continue  # a run going on right now
        kill_namespace_processes(ns)
        ip("netns", "delete", ns, check=False)
        deleted.append(ns)
    return deleted


def namespaces_unavailable():
    """None if this process can make network namespaces, else why not (one line)."""
    if os.geteuid() != 0:
        return f"not root (euid {os.geteuid()}): network namespaces need CAP_SYS_ADMIN and CAP_NET_ADMIN"
    probe = f"{PREFIX}{os.getpid()}-probe"
    try:
        ip("netns", "add", probe)
        ip("link", "set", "lo", "up", ns=probe)
    except NetnsError as e:
        return str(e)
    finally:
        ip("netns", "delete", probe, check=False)
    return None


class HostNet:
    """One host: its namespace, address and veth (the host's end; `port` is the switch's end)."""

    def __init__(self, key, tag):
        self.key = key
        self.ns = f"{PREFIX}{tag}-{key}"
        self.address = f"{SUBNET}.{HOSTS[key]}"
        self.veth = f"v{tag}{key}"  # at most 1 + 7 + 2 characters: under IFNAMSIZ
        self.port = f"s{tag}{key}"


class Network:
    """A switch namespace with a bridge, and one namespace per host joined to it by a veth pair:
    all hosts share SUBNET.0/24. Names carry the pid, so a crashed earlier run cannot collide."""

    def __init__(self, tag=None):
        self.tag = tag or str(os.getpid())
        self.switch = f"{PREFIX}{self.tag}-sw"
        self.bridge = f"b{self.tag}"
        self.hosts = {key: HostNet(key, self.tag) for key in HOSTS}
        self.created = []

    @property
    def namespaces(self):
        return [self.switch] + [h.ns for h in self.hosts.values()]

    def _add_namespace(self, ns):
        ip("netns", "add", ns)
        self.created.append(ns)
        # no IPv6: no router solicitations, neighbour discovery or MLD (all multicast) on the links
        # (written from inside the namespace: /proc/sys/net is the reading process's namespace's)
        script = "for k in all default; do echo 1 > /proc/sys/net/ipv6/conf/$k/disable_ipv6; done"
        subprocess.run(in_namespace(ns, ["sh", "-c", script]), capture_output=True, timeout=15)
        ip("link", "set", "lo", "up", ns=ns)

    def create(self):
        for ns in self.namespaces:
            self._add_namespace(ns)
        sw = self.switch
        ip("link", "add", self.bridge, "type", "bridge", ns=sw)
        ip("link", "set", self.bridge, "type", "bridge", "mcast_snooping", "0", check=False, ns=sw)
        ip("link", "set", self.bridge, "multicast", "off", "up", ns=sw)
        for h in self.hosts.values():
            ip("link", "add", h.veth, "netns", h.ns, "type", "veth", "peer", "name", h.port, "netns", sw)
            ip("link", "set", h.port, "master", self.bridge, ns=sw)
            ip("link", "set", h.port, "multicast", "off", "up", ns=sw)
            ip("addr", "add", f"{h.address}/24", "dev", h.veth, ns=h.ns)
            ip("link", "set", h.veth, "multicast", "off", "up", ns=h.ns)

    def set_link(self, key, up, end="host"):
        """Brings the link of host key down or up at the host's end (its veth) or the switch's (its port)."""
        h = self.hosts[key]
        ns, dev = (h.ns, h.veth) if end == "host" else (self.switch, h.port)
        ip("link", "set", dev, "up" if up else "down", ns=ns)

    def routes(self, key):
        out = ip("-j", "route", "show", "table", "all", ns=self.hosts[key].ns)
        return json.loads(out.stdout or "[]")

    def link_stats(self):
        """{(namespace, interface): received multicast packets} for every link of the network."""
        stats = {}
        for ns in self.namespaces:
            out = ip("-j", "-s", "link", "show", ns=ns)
            for link in json.loads(out.stdout or "[]"):
                rx = link.get("stats64", link.get("stats", {})).get("rx", {})
                stats[(ns, link["ifname"])] = rx.get("multicast", 0)
        return stats

    def destroy(self):
        """Kills every process inside the namespaces, deletes them; returns a list of problems (empty if
        all went)."""
        problems = []
        for ns in self.namespaces:
            if ns in list_namespaces():
                kill_namespace_processes(ns)
                left = namespace_pids(ns)
                if left:
                    problems.append(f"{ns}: processes {left} survived SIGKILL")
                out = ip("netns", "delete", ns, check=False)
                if out.returncode != 0:
                    problems.append(f"{ns}: `ip netns delete` failed: {out.stderr.strip()}")
        left = [ns for ns in list_namespaces() if ns in self.namespaces]
        if left:
            problems.append(f"namespaces left behind: {left}")
        return problems


# ---- the pytest side: processes on the hosts -----------------------------------------------------
def host_env(address, master_uri, home):
    """The environment of a process on a host: ROS_IP and ROS_MASTER_URI of that host, ROS_HOME and
    ROS_LOG_DIR in home, nothing that could send traffic elsewhere (proxies, ROS_HOSTNAME)."""
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("ROS_HOSTNAME", "ROS_NAMESPACE", "TMUX", "ROS_IPV6") and not k.lower().endswith("_proxy")
    }
    env.update(
        ROS_IP=address,
        ROS_MASTER_URI=master_uri,
        ROS_HOME=str(home),
        ROS_LOG_DIR=os.path.join(str(home), "log"),
        PYTHONUNBUFFERED="1",
    )
    return env


class HostProcess:
    """A command run inside a namespace, in a session of its own (so its process group can be
    signalled), stdout and stderr into a file (or stdout piped for an agent)."""

    def __init__(self, name, ns, argv, env, out_path, *, pipe=False):
        self.name, self.ns, self.out_path = name, ns, str(out_path)
        self._out = open(self.out_path, "w")
        self.popen = subprocess.Popen(
            in_namespace(ns, argv),
            env=env,
            stdin=subprocess.PIPE if pipe else subprocess.DEVNULL,
            stdout=subprocess.PIPE if pipe else self._out,
            stderr=self._out,
            start_new_session=True,
            text=pipe,
            bufsize=1 if pipe else -1,
        )

    @property
    def pid(self):
        return self.popen.pid

    def running(self):
        return self.popen.poll() is None

    def interrupt(self):
        if self.running():
            try:
                os.killpg(self.pid, signal.SIGINT)
            except ProcessLookupError:
                pass

    def kill(self):
        try:
            os.killpg(self.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass

    def close(self):
        for stream in (self.popen.stdin, self.popen.stdout):
            if stream is not None:
                try:
                    stream.close()
                except OSError:
                    pass
        self._out.close()


def stop_processes(processes, grace=5.0):
    """SIGINT to every process group (roslaunch then stops its nodes), SIGKILL after grace [s]."""
    for p in processes:
        p.interrupt()
    deadline = time.monotonic() + grace
    while time.monotonic() < deadline and any(p.running() for p in processes):
        time.sleep(0.05)
    for p in processes:
        if p.running():
            p.kill()
        try:
            p.popen.wait(timeout=5)
        except subprocess.TimeoutExpired:
            pass
        p.close()


def log_tails(dirs, lines=LOG_TAIL_LINES, max_files=24):
    """The last lines of the logs under dirs (roslaunch's screen output and the agents' stderr as we
    captured them, the nodes' stdout/stderr logs), newest last, for a failure message."""
    found = []
    for d in dirs:
        for root, _dirs, files in os.walk(str(d)):
            for f in files:
                # (not roslaunch's own roslaunch-*.log: it lists every process's environment)
                if f.endswith((".out", ".err", "stdout.log", "stderr.log")):
                    path = os.path.join(root, f)
                    try:
                        found.append((os.path.getmtime(path), path))
                    except OSError:
                        pass
    parts = []
    for _mtime, path in sorted(found)[-max_files:]:
        try:
            with open(path, errors="replace") as f:
                tail = f.readlines()[-lines:]
        except OSError as e:
            tail = [f"(unreadable: {e})\n"]
        if tail:
            text = ANSI.sub("", "".join(tail)).rstrip()
            parts.append(f"---- {path} (last {len(tail)} lines)\n{text}")
    return "\n".join(parts) if parts else "(no logs)"


class AgentClient:
    """The pytest end of an agent: request() writes one JSON line and waits, with a wall-clock bound,
    for the answer carrying the same id."""

    def __init__(self, proc, logs):
        self.proc, self.logs = proc, logs
        self._answers = queue.Queue()
        self._id = 0
        self._lock = threading.Lock()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        try:
            for line in self.proc.popen.stdout:
                try:
                    self._answers.put(json.loads(line))
                except ValueError:
                    pass
        except (OSError, ValueError):
            pass
        self._answers.put(None)

    def _fail(self, what):
        return AssertionError(f"agent {self.proc.name} ({self.proc.ns}): {what}\n{self.logs()}")

    def wait_ready(self, timeout):
        return self._wait(0, timeout, "ready")

    def _wait(self, want, timeout, op):
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise self._fail(f"no answer to {op!r} within {timeout:.0f} s")
            try:
                answer = self._answers.get(timeout=left)
            except queue.Empty:
                continue
            if answer is None:
                self._answers.put(None)
                raise self._fail(f"exited (status {self.proc.popen.poll()}) before answering {op!r}")
            if answer.get("id") == want:
                if "error" in answer:
                    raise self._fail(f"{op!r} failed: {answer['error']}")
                return answer

    def request(self, op, timeout=10.0, **args):
        with self._lock:
            self._id += 1
            want = self._id
            try:
                self.proc.popen.stdin.write(json.dumps(dict(args, id=want, op=op)) + "\n")
                self.proc.popen.stdin.flush()
            except (OSError, ValueError) as e:
                raise self._fail(f"cannot send {op!r}: {e}") from None
            return self._wait(want, timeout, op)

    def quit(self):
        try:
            self.proc.popen.stdin.write(json.dumps({"id": -1, "op": "quit"}) + "\n")
            self.proc.popen.stdin.flush()
        except (OSError, ValueError):
            pass


# ---- the namespace side: wait-master and the agent -----------------------------------------------
class _TimeoutTransport(xmlrpc.client.Transport):
    def __init__(self, timeout):
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host):
        conn = super().make_connection(host)
        conn.timeout = self._timeout
        return conn


def server(uri, timeout=3.0):
    return xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(timeout))


def wait_master(uri, param, timeout):
    """True once the master at uri answers and holds param (within timeout [s] of wall time)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            code, _msg, _value = server(uri).getParam("/netns_wait", param)
            if code == 1:
                return True
        except (OSError, xmlrpc.client.Error):
            pass
        time.sleep(0.1)
    return False


KINDS = {"odom": Odometry, "twist": Twist, "state": BaseState, "tf": TFMessage}  # what an agent records


class Agent:
    """A rospy node answering requests (dicts) with dicts. Records per topic, each stamped with the
    agent's simulated time when it arrived (``t``):

    odom   nav_msgs/Odometry       [t, stamp, x, y, yaw, vx, vy, wz]
    twist  geometry_msgs/Twist     [t, wall, vx, vy, wz, seq] (seq: linear.z of our commands)
    state  thorvald_msgs/BaseState [t, stamp, largest |prop_speed|]
    tf     tf2_msgs/TFMessage      per transform "parent child": [count, stamp, x, y] and, for children
                                   ending in base_link, records [t, parent, child, stamp, x, y]

    Streams (``stream``) publish a Twist at a fixed wall-clock rate, as a joystick or a navigation
    stack keeps doing whatever the network does; linear.z carries a sequence number (a ground robot
    ignores it) so the robot's side can tell which command came through.
    """

    def __init__(self):
        self.lock = threading.Lock()
        self.records = {}
        self.pairs = {}
        self.subs = {}
        self.streams = {}

    # -- recording
    def watch(self, topic, kind):
        if topic in self.subs:
            return {}
        if kind not in KINDS:
            raise ValueError(f"unknown kind {kind!r}: one of {sorted(KINDS)}")
        msg_type = KINDS[kind]
        self.records[topic] = []
        callback = getattr(self, "_on_" + kind)
        self.subs[topic] = rospy.Subscriber(topic, msg_type, callback, topic, queue_size=200)
        return {}

    def _add(self, topic, record):
        with self.lock:
            self.records[topic].append(record)

    def _on_odom(self, msg, topic):
        p, v = msg.pose.pose, msg.twist.twist
        record = [
            rospy.get_time(),
            msg.header.stamp.to_sec(),
            p.position.x,
            p.position.y,
            quaternion_yaw(p.orientation),
        ]
        self._add(topic, [*record, v.linear.x, v.linear.y, v.angular.z])

    def _on_twist(self, msg, topic):
        t = rospy.get_time()
        self._add(topic, [t, time.monotonic(), msg.linear.x, msg.linear.y, msg.angular.z, msg.linear.z])

    def _on_state(self, msg, topic):
        speed = max((abs(s) for s in msg.prop_speed), default=0.0)
        self._add(topic, [rospy.get_time(), msg.header.stamp.to_sec(), speed])

    def _on_tf(self, msg, topic):
        t = rospy.get_time()
        with self.lock:
            for tr in msg.transforms:
                key = f"{tr.header.frame_id} {tr.child_frame_id}"
                entry = self.pairs.setdefault(key, [0, 0.0, 0.0, 0.0])
                x, y = tr.transform.translation.x, tr.transform.translation.y
                entry[:] = [entry[0] + 1, tr.header.stamp.to_sec(), x, y]
                if tr.child_frame_id.endswith("base_link"):
                    stamp = tr.header.stamp.to_sec()
                    self.records[topic].append([t, tr.header.frame_id, tr.child_frame_id, stamp, x, y])

    # -- streaming
    def stream(self, topic, twist=None, rate=20.0):
        """Starts (twist [vx, vy, wz]), changes or pauses (twist None) the stream on topic."""
        s = self.streams.get(topic)
        if s is None:
            s = self.streams[topic] = _Stream(topic, rate)
        s.set(twist)
        return {}

    # -- answers
    def status(self):
        with self.lock:
            topics = {t: {"count": len(r), "last": r[-1] if r else None} for t, r in self.records.items()}
            pairs = {k: list(v) for k, v in self.pairs.items()}
        streams = {t: s.status() for t, s in self.streams.items()}
        return {"time": rospy.get_time(), "wall": time.monotonic(), "topics": topics, "tf": pairs, "streams": streams}

    def history(self, topic, since=0.0):
        with self.lock:
            return {"records": [r for r in self.records[topic] if r[0] >= since]}

    def param(self, name, default=None):
        return {"value": rospy.get_param(name, default)}

    def nodes(self):
        """Every node the master knows: {name: [xmlrpc uri, pid]} (pid None if it does not answer)."""
        master = rosgraph.Master(rospy.get_name())
        names = set()
        for kind in master.getSystemState():
            for _topic, members in kind:
                names.update(members)
        found = {}
        for name in sorted(names):
            try:
                uri = master.lookupNode(name)
            except rosgraph.MasterError:
                continue
            try:
                _code, _msg, pid = server(uri).getPid("/netns_agent")
            except (OSError, xmlrpc.client.Error):
                pid = None
            found[name] = [uri, pid]
        return {"nodes": found}

    def handle(self, req):
        op = req.pop("op")
        req.pop("id", None)
        if op == "watch":
            return self.watch(**req)
        if op == "stream":
            return self.stream(**req)
        if op == "status":
            return self.status()
        if op == "history":
            return self.history(**req)
        if op == "param":
            return self.param(**req)
        if op == "nodes":
            return self.nodes()
        raise ValueError(f"unknown request {op!r}")


class _Stream:
    def __init__(self, topic, rate):
        self.pub = rospy.Publisher(topic, Twist, queue_size=10)  # asynchronous: never blocks on a link
        self.period = 1.0 / rate
        self.lock = threading.Lock()
        self.twist = None
        self.seq = 0
        self.seq_wall = []  # (seq, wall time) of every change of the twist
        threading.Thread(target=self._run, daemon=True).start()

    def set(self, twist):
        with self.lock:
            self.twist = None if twist is None else [float(v) for v in twist]
            self.seq_wall.append([self.seq, time.monotonic(), self.twist])

    def status(self):
        with self.lock:
            return {"connections": self.pub.get_num_connections(), "seq": self.seq, "twist": self.twist}

    def _run(self):
        tick = time.monotonic()
        while True:
            with self.lock:
                twist = self.twist
                if twist is not None:
                    self.seq += 1
                    seq = self.seq
            if twist is not None:
                msg = Twist()
                msg.linear.x, msg.linear.y, msg.angular.z = twist
                msg.linear.z = float(seq)
                self.pub.publish(msg)
            tick += self.period
            now = time.monotonic()
            if tick < now - self.period:
                tick = now  # fell behind (a busy machine): keep the rate, do not burst
            time.sleep(max(0.0, tick - now))


def agent_main(argv):
    parser = argparse.ArgumentParser(prog="netns_helpers.py agent")
    parser.add_argument("--name", required=True)
    parser.add_argument("--wait", type=float, default=120.0, help="for the master and /use_sim_time [s]")
    args = parser.parse_args(argv)
    # answers go to the original stdout; anything else printing (rospy's console output) to stderr
    answers = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)

    def answer(obj):
        answers.write(json.dumps(obj) + "\n")

    uri = os.environ["ROS_MASTER_URI"]
    if not wait_master(uri, "/use_sim_time", args.wait):
        answer({"id": 0, "error": f"no master with /use_sim_time at {uri} within {args.wait:.0f} s"})
        return 1
    rospy.init_node(args.name, disable_signals=True)
    agent = Agent()
    answer({"id": 0, "ready": True, "uri": rospy.get_node_uri()})
    for line in sys.stdin:
        try:
            req = json.loads(line)
        except ValueError:
            continue
        if req.get("op") == "quit":
            break
        rid = req.get("id")
        try:
            reply = agent.handle(dict(req))
            reply["id"] = rid
        except Exception as e:  # answered, so the test shows it
            reply = {"id": rid, "error": f"{type(e).__name__}: {e}"}
        answer(reply)
    rospy.signal_shutdown("quit")
    return 0


def main(argv):
    if argv[:1] == ["agent"]:
        return agent_main(argv[1:])
    if argv[:1] == ["wait-master"] and len(argv) == 4:
        uri, param, timeout = argv[1], argv[2], float(argv[3])
        if wait_master(uri, param, timeout):
            return 0
        print(f"wait-master: no master holding {param} at {uri} within {timeout:.0f} s", file=sys.stderr)
        return 1
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
