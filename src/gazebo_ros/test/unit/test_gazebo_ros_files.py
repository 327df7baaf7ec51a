"""gazebo_ros's files as users' launch files and scripts meet them (no ROS master): empty_world.launch
has every argument of the original with its default and starts the simulator with the ones that act;
the users'-style rostest names no simulator of ours; gazebo_interface has the original's functions;
spawn_model refuses a wrong argument with exit status 2."""

import inspect
import os
import subprocess

import pytest
import roslaunch.config
import roslaunch.xmlloader

HERE = os.path.dirname(os.path.abspath(__file__))
PACKAGE = os.path.join(HERE, "..", "..")
EMPTY_WORLD = os.path.join(PACKAGE, "launch", "empty_world.launch")
USERS_TEST = os.path.join(PACKAGE, "test", "rostest", "gazebo_users.test")

# gazebo_ros_pkgs noetic-devel, gazebo_ros/launch/empty_world.launch: every argument and its default
ORIGINAL_ARGS = {
    "paused": "false",
    "use_sim_time": "true",
    "extra_gazebo_args": "",
    "gui": "true",
    "recording": "false",
    "headless": "false",
    "debug": "false",
    "physics": "ode",
    "verbose": "false",
    "output": "screen",
    "world_name": "worlds/empty.world",
    "respawn_gazebo": "false",
    "use_clock_frequency": "false",
    "pub_clock_frequency": "100",
    "enable_ros_network": "true",
    "server_required": "false",
    "gui_required": "false",
}


def load(path, args=()):
    config = roslaunch.config.ROSLaunchConfig()
    roslaunch.xmlloader.XmlLoader().load(path, config, argv=list(args), verbose=False)
    return config


def simulator(config):
    (node,) = config.nodes
    params = {k[len("/simulator/") :]: p.value for k, p in config.params.items() if k.startswith("/simulator/")}
    return node, params


def test_empty_world_has_every_argument_of_the_original_with_its_default():
    import xml.etree.ElementTree as ET  # noqa: PLC0415

    root = ET.parse(EMPTY_WORLD).getroot()
    declared = {a.get("name"): a.get("default") for a in root.iter("arg") if a.get("default") is not None}
    assert declared == ORIGINAL_ARGS


