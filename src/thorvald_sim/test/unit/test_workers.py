"""Physics workers (thorvald_sim.physics.workers): a robot stepped in a worker process is the robot stepped in
the node's own client, to the bit; the pool places, spawns, deletes and resets robots across workers
and reports a worker that dies while the others go on.

Real processes and real pybullet: each pool starts its workers (about half a second each)."""

import math
import os
import signal

import genpy
import numpy as np
import pybullet as p
import pytest
from sim_test_helpers import Recorder

from thorvald_model.description import generate_urdf
from thorvald_sim.node.sensor_io import RobotSensors
from thorvald_sim.physics.as_built import AsBuilt, DriveAsBuilt, for_simulator
from thorvald_sim.physics.engine import NOTHING, LocalPhysics, Reads, WorldSettings
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation, SpawnError
from thorvald_sim.physics.workers import PROXIMITY_MARGIN, WorkerPool
from thorvald_sim.world import parse_world

HERE = os.path.dirname(os.path.abspath(__file__))
STD = os.path.abspath(
    os.path.join(
        HERE, "..", "..", "..", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml"
    )
)
FLAT = parse_world({"ground": {"lateral_friction": 0.9}}, "flat")
URDF = generate_urdf(STD)

INERTIAL = '<inertial><mass value="{m}"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
PROBE = f"""<robot name="probe">
  <link name="base_link">{INERTIAL.format(m=20)}
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.4 0.4 0.2"/></geometry></collision></link>
  <link name="lidar_link">{INERTIAL.format(m=0.2)}</link>
  <joint name="lidar_joint" type="fixed"><origin xyz="0 0 0.5"/>
    <parent link="base_link"/><child link="lidar_link"/></joint>
  <gazebo reference="lidar_link"><sensor type="ray" name="lidar"><update_rate>40</update_rate>
  <ray><scan><horizontal><samples>181</samples><min_angle>-1.5708</min_angle><max_angle>1.5708</max_angle></horizontal>
  </scan><range><min>0.1</min><max>30</max></range>
  <noise><type>gaussian</type><mean>0</mean><stddev>0.01</stddev></noise></ray>
  <plugin name="l" filename="libgazebo_ros_laser.so"><topicName>scan</topicName><frameName>lidar_link</frameName>
  </plugin></sensor></gazebo>
  <gazebo reference="base_link"><sensor type="imu" name="imu"><update_rate>100</update_rate>
  <plugin name="i" filename="libgazebo_ros_imu_sensor.so"><topicName>imu</topicName><frameName>base_link</frameName>
  <updateRateHZ>100</updateRateHZ></plugin></sensor></gazebo>
</robot>"""


def delayed():
    """The standard robot as built, its reports 25 ms late: what it reports depends on when it was read."""
    from thorvald_model import load_robot_config  # noqa: PLC0415

    config = load_robot_config(STD)
    drives = tuple(DriveAsBuilt(f"drive{i}", d.r_wheel * 1.01, 0.01) for i, d in enumerate(config.drives))
    radii = tuple(d.r_wheel for d in config.drives)
    return for_simulator(AsBuilt("test", drives, True, 0.025, 0.0, radii), config)


@pytest.fixture
def plain():
    client = p.connect(p.DIRECT)
    yield Simulation(client, FLAT, seed=3)
    p.disconnect(client)


@pytest.fixture
def pool():
    pool = WorkerPool(2, WorldSettings(FLAT, seed=3), strips=(5.0,))
    yield pool
    pool.close()


def commands(k):
    """The command sequence both worlds get: (steering [rad], speeds [m/s], limits) at step k, a hold, or None."""
    if k == 10:
        return [0.0] * 4, [0.6] * 4, [1.0] * 4
    if k == 150:
        return [0.3, 0.3, -0.3, -0.3], [0.5] * 4, [0.8] * 4
    if k == 300:
        return "hold"
    return None


