"""spawn_model's and spawn_robot's arguments (thorvald_sim.spawn.args, pure: no master): every argument of
gazebo_ros's spawn_model and this workspace's, which service each combination goes to, and a clear
refusal (exit status 2, the argument and the rule) for each wrong one."""

import math
import xml.etree.ElementTree as ET

import pytest

from thorvald_sim.errors import SpawnInputError
from thorvald_sim.spawn import args as spawn_args
from thorvald_sim.spawn.args import (
    GAZEBO,
    MODEL_DATABASE_TEMPLATE,
    ROBOT,
    SPAWN_MODEL,
    SPAWN_ROBOT,
    package_to_model,
    parse_args,
    prepared_xml,
    quaternion_from_rpy,
    read_file,
)

MODEL = ["-urdf", "-param", "robot_description", "-model", "thorvald_001"]


def refused(capsys, argv, prog=SPAWN_MODEL):
    """argparse's message for argv (which must exit with status 2)."""
    with pytest.raises(SystemExit) as info:
        parse_args(argv, prog)
    assert info.value.code == 2
    return capsys.readouterr().err


def test_spawn_model_defaults_are_gazebo_ros():
    args = parse_args(MODEL, SPAWN_MODEL)
    assert (args.urdf, args.sdf, args.param, args.model) == (True, False, "robot_description", "thorvald_001")
    assert (args.x, args.y, args.z, args.R, args.P, args.Y) == (0.0,) * 6
    assert args.reference_frame == "" and args.gazebo_namespace == "/gazebo"
    assert args.robot_namespace is None  # the node's namespace, read once the node runs
    assert (args.unpause, args.wait, args.package_to_model, args.bond, args.joints) == (False, None, False, False, [])
    assert (args.route, args.format, args.simulator) == (GAZEBO, "urdf", None)
    assert args.timeout == 60.0


def test_every_argument_of_gazebo_ros_spawn_model():
    argv = [
        "-sdf", "-file", "box.sdf", "-model", "box", "-reference_frame", "thorvald_001::base_link",
        "-gazebo_namespace", "/sim/gazebo", "-robot_namespace", "/box", "-unpause", "-wait", "thorvald_001",
        "-x", "1.5", "-y", "-2", "-z", "0.25", "-R", "0.1", "-P", "-0.2", "-Y", "3.1",
        "-J", "turn", "0.7", "-J", "lift", "-0.05", "-package_to_model", "-b",
    ]  # fmt: skip
    args = parse_args(argv, SPAWN_MODEL)
    assert (args.sdf, args.file, args.model, args.reference_frame) == (
        True,
        "box.sdf",
        "box",
        "thorvald_001::base_link",
    )
    assert (args.gazebo_namespace, args.robot_namespace, args.wait) == ("/sim/gazebo", "/box", "thorvald_001")
    assert (args.x, args.y, args.z, args.R, args.P, args.Y) == (1.5, -2.0, 0.25, 0.1, -0.2, 3.1)
    assert args.joints == [("turn", 0.7), ("lift", -0.05)]
    assert args.unpause and args.package_to_model and args.bond
    assert (args.route, args.format) == (GAZEBO, "sdf")


@pytest.mark.parametrize(
    "source, attribute, value",
    [
        (["-file", "m.urdf"], "file", "m.urdf"),
        (["-param", "d"], "param", "d"),
        (["-database", "pine_tree"], "database", "pine_tree"),
        (["-stdin"], "stdin", True),
    ],
)
def test_each_source(source, attribute, value):
    args = parse_args(["-sdf", *source, "-model", "m"], SPAWN_MODEL)
    assert getattr(args, attribute) == value


def test_a_namespace_given_with_a_trailing_slash_names_the_same_services():
    assert parse_args([*MODEL, "-gazebo_namespace", "/gazebo/"], SPAWN_MODEL).gazebo_namespace == "/gazebo"
    assert spawn_args.service_name("/gazebo", "spawn_urdf_model") == "/gazebo/spawn_urdf_model"


# ---- which service spawns ------------------------------------------------------------------------
def test_spawn_robot_sends_a_urdf_to_the_simulators_spawn_robot_as_it_always_has():
    args = parse_args(["-param", "robot_description", "-model", "r"], SPAWN_ROBOT)  # -urdf optional
    assert (args.route, args.format, args.simulator) == (ROBOT, "urdf", "/simulator")
    args = parse_args(["-urdf", "-file", "post.urdf", "-model", "post", "-no_publish_tf"], SPAWN_ROBOT)
    assert (args.route, args.publish_tf) == (ROBOT, 0)


def test_spawn_robot_sends_an_sdf_to_gazebos_service():
    assert parse_args(["-sdf", "-file", "box.sdf", "-model", "box"], SPAWN_ROBOT).route == GAZEBO
    assert parse_args(["-database", "pine_tree", "-model", "tree"], SPAWN_ROBOT).route == GAZEBO


