"""The simulator's physics without ROS: descriptions, robots on the ground, motors, springs, casters.

Every robot is generated from an example configuration (thorvald_model, the real xacro); expected
numbers come from that configuration and from mechanics, not from the simulator's own output.
"""

import glob
import math
import os

import pybullet as p
import pytest
import yaml

from thorvald_model import load_robot_config
from thorvald_model.description import generate_urdf
from thorvald_sim.physics.description import DescriptionError, parse_description
from thorvald_sim.physics.robot import Pose2D, yaw_of
from thorvald_sim.physics.simulation import Camera, Simulation, SpawnError
from thorvald_sim.world import parse_world

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIGS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "thorvald_model", "config"))
EXAMPLES = sorted(glob.glob(os.path.join(CONFIGS, "*", "*.yaml")))
FLAT = parse_world({"ground": {"lateral_friction": 0.9}}, "flat")
_URDF = {}


def example(name):
    return os.path.join(CONFIGS, name, name + ".yaml")


def urdf(path, tf_prefix=""):
    key = (path, tf_prefix)
    if key not in _URDF:
        _URDF[key] = generate_urdf(path, tf_prefix=tf_prefix)
    return _URDF[key]


@pytest.fixture
def sim():
    client = p.connect(p.DIRECT)
    yield Simulation(client, FLAT)
    p.disconnect(client)


def run(sim, seconds, robot=None, steering=None, speeds=None):
    if robot is not None:
        robot.command(steering, speeds)
    for _ in range(round(seconds / sim.dt)):
        sim.step()


# ---- the description ------------------------------------------------------------------------
@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: os.path.basename(p)[:-5])
def test_the_description_lists_the_configurations_drives_in_order(path):
    config = load_robot_config(path)
    d = parse_description(urdf(path, "r/"))
    assert (d.command_topic, d.odometry_topic, d.odometry_frame, d.base_frame) == (
        "base_state",
        "odometry/gazebo",
        "r/odom",
        "r/base_link",
    )
    assert [(x.steering_joint, x.wheel_joint, x.wheel_radius, x.steerable) for x in d.drives] == [
        ("r/" + c.steering_name, "r/" + c.wheel_name, c.r_wheel, c.steerable) for c in config.drives
    ]
    # motors' limits: the motor torques through the gears
    for c, x in zip(config.drives, d.drives):
        assert d.joints[x.wheel_joint].effort == pytest.approx(c.prp_motor_torque * c.prp_gr_rt)
    assert sorted(s.joint for s in d.springs) == sorted("r/suspension" + s.drive[5:] for s in config.suspensions)
    casters = [w for w in config.passive_wheels if not w.fixed]
    assert {j.name for j in d.passive_joints} == {"r/" + w.name + "_swivel" for w in casters} | {
        "r/" + w.name + "_wheel" for w in config.passive_wheels
    }


@pytest.mark.parametrize(
    "xml, reason",
    [
        ("", "is empty"),
        ("<robot name='x'><link name='a'>", "not valid XML"),
        ("<sdf/>", "root element is <sdf>"),
        ("<robot name='x'/>", "has no <link>"),
        (
            "<robot name='x'><link name='a'/><gazebo><plugin><drive index='0' type='0' steering_joint='s'"
            " wheel_joint='w' wheel_radius='0.2'/></plugin></gazebo></robot>",
            "drive 0 names joint 'w', which the description does not have",
        ),
    ],
)
def test_a_description_the_simulator_cannot_use_says_why(xml, reason):
    with pytest.raises(DescriptionError, match=reason):
        parse_description(xml)


# ---- robots on the ground -------------------------------------------------------------------
@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: os.path.basename(p)[:-5])
def test_every_example_robot_stands_on_its_wheels_and_drives_straight(sim, path):
    config = load_robot_config(path)
    robot = sim.spawn("r", urdf(path), Pose2D(1.0, 2.0, 0.02, 0.5))
    run(sim, 1.0)
    (x0, y0, z0), q0 = robot.odom_pose()
    # base_link is on the ground plane: in the odom frame (the spawn pose on the ground) it starts at
    # the origin; a suspension sags under the robot's weight, but less than its travel
    sag = max((s.travel / 2 for s in config.suspensions), default=0.0)
    assert abs(x0) < 0.01 and abs(y0) < 0.01 and -sag - 0.005 < z0 < 0.005 and abs(yaw_of(q0)) < 0.01
    n = len(config.drives)
    # up to speed (a single driven wheel takes about 0.2 s: its traction and torque limit it), then
    # 2 s at 0.5 m/s along odom x
    run(sim, 1.0, robot, [0.0] * n, [0.5] * n)
    (x0, y0, _), q0 = robot.odom_pose()
    run(sim, 2.0)
    (x1, y1, _), q1 = robot.odom_pose()
    v, w = robot.body_twist()
    assert v[0] == pytest.approx(0.5, abs=0.005) and abs(v[1]) < 0.005 and abs(w[2]) < 0.005
    # along the heading it had (unevenly loaded wheels may turn it a little while accelerating)
    heading = yaw_of(q0)
    along = (x1 - x0) * math.cos(heading) + (y1 - y0) * math.sin(heading)
    across = -(x1 - x0) * math.sin(heading) + (y1 - y0) * math.cos(heading)
    assert along == pytest.approx(1.0, rel=0.02) and abs(across) < 0.01 and abs(yaw_of(q1) - heading) < 0.01
    # the world frame: odom is the spawn pose, 0.5 rad from world x
    (wx, wy, _), _ = robot.world_pose()
    c, s = math.cos(0.5), math.sin(0.5)
    assert (wx, wy) == pytest.approx((1.0 + c * x1 - s * y1, 2.0 + s * x1 + c * y1), abs=1e-6)
    # the encoders: rim speed 0.5 m/s
    assert all(s.speed == pytest.approx(0.5, abs=0.01) for s in robot.drive_states())