def reads_at(k):
    """What the node would read at step k: drive states every third step, currents every 24th,
    odometry and passive joints every fifth (the rate grids at 240 Hz)."""
    return Reads(states=k % 3 == 0, currents=k % 24 == 0, odometry=k % 5 == 0, joints=k % 5 == 0)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_robot_in_a_worker_is_the_robot_in_the_nodes_client_to_the_bit(plain, pool):
    built = delayed()
    names = ("std", "built")
    # the plain world holds both robots; in the pool each has a worker of its own and a neighbour
    local = {
        "std": plain.spawn("std", URDF, Pose2D(0.0, 0.0)),
        "built": plain.spawn("built", URDF, Pose2D(8.0, 3.0), built),
    }
    remote = {
        "std": pool.spawn("std", URDF, Pose2D(0.0, 0.0)),
        "built": pool.spawn("built", URDF, Pose2D(8.0, 3.0), built),
    }
    pool.spawn("neighbour", URDF, Pose2D(0.0, 6.0))
    assert (remote["std"].worker, remote["built"].worker) == (0, 1)
    for k in range(1, 481):
        command = commands(k)
        for name in names:
            for robot in (local[name], remote[name]):
                if command == "hold":
                    robot.hold()
                elif command is not None:
                    robot.command(*command)
        reads = reads_at(k)
        plain.step()
        now = genpy.Time.from_sec(plain.time).to_sec()  # drives are read at their messages' stamp, as the node does
        assert pool.step({name: reads for name in names}, stamped=now) == []
        assert pool.time == plain.time
        for name in names:
            a, b = local[name], remote[name]
            passive = [j for j, _ in a.passive] + [j for j, _ in a.springs]
            if reads.currents:
                assert b.drive_currents(now) == a.drive_currents(now), (name, k)
            if reads.states:
                assert b.drive_states(now) == a.drive_states(now), (name, k)
            if reads.odometry:
                assert (b.odom_pose(), b.body_twist()) == (a.odom_pose(), a.body_twist()), (name, k)
                assert b.joint_states(passive) == (a.joint_states(passive) if passive else []), (name, k)
    assert local["std"].odom_pose()[0][0] > 0.3  # it drove
    with pytest.raises(RuntimeError, match="states not read"):
        remote["std"].drive_states(plain.time + plain.dt)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_the_nodes_own_physics_reads_what_a_plain_simulation_does_to_the_bit(plain):
    """LocalPhysics, the node's own client behind the physics interface the workers offer: the same
    robot, commands and reads give the same readings to the bit as a Simulation read directly."""
    local = LocalPhysics(WorldSettings(FLAT, seed=3))
    try:
        a = plain.spawn("built", URDF, Pose2D(8.0, 3.0), delayed())
        b = local.spawn("built", URDF, Pose2D(8.0, 3.0), delayed())
        for k in range(1, 361):
            command = commands(k)
            for robot in (a, b):
                if command == "hold":
                    robot.hold()
                elif command is not None:
                    robot.command(*command)
            reads = reads_at(k)
            plain.step()
            now = genpy.Time.from_sec(plain.time).to_sec()
            assert local.step({"built": reads}, stamped=now) == [] and local.time == plain.time
            if reads.states:
                assert b.drive_states(now) == a.drive_states(now), k
            if reads.currents:
                assert b.drive_currents(now) == a.drive_currents(now), k
            if reads.odometry:
                assert (b.odom_pose(), b.body_twist()) == (a.odom_pose(), a.body_twist()), k
        assert a.odom_pose()[0][0] > 0.3  # it drove (in its odom frame, from its spawn pose)
        assert local.too_close() == [] and local.placed(b) == "" and local.statuses("/simulator", {}) == []
    finally:
        local.close()


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_sensors_read_in_a_worker_read_what_they_read_in_the_nodes_client(plain, pool):
    local = plain.spawn("probe", PROBE, Pose2D(0.0, 0.0))
    remote = pool.spawn("probe", PROBE, Pose2D(0.0, 0.0))
    assert [s.spec.name for s in remote.sensors] == [s.spec.name for s in local.sensors] == ["lidar", "imu"]
    read = 0
    for _ in range(120):
        plain.step()
        pool.step({"probe": Reads(sensors=(0, 1))})
        results = remote.sensor_results
        for k, sensor in enumerate(local.sensors):
            if sensor.due(plain.time):
                kind, reading, cpu = results.pop(k)
                expected = sensor.read(plain.time)
                assert kind == "read" and cpu >= 0.0
                for field in expected.__dataclass_fields__:
                    mine, theirs = getattr(reading, field), getattr(expected, field)
                    assert np.array_equal(np.asarray(mine), np.asarray(theirs)), field
                read += 1
        assert results == {}  # nothing read that was not due
    assert read == 20 + 50  # 40 Hz and 100 Hz over half a simulated second


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_workers_sensors_publish_the_messages_the_nodes_own_would(plain, pool):
    """RobotSensors as the node runs it: stepped on its own client, or asking a worker (requests) and
    publishing what it read (publish_readings); every message the same, byte for byte."""
    local = RobotSensors(plain.spawn("probe", PROBE, Pose2D()).sensors, "/probe", publisher=Recorder)
    remote = RobotSensors(pool.spawn("probe", PROBE, Pose2D()).sensors, "/probe", publisher=Recorder)
    robot = pool.robots["probe"]
    for _ in range(120):
        plain.step()
        local.step(plain.time)
        pool.step({"probe": Reads(sensors=remote.requests(plain.time))})
        remote.publish_readings(plain.time, robot.sensor_results)
    for mine, theirs in zip(remote.ios, local.ios):
        for role, pub in mine.pubs.items():
            sent, expected = pub.messages, theirs.pubs[role].messages
            assert len(sent) == len(expected) > 0, role
            assert [serialised(m) for m in sent] == [serialised(m) for m in expected], role
    assert [u.readings for u in remote.uses()] == [u.readings for u in local.uses()] == [20, 50]

    # a reading that failed in the worker disables its sensor as a failure here would, alone
    remote.publish_readings(0.5, {1: ("failed", "OverflowError: too large", "Traceback ...")})
    local.ios[1].disable(0.5, OverflowError("too large"))
    assert remote.disabled() == local.disabled() and remote.disabled()[0].what.endswith("OverflowError: too large")
    assert remote.requests(0.6) == (0,)