@pytest.mark.parametrize(
    "extra, dest, value",
    [
        (["-simulator", "/sim2"], "simulator", "/sim2"),
        (["-command_topic", "drive_commands"], "command_topic", "drive_commands"),
        (["-publish_tf"], "publish_tf", 1),
        (["-no_publish_tf"], "publish_tf", 0),
        (["-as_built", "field:7", "-robot_model", "robot.yaml"], "as_built", "field:7"),
    ],
)
def test_spawn_model_given_a_robot_argument_goes_to_the_simulators_spawn_robot(extra, dest, value):
    args = parse_args([*MODEL, *extra], SPAWN_MODEL)
    assert (args.route, getattr(args, dest)) == (ROBOT, value)
    assert args.simulator == ("/sim2" if dest == "simulator" else "/simulator")


def test_this_workspaces_arguments_keep_their_meaning():
    args = parse_args(
        ["-param", "robot_description", "-model", "r", "-simulator", "/simulator", "-command_topic", "base_state",
         "-publish_tf", "-as_built", "field:3", "-robot_model", "r.yaml", "-timeout", "5", "-x", "2", "-Y", "0.7"],
    )  # fmt: skip
    assert (args.simulator, args.command_topic, args.publish_tf) == ("/simulator", "base_state", 1)
    assert (args.as_built, args.robot_model, args.timeout, args.x, args.Y) == ("field:3", "r.yaml", 5.0, 2.0, 0.7)
    assert parse_args(["-param", "d", "-model", "r", "-timeout", "0"]).timeout == 0.0  # for ever
    assert spawn_args.timeout_or_none(0.0) is None and spawn_args.timeout_or_none(5.0) == 5.0


# ---- refusals ------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "argv, says",
    [
        (["-param", "d", "-model", "m"], "one of the arguments -urdf -sdf is required"),
        (["-urdf", "-sdf", "-param", "d", "-model", "m"], "argument -sdf: not allowed with argument -urdf"),
        (["-urdf", "-model", "m"], "one of the arguments -file -param -database -stdin is required"),
        (["-urdf", "-file", "f", "-param", "d", "-model", "m"], "argument -param: not allowed with argument -file"),
        (["-urdf", "-param", "d"], "the following arguments are required: -model"),
        (["-urdf", "-param", "d", "-model", "a b"], "argument -model: model name 'a b': must be letters"),
        ([*MODEL, "-x", "north"], "argument -x: 'north' is not a number"),
        ([*MODEL, "-Y", "nan"], "argument -Y: 'nan': must be a finite number"),
        ([*MODEL, "-z", "inf"], "argument -z: 'inf': must be a finite number"),
        ([*MODEL, "-J", "turn"], "argument -J: expected 2 arguments"),
        ([*MODEL, "-J", "turn", "left"], "argument -J: joint 'turn': position 'left' is not a number"),
        ([*MODEL, "-J", "turn", "nan"], "argument -J: joint 'turn': position 'nan': must be a finite number"),
        ([*MODEL, "-robot_namespace", "/bad ns"], "argument -robot_namespace: robot namespace '/bad ns'"),
        ([*MODEL, "-robot_namespace", "~private"], "must not be private"),
        ([*MODEL, "-gazebo_namespace", "gazebo"], "argument -gazebo_namespace: 'gazebo': must be a global ROS name"),
        ([*MODEL, "-gazebo_namespace", "/a b"], "argument -gazebo_namespace: '/a b': must be a legal ROS name"),
        ([*MODEL, "-simulator", "sim"], "argument -simulator: 'sim': must be a global ROS name"),
        ([*MODEL, "-timeout", "-1"], "argument -timeout: '-1': must be 0 (wait for ever) or more"),
        ([*MODEL, "-publish_tf", "-no_publish_tf"], "argument -no_publish_tf: not allowed with argument -publish_tf"),
        ([*MODEL, "-wait"], "argument -wait: expected one argument"),
        ([*MODEL, "-frobnicate"], "unrecognized arguments: -frobnicate"),
        (["-sdf", "-file", "b.sdf", "-model", "b", "-command_topic", "x"], "argument -command_topic: only for a robot"),
        (["-sdf", "-file", "b.sdf", "-model", "b", "-as_built", "field:1"], "argument -as_built: only for a robot"),
        ([*MODEL, "-publish_tf", "-R", "0.1"], "argument -R/-P: must be 0: robots are spawned upright"),
        (
            [*MODEL, "-no_publish_tf", "-reference_frame", "box::link"],
            "argument -reference_frame: 'box::link': a robot spawned through the simulator's ~spawn_robot",
        ),
    ],
)
def test_a_wrong_argument_is_refused_with_exit_status_2(capsys, argv, says):
    err = refused(capsys, argv)
    assert says in err, err
    assert err.startswith("usage: spawn_model")