def test_spin_in_place_about_base_link(sim):
    config = load_robot_config(example("thorvald_ii_4wd4ws_std"))
    robot = sim.spawn("r", urdf(example("thorvald_ii_4wd4ws_std")), Pose2D())
    wz = 0.5
    # each wheel rolls along wz x (x, y) = (-wz y, wz x); rim speed wz * distance to base_link
    steering = [math.atan2(wz * d.x, -wz * d.y) for d in config.drives]
    speeds = [wz * math.hypot(d.x, d.y) for d in config.drives]
    run(sim, 1.0, robot, steering, [0.0] * 4)  # steer first
    (x0, y0, _), q0 = robot.odom_pose()
    run(sim, 2.0, robot, steering, speeds)
    (x1, y1, _), q1 = robot.odom_pose()
    assert robot.body_twist()[1][2] == pytest.approx(wz, rel=0.01)
    assert math.hypot(x1 - x0, y1 - y0) < 0.05
    turned = math.remainder(yaw_of(q1) - yaw_of(q0), 2 * math.pi)
    assert turned == pytest.approx(wz * 2.0, rel=0.03)


def test_a_differential_robot_turns_about_the_point_its_wheel_speeds_give(sim):
    """v_right, v_left = vx -+ wz b: base_link turns about (0, vx / wz). The wheels must touch the
    ground under their centre lines for that (pybullet touches a wide cylinder at one rim)."""
    config = load_robot_config(example("thorvald_ii_2wd_diff"))
    robot = sim.spawn("r", urdf(example("thorvald_ii_2wd_diff")), Pose2D())
    run(sim, 0.5)
    vx, wz = 0.4, 0.3
    run(sim, 3.0, robot, [0.0, 0.0], [vx - wz * d.y for d in config.drives])
    v, w = robot.body_twist()
    assert w[2] == pytest.approx(wz, rel=0.01)
    assert math.hypot(v[0], v[1]) / w[2] == pytest.approx(vx / wz, rel=0.01)


def test_the_wheels_touch_the_ground_with_thin_discs():
    from thorvald_sim.physics.description import with_tyre_contact  # noqa: PLC0415

    xml = urdf(example("thorvald_ii_2wd_diff"))
    thin = with_tyre_contact(xml, ["wheel0", "passive0_wheel"], 0.01)
    import xml.etree.ElementTree as ET  # noqa: PLC0415

    def widths(text, link):
        root = ET.fromstring(text)
        element = next(e for e in root.findall("link") if e.get("name") == link)
        return [float(c.get("length")) for c in element.findall("collision/geometry/cylinder")], [
            float(c.get("length")) for c in element.findall("visual/geometry/cylinder")
        ]

    # collision narrowed to 1 cm, the visual as the URDF draws it; a wheel not named stays whole
    assert widths(thin, "wheel0_link") == ([0.01, 0.01], [0.16, 0.164])
    assert widths(thin, "passive0_wheel_link")[0] == [0.01, 0.01]
    assert widths(thin, "wheel1_link") == widths(xml, "wheel1_link")


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_wheels_are_torque_limited(sim):
    """A robot with a hundredth of the motor torque cannot reach the commanded speed up front: the
    standard one reaches 0.5 m/s at once, the weak one accelerates at about torque / (r m)."""
    data = yaml.safe_load(open(example("thorvald_ii_4wd4ws_std")))
    for drive in data["motor_drives"].values():
        drive["prp_motor_torque"] = 0.016
        drive.pop("prp_slm_e", None)
    weak_path = os.path.join(os.path.dirname(__file__), "_weak_robot.yaml")
    with open(weak_path, "w") as f:
        yaml.safe_dump(data, f)
    try:
        weak = sim.spawn("weak", generate_urdf(weak_path, tf_prefix="weak/"), Pose2D(0.0, 5.0, 0.0, 0.0))
    finally:
        os.unlink(weak_path)
    strong = sim.spawn("strong", urdf(example("thorvald_ii_4wd4ws_std"), "strong/"), Pose2D())
    run(sim, 0.5)
    weak.command([0.0] * 4, [0.5] * 4)
    strong.command([0.0] * 4, [0.5] * 4)
    run(sim, 0.5)
    assert strong.body_twist()[0][0] == pytest.approx(0.5, abs=0.01)
    # 4 wheels x 0.016 x 42 N m / 0.2 m = 13.4 N on the robot's mass: well under 0.1 m/s^2
    links = range(-1, p.getNumJoints(weak.body, physicsClientId=sim.client))
    mass = sum(p.getDynamicsInfo(weak.body, link, physicsClientId=sim.client)[0] for link in links)
    assert weak.body_twist()[0][0] == pytest.approx(4 * 0.016 * 42 / 0.2 / mass * 0.5, rel=0.2)