def serialised(msg) -> bytes:
    import io  # noqa: PLC0415

    buff = io.BytesIO()
    msg.serialize(buff)
    return buff.getvalue()


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_spawn_and_delete_refuse_with_the_simulations_words(plain, pool):
    broken = '<robot name="b"><link name="base_link"/><joint name="j" type="fixed"><parent link="base_link"/><child link="nowhere"/></joint></robot>'  # noqa: E501
    cases = [("", URDF), ("twice", URDF), ("twice", URDF), ("broken", broken), ("bad", "<robot")]
    for name, urdf in cases:
        said = []
        for world in (plain, pool):
            try:
                world.spawn(name, urdf, Pose2D())
                said.append(None)
            except SpawnError as e:
                said.append(str(e))
        assert said[0] == said[1], name
    for world in (plain, pool):
        with pytest.raises(SpawnError) as e:
            world.delete("ghost")
        assert str(e.value) == "no robot named 'ghost'; robots: twice"


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_robots_go_to_their_strips_worker_or_the_least_loaded():
    pool = WorkerPool(3, WorldSettings(FLAT), strips=(0.0, 10.0))
    try:
        places = {x: pool.placement(Pose2D(x, 0.0)) for x in (-5.0, 0.0, 9.9, 10.0, 40.0)}
        assert places == {-5.0: 0, 0.0: 1, 9.9: 1, 10.0: 2, 40.0: 2}
    finally:
        pool.close()
    pool = WorkerPool(2, WorldSettings(FLAT))
    try:
        workers = [pool.spawn(f"r{k}", URDF, Pose2D(3.0 * k, 0.0)).worker for k in range(3)]
        assert workers == [0, 1, 0]  # without strips: the fewest robots, the first of those
        pool.delete("r0")
        assert pool.spawn("r3", URDF, Pose2D(50.0, 0.0)).worker == 0
    finally:
        pool.close()
    with pytest.raises(ValueError, match="strips"):
        WorkerPool(2, WorldSettings(FLAT), strips=(1.0, 2.0))


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_killed_worker_is_reported_and_the_others_go_on(pool):
    a = pool.spawn("a", URDF, Pose2D(0.0, 0.0))
    b = pool.spawn("b", URDF, Pose2D(10.0, 0.0))
    c = pool.spawn("c", URDF, Pose2D(12.0, 0.0))
    for robot in (a, b, c):
        robot.command([0.0] * 4, [0.5] * 4)
    for _ in range(60):
        assert pool.step() == []
    killed = pool.pids[1]
    os.kill(killed, signal.SIGKILL)
    deaths = pool.step()
    assert len(deaths) == 1
    death = deaths[0]
    assert (death.worker, death.pid, death.robots) == (1, killed, ("b", "c"))
    assert "signal 9" in death.reason and "b, c" in str(death)
    assert (a.alive, b.alive, c.alive) == (True, False, False)
    before = a.odom_pose()[0][0]
    for _ in range(60):
        assert pool.step() == []  # reported once
    assert a.odom_pose()[0][0] > before + 0.05  # worker 0's robot drives on
    assert b.got == NOTHING
    pool.delete("b")  # a dead worker's robots are still removed
    assert sorted(pool.robots) == ["a", "c"]
    assert pool.spawn("d", URDF, Pose2D(20.0, 0.0)).worker == 0  # its strip's worker is dead: the live one
    assert pool.solver_cpu > 0.0 and pool.cpu_elsewhere > 0.0


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_hung_worker_is_killed_after_the_timeout():
    pool = WorkerPool(2, WorldSettings(FLAT), timeout=1.0)
    try:
        pool.spawn("a", URDF, Pose2D())
        pool.spawn("b", URDF, Pose2D(5.0, 0.0))
        hung = pool.pids[0]
        os.kill(hung, signal.SIGSTOP)
        deaths = pool.step()
        assert [(d.worker, d.pid, d.robots) for d in deaths] == [(0, hung, ("a",))]
        assert "no answer" in deaths[0].reason and "killed" in deaths[0].reason
        assert pool.workers[0].process.poll() is not None  # it is gone, not stopped
        assert pool.step() == [] and pool.robots["b"].alive
    finally:
        pool.close()


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_reset_and_delete_work_across_workers(pool):
    a = pool.spawn("a", URDF, Pose2D(0.0, 0.0, 0.0, 0.5))
    b = pool.spawn("b", URDF, Pose2D(10.0, 0.0))
    assert (a.worker, b.worker) == (0, 1)
    for robot in (a, b):
        robot.command([0.0] * 4, [0.8] * 4)
    for _ in range(240):
        pool.step()
    assert all(math.hypot(*r.odom_pose()[0][:2]) > 0.3 for r in (a, b))
    pool.reset()
    pool.step()
    assert all(math.hypot(*r.odom_pose()[0][:2]) < 0.01 for r in (a, b))
    pool.delete("a")
    pool.delete("b")
    assert pool.robots == {} and [w.robots for w in pool.workers] == [[], []]
    again = pool.spawn("a", URDF, Pose2D(10.0, 0.0))  # the name is free again, on either worker
    assert again.worker == 1


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_robots_on_two_workers_closer_than_their_footprints_are_named(pool):
    a = pool.spawn("a", URDF, Pose2D(3.0, 0.0))
    b = pool.spawn("b", URDF, Pose2D(5.0, 0.0))
    pool.spawn("c", URDF, Pose2D(3.0, 2.2))  # on a's worker: as close to a, and no warning
    pool.step(positions=True)
    close = pool.too_close()
    assert [(t.a, t.b) for t in close] == [("a", "b")]
    assert close[0].limit == pytest.approx(a.radius + b.radius + PROXIMITY_MARGIN)
    assert 1.99 < close[0].distance < 2.01 < close[0].limit and 0.5 < a.radius < 1.5