def test_spawn_robot_refuses_what_its_robots_cannot_take(capsys):
    assert "argument -R/-P: must be 0" in refused(capsys, ["-param", "d", "-model", "r", "-P", "0.2"], SPAWN_ROBOT)
    err = refused(capsys, ["-param", "d", "-model", "r", "-reference_frame", "box"], SPAWN_ROBOT)
    assert "argument -reference_frame: 'box'" in err and err.startswith("usage: spawn_robot")
    # the world's names are the world: accepted
    for frame in ("", "world", "map"):
        assert parse_args(["-param", "d", "-model", "r", "-reference_frame", frame]).reference_frame == frame


def test_spawn_model_takes_a_tilted_pose_and_a_reference_frame_for_gazebos_service():
    args = parse_args([*MODEL, "-R", "0.1", "-reference_frame", "box::link"], SPAWN_MODEL)
    assert (args.route, args.R, args.reference_frame) == (GAZEBO, 0.1, "box::link")


def test_an_unknown_program_name_is_a_programming_error():
    with pytest.raises(ValueError, match="spawn_model, spawn_robot"):
        spawn_args.build_parser("spawn_thing")


# ---- the model's text ------------------------------------------------------------------------------
def test_read_file_says_what_gazebo_ros_says(tmp_path):
    with pytest.raises(SpawnInputError, match=r"Error: specified file .*nothing.urdf does not exist"):
        read_file(str(tmp_path / "nothing.urdf"))
    with pytest.raises(SpawnInputError, match="is not a file"):
        read_file(str(tmp_path))
    (tmp_path / "empty.urdf").write_text("")
    with pytest.raises(SpawnInputError, match=r"Error: file .*empty.urdf is empty"):
        read_file(str(tmp_path / "empty.urdf"))
    (tmp_path / "latin1.urdf").write_bytes(b"<robot name='\xe6'/>")
    with pytest.raises(SpawnInputError, match="Error reading file"):
        read_file(str(tmp_path / "latin1.urdf"))
    (tmp_path / "m.urdf").write_text("<robot name='m'/>")
    assert read_file(str(tmp_path / "m.urdf")) == "<robot name='m'/>"


@pytest.mark.parametrize("text", ["", "<robot name='m'>", "not xml", "<robot/><robot/>"])
def test_broken_xml_is_refused_before_any_service(text):
    with pytest.raises(SpawnInputError, match=r"^Invalid XML: "):
        prepared_xml(text)


def test_the_text_is_sent_as_it_is_unless_package_to_model():
    text = "<!-- a comment --><robot name='m'><link name='a'/></robot>"
    assert prepared_xml(text) == text


def test_package_to_model_rewrites_mesh_filenames_only():
    text = (
        "<robot name='m'><link name='a'><visual><geometry><mesh filename='package://my_pkg/meshes/a.dae'"
        " scale='1 1 1'/></geometry></visual><collision><geometry><mesh filename='file:///tmp/b.stl'/>"
        "</geometry></collision><collision><geometry><mesh/></geometry></collision></link>"
        "<gazebo><uri>package://my_pkg/keep</uri></gazebo></robot>"
    )
    root = ET.fromstring(prepared_xml(text, to_model=True))
    assert [m.get("filename") for m in root.iter("mesh")] == ["model://my_pkg/meshes/a.dae", "file:///tmp/b.stl", None]
    assert root.find("gazebo/uri").text == "package://my_pkg/keep"
    assert package_to_model(ET.fromstring(text)) == 1


def test_database_sends_gazebos_template():
    text = spawn_args.database_text("pine_tree")
    assert text == MODEL_DATABASE_TEMPLATE.format("pine_tree")
    assert ET.fromstring(text).find("world/include/uri").text == "model://pine_tree"


@pytest.mark.parametrize("rpy", [(0, 0, 0), (0.1, -0.2, 3.1), (math.pi / 2, 0, 0), (0, math.pi / 2 - 1e-3, 1.0)])
def test_the_pose_is_tfs_quaternion_from_euler(rpy):
    x, y, z, w = quaternion_from_rpy(*rpy)
    assert math.isclose(x * x + y * y + z * z + w * w, 1.0)
    # back to roll, pitch, yaw (fixed axes x, y, z): the angles given
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    assert (roll, pitch, yaw) == pytest.approx(rpy, abs=1e-9)


def test_yaw_alone_turns_about_z():
    assert quaternion_from_rpy(0, 0, 0.3) == pytest.approx((0, 0, math.sin(0.15), math.cos(0.15)))


def test_the_argument_module_is_pure():
    import subprocess  # noqa: PLC0415
    import sys  # noqa: PLC0415

    code = "import sys, thorvald_sim.spawn.args; print(sorted(m for m in ('rospy', 'pybullet') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