def test_empty_world_starts_the_simulator_on_the_flat_world_with_gazebos_api(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    config = load(EMPTY_WORLD)
    node, params = simulator(config)
    assert (node.package, node.type, node.name, node.namespace) == ("thorvald_sim", "simulator", "simulator", "/")
    assert params == {"world": "flat", "gui": False, "paused": False, "clock_rate": 100, "gazebo_namespace": "/gazebo"}
    assert (node.required, node.respawn, node.output) == (False, False, "screen")
    assert config.params["/use_sim_time"].value is True
    assert config.params["/gazebo/enable_ros_network"].value is True
    assert "/gazebo/pub_clock_frequency" not in config.params  # as the original: only with use_clock_frequency


def test_the_arguments_that_act(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    config = load(
        EMPTY_WORLD,
        [
            "world_name:=tarmac_gravel", "paused:=true", "use_sim_time:=false", "pub_clock_frequency:=50",
            "use_clock_frequency:=true", "output:=log", "respawn_gazebo:=true",
        ],
    )  # fmt: skip
    node, params = simulator(config)
    assert (params["world"], params["paused"], params["clock_rate"]) == ("tarmac_gravel", True, 50)
    assert config.params["/use_sim_time"].value is False
    assert config.params["/gazebo/pub_clock_frequency"].value == 50
    assert (node.respawn, node.output) == (True, "log")
    node, _ = simulator(load(EMPTY_WORLD, ["server_required:=true"]))
    assert node.required


@pytest.mark.parametrize(
    "world, expected",
    [
        ("worlds/empty.world", "flat"),
        ("empty.world", "flat"),
        ("slope", "slope"),
        ("/data/my_field.yaml", "/data/my_field.yaml"),
    ],
)
def test_world_name(monkeypatch, world, expected):
    monkeypatch.delenv("DISPLAY", raising=False)
    assert simulator(load(EMPTY_WORLD, [f"world_name:={world}"]))[1]["world"] == expected


@pytest.mark.parametrize("display, gui, window", [(":0", "true", True), (":0", "false", False), ("", "true", False)])
def test_gui_is_pybullets_window_where_there_is_a_display(monkeypatch, display, gui, window):
    monkeypatch.setenv("DISPLAY", display)
    assert simulator(load(EMPTY_WORLD, [f"gui:={gui}"]))[1]["gui"] is window


def test_the_inert_arguments_are_accepted_and_change_nothing(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    plain = simulator(load(EMPTY_WORLD))
    inert = simulator(
        load(
            EMPTY_WORLD,
            [
                "headless:=true", "debug:=true", "recording:=true", "verbose:=true", "physics:=bullet",
                "extra_gazebo_args:=--lockstep", "gui_required:=true", "enable_ros_network:=false",
            ],
        )
    )  # fmt: skip
    assert inert[1] == plain[1]
    assert (inert[0].args, inert[0].required, inert[0].respawn) == (plain[0].args, plain[0].required, plain[0].respawn)


def test_the_users_test_is_a_gazebo_file_naming_no_simulator_of_ours(monkeypatch):
    with open(USERS_TEST, encoding="utf-8") as f:
        text = f.read()
    assert "thorvald_sim" not in text
    assert "$(find gazebo_ros)/launch/empty_world.launch" in text
    monkeypatch.delenv("DISPLAY", raising=False)
    config = load(USERS_TEST)
    spawns = {
        n.namespace + n.name: n.args for n in config.nodes if (n.package, n.type) == ("gazebo_ros", "spawn_model")
    }
    robot = spawns["/thorvald_001/spawner"].split()
    assert robot[:5] == ["-urdf", "-param", "robot_description", "-model", "thorvald_001"]
    assert "-sdf -file" in spawns["/spawn_box"] and "-J turn 0.7 -b" in spawns["/spawn_turntable"]


def test_gazebo_interface_has_the_originals_functions():
    from gazebo_ros import gazebo_interface  # noqa: PLC0415

    params = {
        "spawn_sdf_model_client": "model_name model_xml robot_namespace initial_pose reference_frame gazebo_namespace",
        "spawn_urdf_model_client": "model_name model_xml robot_namespace initial_pose reference_frame gazebo_namespace",
        "set_model_configuration_client": "model_name model_param_name joint_names joint_positions gazebo_namespace",
    }
    for name, args in params.items():
        assert list(inspect.signature(getattr(gazebo_interface, name)).parameters) == args.split(), name
    # the names the original's star imports gave its users
    for name in ("ModelState", "SpawnModel", "GetModelState", "Pose", "Point", "Quaternion", "Twist", "Wrench"):
        assert hasattr(gazebo_interface, name), name


@pytest.mark.slow
@pytest.mark.parametrize(
    "args, says",
    [
        (["-param", "robot_description", "-model", "r"], "one of the arguments -urdf -sdf is required"),
        (["-urdf", "-param", "d", "-model", "r", "-J", "turn", "half"], "position 'half' is not a number"),
        (["-sdf", "-file", "b.sdf", "-model", "b", "-no_publish_tf"], "argument -no_publish_tf: only for a robot"),
    ],
)  # fmt: skip
def test_spawn_model_refuses_a_wrong_argument_without_a_master(args, says):
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:1")  # nothing listens: no master is needed
    script = os.path.join(PACKAGE, "scripts", "spawn_model")
    done = subprocess.run([script, *args], capture_output=True, text=True, env=env, timeout=60)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("usage: spawn_model") and says in done.stderr, done.stderr
