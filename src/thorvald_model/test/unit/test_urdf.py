"""The robot description generated from each robot configuration file (issue 5), without a ROS master.

Parametrised over every example robot (globbed at collection time) and the paper's Figure 5 file.
Expected names and numbers come from the raw YAML files and the original's published figures.
"""

import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest
from urdf_helpers import (
    EXTRAS,
    FIGURE5,
    ORIGINAL_STR_LIM,
    PKG,
    ROBOTS,
    expected_moving_joints,
    golden_path,
    inertia_problems,
    origin_of,
    raw_yaml,
    robot_id,
    structural_differences,
    urdf_text,
    urdf_tree,
)

from thorvald_model import ConfigError
from thorvald_model.description import generate_urdf

robots = pytest.mark.parametrize("robot", ROBOTS, ids=robot_id)
STD = os.path.join(PKG, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
ENV = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(PKG, "src"), os.environ.get("PYTHONPATH", "")]))


def joints(tree):
    return {j.get("name"): j for j in tree.findall("joint")}


def links(tree):
    return {link.get("name"): link for link in tree.findall("link")}


# --- every robot ------------------------------------------------------------------------------
@robots
@pytest.mark.slow  # a process per case: the command as a user types it
def test_check_urdf_accepts_the_robot(robot, tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(urdf_text(robot))
    result = subprocess.run(["check_urdf", str(path)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Successfully Parsed XML" in result.stdout
    assert "root Link: base_link" in result.stdout


@pytest.mark.slow  # a description generated through xacro for every example robot
@robots
def test_moving_joints_are_those_of_the_configuration(robot):
    expected = expected_moving_joints(robot)
    moving = {name: j.get("type") for name, j in joints(urdf_tree(robot)).items() if j.get("type") != "fixed"}
    assert moving == expected


@robots
def test_every_drive_keeps_both_joint_names(robot):
    # A type-1 drive cannot steer, but its steering joint keeps the name (fixed), like the original.
    names = set(joints(urdf_tree(robot)))
    for name, d in raw_yaml(robot)["motor_drives"].items():
        n = name[len("drive") :]
        assert (d.get("steering_name") or "steering" + n) in names
        assert (d.get("wheel_name") or "wheel" + n) in names


@robots
def test_steering_limits_equal_str_lim(robot):
    js = joints(urdf_tree(robot))
    for name, d in raw_yaml(robot)["motor_drives"].items():
        if int(d.get("type", 0)) != 0:
            continue
        limit = js[d.get("steering_name") or "steering" + name[len("drive") :]].find("limit")
        str_lim = float(d.get("str_lim", ORIGINAL_STR_LIM))
        assert float(limit.get("lower")) == pytest.approx(-str_lim)
        assert float(limit.get("upper")) == pytest.approx(str_lim)


@robots
def test_drive_legs_stand_at_their_positions(robot):
    # The steering axis at (x, y), at wheel-centre height over base_link on the ground plane.
    tree = urdf_tree(robot)
    js = joints(tree)
    for name, d in raw_yaml(robot)["motor_drives"].items():
        n = name[len("drive") :]
        leg_joint = js[d.get("steering_name") or "steering" + n]
        parent = leg_joint.find("parent").get("link")
        xyz, _ = origin_of(leg_joint)
        if parent != "base_link":  # carried by a suspension module
            xyz2, _ = origin_of(js["suspension" + n])
            xyz = [a + b for a, b in zip(xyz, xyz2)]
        assert xyz == pytest.approx([float(d["x"]), float(d["y"]), float(d.get("r_wheel", 0.2))])


@robots
def test_every_link_has_a_valid_inertia(robot):
    problems = [p for link in urdf_tree(robot).findall("link") for p in inertia_problems(link)]
    assert problems == []


@robots
def test_modules_of_the_configuration_have_their_links(robot):
    data = raw_yaml(robot)
    names = set(links(urdf_tree(robot)))
    expected = {"base_link"}
    for name, d in data["motor_drives"].items():
        n = name[len("drive") :]
        expected |= {"leg" + n, f"wheel{n}_link"}
        if d.get("tower", True) not in (False, 0, "false"):
            expected.add("top" + n)
    expected |= set(data.get("batteries") or {})
    for c in data.get("corners") or {}:
        expected |= {c, c + "_1", c + "_2"}
    for p in data.get("pipes") or {}:
        expected |= {p + "_1", p + "_2"}
    expected |= set(data.get("beams") or {})
    expected |= set(data.get("frame_parts") or {})
    for p in data.get("passive_wheels") or {}:
        expected |= {p + "_fork", p + "_wheel_link"}
    for s in (data.get("suspensions") or {}).values():
        expected.add("suspension{}_link".format(s["drive"][len("drive") :]))
    assert names == expected


@robots
def test_matches_its_golden_urdf(robot):
    golden = golden_path(robot)
    assert os.path.exists(golden), f"no golden for {robot}: run src/thorvald_model/test/regenerate_goldens"
    with open(golden, "rb") as f:
        expected = ET.fromstring(f.read())
    differences = structural_differences(urdf_tree(robot), expected)
    assert differences == [], "\n".join(differences[:30])


@robots
def test_pybullet_loads_the_robot_with_its_joints(robot, tmp_path):
    pybullet = pytest.importorskip("pybullet")
    path = tmp_path / "robot.urdf"
    path.write_text(urdf_text(robot))
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(path), physicsClientId=client)
        count = pybullet.getNumJoints(body, physicsClientId=client)
        info = [pybullet.getJointInfo(body, i, physicsClientId=client) for i in range(count)]
        kinds = {pybullet.JOINT_REVOLUTE: "revolute", pybullet.JOINT_PRISMATIC: "prismatic"}
        moving = {i[1].decode(): kinds.get(i[2], "other") for i in info if i[2] != pybullet.JOINT_FIXED}
        # pybullet has no continuous type: continuous joints load as revolute.
        expected = {
            n: "prismatic" if k == "prismatic" else "revolute" for n, k in expected_moving_joints(robot).items()
        }
        assert moving == expected
        assert {i[1].decode() for i in info} == set(joints(urdf_tree(robot)))
        # A free-floating base: pybullet fixes a base of mass 0 to the world.
        assert pybullet.getDynamicsInfo(body, -1, physicsClientId=client)[0] > 0
    finally:
        pybullet.disconnect(client)


# --- the standard robot against the original's published figures --------------------------
def test_standard_drive_module_has_the_original_masses_and_inertias():
    ls = links(urdf_tree(STD))
    leg = ls["leg0"].find("inertial")
    assert float(leg.find("mass").get("value")) == pytest.approx(15.64)
    i = leg.find("inertia")
    assert [float(i.get(k)) for k in ("ixx", "iyy", "izz")] == pytest.approx([0.0356, 0.0356, 0.0125], abs=1e-4)
    wheel = ls["wheel0_link"].find("inertial")
    assert float(wheel.find("mass").get("value")) == pytest.approx(6.0)
    # The original's wheel I = (0.0728, 0.0728, 0.12) about a cylinder axis turned onto the leg's y axis.
    _, rpy = origin_of(wheel)
    assert [abs(v) for v in rpy] == pytest.approx([math.pi / 2, 0, 0])
    i = wheel.find("inertia")
    assert [float(i.get(k)) for k in ("ixx", "iyy", "izz")] == pytest.approx([0.0728, 0.0728, 0.12], abs=1e-4)


def test_wheel_joint_turns_about_the_legs_y_axis_and_steering_about_z():
    js = joints(urdf_tree(STD))
    assert js["wheel2"].find("parent").get("link") == "leg2"
    assert js["wheel2"].find("axis").get("xyz").split() == ["0", "1", "0"]
    assert js["steering2"].find("axis").get("xyz").split() == ["0", "0", "1"]
    assert js["steering2"].find("parent").get("link") == "base_link"


def test_fixed_modules_weigh_about_the_original_lumped_base_link():
    # Gazebo lumped the original's fixed modules into base_link: 86.43 kg (reconstruction notes 6).
    tree = urdf_tree(STD)
    moving_children = {j.find("child").get("link") for j in tree.findall("joint") if j.get("type") != "fixed"}
    moving = set(moving_children)
    changed = True
    while changed:  # everything below a moving joint moves too
        changed = False
        for j in tree.findall("joint"):
            if j.find("parent").get("link") in moving and j.find("child").get("link") not in moving:
                moving.add(j.find("child").get("link"))
                changed = True
    lumped = sum(
        float(link.find("inertial/mass").get("value"))
        for link in tree.findall("link")
        if link.get("name") not in moving
    )
    assert lumped == pytest.approx(86.43, rel=0.1)


def test_tower_and_pipes_of_the_standard_frame():
    tree = urdf_tree(STD)
    js = {j.find("child").get("link"): j for j in tree.findall("joint")}
    xyz, _ = origin_of(js["top1"])
    assert xyz == pytest.approx([0.547, -0.30, 0.65])
    # pipe0 from (-0.423, 0.296) to (0.423, 0.296), height 0.65, space 0.15: tubes at 0.575 and 0.725.
    assert origin_of(js["pipe0_1"])[0] == pytest.approx([0.0, 0.296, 0.575])
    assert origin_of(js["pipe0_2"])[0] == pytest.approx([0.0, 0.296, 0.725])
    tube = links(tree)["pipe0_1"].find("visual/geometry/cylinder")
    assert float(tube.get("length")) == pytest.approx(0.846)
    assert float(tube.get("radius")) == pytest.approx(0.02)


def test_type1_drives_cannot_steer():
    tall = os.path.join(PKG, "config", "thorvald_ii_4wd2ws_tall", "thorvald_ii_4wd2ws_tall.yaml")
    js = joints(urdf_tree(tall))
    assert js["steering2"].get("type") == "fixed" and js["steering3"].get("type") == "fixed"
    assert js["steering0"].get("type") == "revolute"
    assert js["wheel2"].get("type") == "continuous"


def test_motor_limits_are_the_motor_torques_through_the_gears():
    # 4wd2ws_tall: standard modules, so the defaults prp_motor_torque 1.6 N m x prp_gr_rt 42 and
    # str_motor_torque 1.0 N m x str_gr_rt 42.8571429; a passive wheel has no motor
    js = joints(urdf_tree(os.path.join(PKG, "config", "thorvald_ii_4wd2ws_tall", "thorvald_ii_4wd2ws_tall.yaml")))
    assert float(js["wheel0"].find("limit").get("effort")) == pytest.approx(1.6 * 42)
    assert float(js["steering0"].find("limit").get("effort")) == pytest.approx(1.0 * 42.8571429)
    rwd = joints(urdf_tree(os.path.join(PKG, "config", "thorvald_ii_1wd1ws_rwd", "thorvald_ii_1wd1ws_rwd.yaml")))
    assert float(rwd["passive0_wheel"].find("limit").get("effort")) == 0.0


@pytest.mark.slow  # a description generated through xacro for every example robot
@pytest.mark.parametrize("robot", ROBOTS, ids=robot_id)
def test_the_simulator_block_lists_every_drive_in_order(robot):
    tree = urdf_tree(robot, "r9/")
    plugin = tree.find("gazebo/plugin")
    assert plugin.findtext("commandTopic") == "base_state"
    assert plugin.findtext("odometryTopic") == "odometry/gazebo"
    assert (plugin.findtext("odometryFrame"), plugin.findtext("robotBaseFrame")) == ("r9/odom", "r9/base_link")
    drives = raw_yaml(robot)["motor_drives"]
    entries = plugin.findall("drive")
    assert [int(e.get("index")) for e in entries] == list(range(len(drives)))
    js = joints(tree)
    for e in entries:
        d = drives[f"drive{e.get('index')}"]
        assert int(e.get("type")) == int(d.get("type", 0))
        assert float(e.get("wheel_radius")) == pytest.approx(float(d.get("r_wheel", 0.2)))
        # the joints it names exist: the wheel turns, the steering turns unless the drive is type 1
        assert js[e.get("wheel_joint")].get("type") == "continuous"
        assert js[e.get("steering_joint")].get("type") == ("fixed" if e.get("type") == "1" else "revolute")


@pytest.mark.parametrize("robot", [r for r in ROBOTS if raw_yaml(r).get("suspensions")], ids=robot_id)
def test_suspension_is_a_damped_vertical_joint_within_its_travel(robot):
    js = joints(urdf_tree(robot))
    for s in raw_yaml(robot)["suspensions"].values():
        j = js["suspension" + s["drive"][len("drive") :]]
        assert j.find("axis").get("xyz").split() == ["0", "0", "1"]
        travel = float(s.get("travel", 0.1))
        assert float(j.find("limit").get("lower")) == pytest.approx(-travel / 2)
        assert float(j.find("limit").get("upper")) == pytest.approx(travel / 2)
        assert float(j.find("dynamics").get("damping")) == pytest.approx(float(s.get("damping", 3000)))


# --- arguments ----------------------------------------------------------------------------------
@pytest.mark.slow  # a description generated through xacro for every example robot
def test_model_extras_adds_a_sensor_link():
    tree = urdf_tree(STD, "", EXTRAS)
    assert "lidar_front" in links(tree)
    assert joints(tree)["lidar_front_joint"].find("parent").get("link") == "top1"
    assert "lidar_front" not in links(urdf_tree(STD))


def test_model_extras_sees_the_tf_prefix():
    tree = urdf_tree(STD, "robot_7/", EXTRAS)
    assert joints(tree)["robot_7/lidar_front_joint"].find("parent").get("link") == "robot_7/top1"


def test_two_robots_with_different_tf_prefix_share_no_frame():
    def names(prefix):
        tree = urdf_tree(STD, prefix)
        return {e.get("name") for e in tree.findall("link")} | {e.get("name") for e in tree.findall("joint")}

    one, two = names("robot_1/"), names("robot_2/")
    assert one and two and not (one & two)
    assert all(n.startswith("robot_1/") for n in one)
    # The prefix is concatenated without a separator (tf_prefix:="robot_1/"), as the original.
    assert {n[len("robot_1/") :] for n in one} == names("")
    tree = urdf_tree(STD, "robot_1/")
    parents = {j.find("parent").get("link") for j in tree.findall("joint")}
    assert all(p.startswith("robot_1/") for p in parents)


def test_robot_name_defaults_to_the_file_name_and_can_be_set():
    assert urdf_tree(FIGURE5).get("name") == "paper_figure5"
    assert ET.fromstring(generate_urdf(FIGURE5, robot_name="thorvald_001").encode()).get("name") == "thorvald_001"


def test_a_broken_configuration_raises_the_loaders_error(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("motor_drives:\n  drive0: {node: 1, x: 0.5, y: 0.3, r_wheel: -0.2}\n  drive1: {node: 2, y: 0}\n")
    with pytest.raises(ConfigError) as info:
        generate_urdf(str(bad))
    paths = {p.path for p in info.value.problems}
    assert {"motor_drives.drive0.r_wheel", "motor_drives.drive1.x"} <= paths


# --- command line -------------------------------------------------------------------------------
def run_module(module, *args):
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True, env=ENV)


@pytest.mark.slow  # a process per case: the command as a user types it
def test_cli_prints_the_urdf():
    result = run_module("thorvald_model.generate_urdf", FIGURE5, "--tf-prefix", "robot_1/", "--robot-name", "r1")
    assert result.returncode == 0, result.stderr
    tree = ET.fromstring(result.stdout.encode())
    assert tree.get("name") == "r1"
    assert "robot_1/steering3" in joints(tree)


@pytest.mark.parametrize(
    "module,extra",
    [
        ("thorvald_model.generate_urdf", []),
        ("thorvald_model.xacro_wrapper", [os.path.join(PKG, "urdf", "thorvald_model.xacro")]),
    ],
)
@pytest.mark.slow  # a process per case: the command as a user types it
def test_cli_prints_the_loaders_problems_and_exits_2(tmp_path, module, extra):
    bad = tmp_path / "bad.yaml"
    bad.write_text("motor_drives:\n  drive0: {node: 1, x: 0.5, y: 0.3, r_wheel: -0.2, str_lm: 1}\n")
    args = [*extra, "robot_config:=" + str(bad)] if extra else [str(bad)]
    result = run_module(module, *args)
    assert result.returncode == 2
    assert result.stdout == ""
    assert "Traceback" not in result.stderr
    assert f"{bad}: motor_drives.drive0.r_wheel: -0.2: must be > 0" in result.stderr
    assert "motor_drives.drive0.str_lm" in result.stderr and "did you mean 'str_lim'?" in result.stderr


@pytest.mark.slow  # a process per case: the command as a user types it
def test_cli_reports_a_missing_extras_file_and_exits_2(tmp_path):
    result = run_module("thorvald_model.generate_urdf", FIGURE5, "--extras", str(tmp_path / "nope.xacro"))
    assert result.returncode == 2
    assert "Traceback" not in result.stderr and "nope.xacro" in result.stderr


@pytest.mark.slow  # a process per case: the command as a user types it
def test_xacro_wrapper_output_equals_the_library_output():
    xacro_file = os.path.join(PKG, "urdf", "thorvald_model.xacro")
    result = run_module("thorvald_model.xacro_wrapper", xacro_file, "robot_config:=" + FIGURE5, "tf_prefix:=a/")
    assert result.returncode == 0, result.stderr
    assert structural_differences(ET.fromstring(result.stdout.encode()), urdf_tree(FIGURE5, "a/")) == []


@pytest.mark.slow  # a process per case: the command as a user types it
def test_generation_is_pure():
    # URDF generation belongs to the pure core: no rospy, no messages, no pybullet.
    code = (
        "import sys, thorvald_model.description as d; d.generate_urdf(sys.argv[1]); "
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('rospy', 'pybullet') or m.endswith('.msg')))"
    )
    result = subprocess.run([sys.executable, "-c", code, FIGURE5], capture_output=True, text=True, env=ENV)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"