def test_suspension_springs_carry_the_robot_and_settle(sim):
    path = example("thorvald_ii_4wd4ws_wide_susp")
    config = load_robot_config(path)
    robot = sim.spawn("r", urdf(path), Pose2D())
    run(sim, 3.0)
    c = sim.client
    springs = robot.joint_states([j for j, _ in robot.springs])
    for position, velocity in springs:
        # compressed (the wheel up against the frame: the joint's +z) within the travel, at rest
        assert 0.0 < position < config.suspensions[0].travel / 2
        assert abs(velocity) < 1e-3
    # statics: the springs carry every link but those below them (suspension slide, leg, wheel)
    n = p.getNumJoints(robot.body, physicsClientId=c)
    parent = {j: p.getJointInfo(robot.body, j, physicsClientId=c)[16] for j in range(n)}

    def below_a_spring(link):
        while link != -1:
            if link in {j for j, _ in robot.springs}:
                return True
            link = parent[link]
        return False

    sprung = sum(p.getDynamicsInfo(robot.body, k, physicsClientId=c)[0] for k in range(-1, n) if not below_a_spring(k))
    k = config.suspensions[0].stiffness
    assert k * sum(q for q, _ in springs) == pytest.approx(sprung * 9.81, rel=0.02)


def test_casters_swivel_to_trail_the_motion(sim):
    path = example("thorvald_ii_2wd_diff")
    robot = sim.spawn("r", urdf(path), Pose2D())
    swivels = [j for j, info in robot.passive if info.name.endswith("_swivel")]
    assert len(swivels) == 2
    run(sim, 0.5)
    # spin on the spot, right wheel (drive0, y -0.275) back, left forward: clockwise at
    # (v_right - v_left) / track = -0.6 / 0.55; the casters behind the axle roll sideways, so they turn
    robot.command([0.0, 0.0], [-0.3, 0.3])
    run(sim, 2.0)
    _, q0 = robot.world_pose()
    run(sim, 1.0)
    _, q1 = robot.world_pose()
    assert math.remainder(yaw_of(q1) - yaw_of(q0), 2 * math.pi) == pytest.approx(-0.6 / 0.55, rel=0.03)
    assert all(abs(math.remainder(q, math.pi)) > 0.5 for q, _ in robot.joint_states(swivels))


def test_hold_stops_the_wheels_and_reset_returns_to_the_spawn_pose(sim):
    robot = sim.spawn("r", urdf(example("thorvald_ii_4wd4ws_std")), Pose2D(3.0, -1.0, 0.0, 1.0))
    run(sim, 2.0, robot, [0.3] * 4, [0.8] * 4)
    robot.hold()
    run(sim, 1.0)
    assert math.hypot(*robot.body_twist()[0][:2]) < 0.01
    assert [s.steering for s in robot.drive_states()] == pytest.approx([0.3] * 4, abs=0.01)
    sim.reset()
    run(sim, 0.5)
    (x, y, _), q = robot.world_pose()
    assert (x, y, yaw_of(q)) == pytest.approx((3.0, -1.0, 1.0), abs=0.01)


def test_spawn_and_delete_refuse_what_they_cannot_do_and_the_world_keeps_going(sim):
    sim.spawn("a", urdf(example("thorvald_ii_2wd_diff")), Pose2D())
    with pytest.raises(SpawnError, match="exists already"):
        sim.spawn("a", urdf(example("thorvald_ii_2wd_diff")), Pose2D(5.0, 0.0))
    with pytest.raises(SpawnError, match="b: the robot description is not valid XML"):
        sim.spawn("b", "<robot name='b'><link", Pose2D())
    with pytest.raises(SpawnError, match="no robot named 'c'; robots: a"):
        sim.delete("c")
    run(sim, 0.1)
    sim.delete("a")
    assert sim.robots == {}
    assert sim.time == pytest.approx(0.1, abs=sim.dt)


def test_snapshot_renders_the_world_without_a_display(sim):
    sim.spawn("r", urdf(example("thorvald_ii_4wd4ws_std")), Pose2D())
    image = sim.render(Camera(width=160, height=120))
    assert image.shape == (120, 160, 3)
    # the robot stands in the middle of the view: not one flat colour there
    centre = image[40:80, 60:100].reshape(-1, 3)
    assert len({tuple(px) for px in centre}) > 20
