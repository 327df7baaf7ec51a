"""The robot configuration loader: one test per rule, each asserting the dotted key path."""

import math
import os

import pytest
import yaml
from model_test_helpers import EXAMPLE_ROBOTS, FIGURE5, std_drive

from thorvald_model import (
    ConfigError,
    config_to_dict,
    load_robot_config,
    parse_robot_config,
    with_drive_param,
    with_drive_params,
)
from thorvald_model.config import STD_CALCULATOR


def problems_of(data):
    with pytest.raises(ConfigError) as info:
        parse_robot_config(data, "robot.yaml")
    return info.value.problems


def assert_problem(data, path, *words):
    """Loading data fails with a problem at path whose rule mentions every word."""
    problems = problems_of(data)
    matching = [p for p in problems if p.path == path]
    assert matching, f"no problem at {path}; got {[(p.path, p.rule) for p in problems]}"
    for word in words:
        assert any(word in p.rule for p in matching), (word, [p.rule for p in matching])
    return matching[0]


# --- the file as a whole ---------------------------------------------------------------------
def test_valid_robot_loads_in_si_units(robot):
    config = parse_robot_config(robot, "robot.yaml")
    assert len(config.drives) == 4
    d = config.drives[1]
    assert (d.name, d.index, d.node, d.x, d.y) == ("drive1", 1, 2, 0.547, -0.30)
    # Defaults are the standard Thorvald II module: 3000 rpm motor, 42:1 gear, 0.2 m wheel.
    assert d.r_wheel == 0.2 and d.prp_gr_rt == 42.0 and d.prp_max_rpm == 3000.0
    # 3000 rpm / 42 = 71.43 wheel rpm = 7.480 rad/s; times 0.2 m = 1.496 m/s
    assert d.max_wheel_speed == pytest.approx(1.496, abs=1e-3)
    assert (d.steering_name, d.wheel_name) == ("steering1", "wheel1")
    assert config.track == pytest.approx(0.6) and config.wheelbase == pytest.approx(1.094)


def test_calculator_defaults_to_the_standard_plugin(robot):
    del robot["base_calculator"]
    assert parse_robot_config(robot).base_calculator == STD_CALCULATOR


def test_top_level_must_be_a_mapping():
    assert_problem(["drive0"], "", "mapping")


def test_unknown_top_level_key_suggests_the_right_one(robot):
    robot["motor_drive"] = robot.pop("motor_drives")
    p = assert_problem(robot, "motor_drive", "unknown key", "did you mean 'motor_drives'?")
    assert p.value == robot["motor_drive"] or isinstance(p.value, str)


def test_unknown_drive_key_suggests_the_right_one(robot):
    robot["motor_drives"]["drive2"]["r_wheeel"] = 0.2
    p = assert_problem(robot, "motor_drives.drive2.r_wheeel", "did you mean 'r_wheel'?")
    assert p.value == 0.2


def test_sensor_keys_of_user_extras_pass_through(robot):
    robot["lidar_front"] = {"x": 1.0, "parent_link": "top0"}
    config = parse_robot_config(robot)
    assert dict(config.extras)["lidar_front"]["parent_link"] == "top0"


def test_ignored_keys_let_a_node_parse_its_private_namespace(robot):
    robot["simple_sim"] = True
    robot["tf_prefix"] = "robot_1/"
    assert [w.path for w in parse_robot_config(dict(robot)).warnings] == ["simple_sim", "tf_prefix"]
    config = parse_robot_config(robot, ignore=("simple_sim", "tf_prefix"))
    assert len(config.drives) == 4 and config.warnings == ()


# --- keys we do not know: a typing mistake is an error, the user's own keys are kept -----------------
def test_unknown_keys_unlike_ours_are_kept_with_a_warning(robot, caplog):
    """As the original, which ignored keys it did not know; kept, so a user's xacro extras can read
    them from the configuration the model gets (to_dict), and said once."""
    robot["sensor_mast"] = {"height": 2.1}
    robot["motor_drives"]["drive1"]["hub_motor_make"] = "ACME"
    robot["batteries"] = {"bat0": {"id": 1, "colour_code": 7}}
    source = "kept_keys_robot.yaml"
    with caplog.at_level("WARNING", logger="thorvald_model"):
        config = parse_robot_config(robot, source)
        parse_robot_config(config_to_dict(config), source)  # loaded again: no second warning
    assert [(w.path, w.value) for w in config.warnings] == [
        ("sensor_mast", {"height": 2.1}),
        ("motor_drives.drive1.hub_motor_make", "ACME"),
        ("batteries.bat0.colour_code", 7),
    ]
    assert all("unknown key, kept" in w.rule for w in config.warnings)
    assert sorted(r.getMessage() for r in caplog.records) == sorted(w.format(source) for w in config.warnings)
    out = config_to_dict(config)
    assert out["sensor_mast"] == {"height": 2.1}
    assert out["motor_drives"]["drive1"]["hub_motor_make"] == "ACME"
    assert out["batteries"]["bat0"]["colour_code"] == 7
    assert "hub_motor_make" not in out["motor_drives"]["drive0"]


@pytest.mark.parametrize(
    "path, key, meant",
    [
        (("motor_drives", "drive2"), "r_wheeel", "r_wheel"),
        (("motor_drives", "drive0"), "prp_gr_rate", "prp_gr_rt"),
        ((), "motor_drive", "motor_drives"),
        ((), "batterys", "batteries"),
        (("batteries", "bat0"), "with_batery", "with_battery"),
    ],
)
def test_a_key_like_one_of_ours_stays_an_error(robot, path, key, meant):
    robot["batteries"] = {"bat0": {"id": 1}}
    entry = robot
    for part in path:
        entry = entry[part]
    entry[key] = entry.get(meant, 1) if path else entry.pop(meant, {"bat0": {"id": 1}})
    assert_problem(robot, ".".join((*path, key)), f"did you mean '{meant}'?")


def test_sensor_keys_of_users_stay_silent(robot):
    robot["imu"] = {"parent_link": "top0"}
    assert parse_robot_config(robot).warnings == ()


# --- values ----------------------------------------------------------------------------------
def test_required_drive_keys(robot):
    del robot["motor_drives"]["drive0"]["node"]
    del robot["motor_drives"]["drive3"]["y"]
    problems = problems_of(robot)
    paths = {p.path: p for p in problems}
    assert paths["motor_drives.drive0.node"].rule == "is required"
    assert paths["motor_drives.drive3.y"].rule == "is required"


@pytest.mark.parametrize("bad", ["abc", float("nan"), float("inf"), True, [1.0], None])
def test_numbers_must_be_finite_numbers(robot, bad):
    robot["motor_drives"]["drive1"]["x"] = bad
    p = assert_problem(robot, "motor_drives.drive1.x", "finite number")
    assert p.value is bad


def test_numbers_written_as_strings_load_as_numbers(robot):
    robot["motor_drives"]["drive1"]["x"] = "0.547"
    robot["motor_drives"]["drive1"]["node"] = "2"
    robot["pipes"] = {"pipe0": {"x1": "-0.425", "y1": "0.3", "x2": "0.425", "y2": "0.3", "height": "0.65"}}
    config = parse_robot_config(robot)
    assert config.drives[1].x == 0.547 and config.drives[1].node == 2
    assert config.pipes[0].x1 == -0.425 and config.pipes[0].length == pytest.approx(0.85)


def test_integers_must_be_whole(robot):
    robot["motor_drives"]["drive1"]["node"] = 2.5
    assert_problem(robot, "motor_drives.drive1.node", "integer")


def test_figure5_spellings_are_aliases(robot):
    robot["motor_drives"]["drive0"].update(prp_slm_e=2.5, str_slm_v=3.0)
    d = parse_robot_config(robot).drives[0]
    assert (d.prp_sim_a, d.str_sim_v) == (2.5, 3.0)


def test_alias_and_key_together_are_refused(robot):
    robot["motor_drives"]["drive0"].update(prp_slm_e=2.5, prp_sim_a=1.5)
    problems = problems_of(robot)
    assert any(p.path.startswith("motor_drives.drive0.prp_s") and "already given" in p.rule for p in problems)


@pytest.mark.parametrize("value", [0, -0.1, 3.2, 4.0])
def test_str_lim_within_zero_and_pi(robot, value):
    robot["motor_drives"]["drive2"]["str_lim"] = value
    assert_problem(robot, "motor_drives.drive2.str_lim", "(0, pi]")


def test_str_lim_of_exactly_pi_is_allowed(robot):
    robot["motor_drives"]["drive2"]["str_lim"] = math.pi
    assert parse_robot_config(robot).drives[2].str_lim == math.pi


@pytest.mark.parametrize(
    "key", ["r_wheel", "w_wheel", "prp_gr_rt", "prp_enc_ppr", "prp_max_rpm", "prp_sim_a", "str_gr_rt", "str_sim_v"]
)
@pytest.mark.parametrize("value", [0, -1])
def test_module_parameters_must_be_positive(robot, key, value):
    robot["motor_drives"]["drive1"][key] = value
    assert_problem(robot, "motor_drives.drive1." + key, "> 0")


def test_steering_offset_is_a_homing_error_of_at_most_0_2_rad(robot):
    assert parse_robot_config(robot).drives[1].steering_offset == 0.0  # default: homed exactly
    robot["motor_drives"]["drive1"]["steering_offset"] = -0.2
    assert parse_robot_config(robot).drives[1].steering_offset == -0.2
    robot["motor_drives"]["drive1"]["steering_offset"] = 0.21
    problem = assert_problem(robot, "motor_drives.drive1.steering_offset", "within +-0.2 rad")
    assert problem.value == 0.21


def test_a_drive_that_does_not_steer_has_no_steering_offset(robot):
    # the rear axle (drive0, drive2) of type-1 drives on one controller
    robot["motor_drives"]["drive0"].update(type=1, node=5)
    robot["motor_drives"]["drive2"].update(type=1, node=5, steering_offset=0.01)
    problem = assert_problem(robot, "motor_drives.drive2.steering_offset", "must be 0", "does not steer")
    assert problem.value == 0.01
    robot["motor_drives"]["drive2"]["steering_offset"] = 0.0
    assert parse_robot_config(robot).drives[2].steering_offset == 0.0


def test_steering_offset_may_change_while_the_robot_runs(robot):
    from thorvald_model.config import RUNTIME_DRIVE_KEYS  # noqa: PLC0415

    assert "steering_offset" in RUNTIME_DRIVE_KEYS
    config = with_drive_param(parse_robot_config(robot), 2, "steering_offset", 0.05)
    assert config.drives[2].steering_offset == 0.05
    assert config_to_dict(config)["motor_drives"]["drive2"]["steering_offset"] == 0.05


def test_drive_type_is_0_or_1(robot):
    robot["motor_drives"]["drive1"]["type"] = 2
    assert_problem(robot, "motor_drives.drive1.type", "0 (propulsion/steering) or 1")


@pytest.mark.parametrize("node", [0, 128, -1])
def test_node_is_a_canopen_id(robot, node):
    robot["motor_drives"]["drive1"]["node"] = node
    assert_problem(robot, "motor_drives.drive1.node", "1..127")


# --- naming of entries -----------------------------------------------------------------------
def test_section_must_be_a_mapping(robot):
    robot["batteries"] = [1, 2]
    assert_problem(robot, "batteries", "mapping of bat0, bat1")


def test_entry_must_be_a_mapping(robot):
    robot["motor_drives"]["drive3"] = 7
    assert_problem(robot, "motor_drives.drive3", "mapping of keys")


@pytest.mark.parametrize("name", ["wheel4", "drive04", "drive", "Drive4"])
def test_entries_named_prefix_and_number(robot, name):
    robot["motor_drives"][name] = std_drive(9, 2.0, 2.0)
    assert_problem(robot, "motor_drives." + name, "named drive0, drive1")


def test_drives_numbered_without_gaps(robot):
    # The original reads drive0, drive1, ... until one is missing: drive3 after a gap would be lost.
    robot["motor_drives"]["drive5"] = robot["motor_drives"].pop("drive3")
    assert_problem(robot, "motor_drives.drive3", "without gaps", "drive5")


def test_a_gap_says_which_entries_the_original_would_drop(robot):
    drives = robot["motor_drives"]
    drives["drive4"], drives["drive6"] = drives.pop("drive2"), drives.pop("drive3")
    p = assert_problem(robot, "motor_drives.drive2", "without gaps")
    assert "stop after drive0, drive1 at the missing drive2, and drive4, drive6 would be dropped" in p.rule
    robot["motor_drives"] = {"drive1": drives["drive1"]}
    p = assert_problem(robot, "motor_drives.drive0", "without gaps")
    assert "stop after none at the missing drive0, and drive1 would be dropped" in p.rule


# --- cross-field rules -----------------------------------------------------------------------
def test_at_least_one_driven_wheel(robot):
    del robot["motor_drives"]
    assert_problem(robot, "motor_drives", "at least one driven wheel")


def test_empty_motor_drives_has_no_driven_wheel(robot):
    robot["motor_drives"] = {}
    assert_problem(robot, "motor_drives", "at least one driven wheel")


def test_type1_drives_come_in_pairs_on_one_node(robot):
    robot["motor_drives"]["drive0"].update(type=1, node=5)
    robot["motor_drives"]["drive2"].update(type=1, node=6)
    assert_problem(robot, "motor_drives.drive0.node", "pairs on one controller node")
    assert_problem(robot, "motor_drives.drive2.node", "pairs on one controller node")


def test_type1_pair_does_not_share_with_a_type0_drive(robot):
    robot["motor_drives"]["drive0"].update(type=1, node=1)
    robot["motor_drives"]["drive2"].update(type=1, node=1)
    robot["motor_drives"]["drive1"].update(node=1)
    assert_problem(robot, "motor_drives.drive0.node", "pairs on one controller node")


def test_type0_drives_each_have_their_own_controller(robot):
    robot["motor_drives"]["drive3"]["node"] = 2
    assert_problem(robot, "motor_drives.drive3.node", "controller of its own", "drive1")


def test_no_two_drives_at_one_spot(robot):
    robot["motor_drives"]["drive3"].update(x=0.547, y=-0.30)
    assert_problem(robot, "motor_drives.drive3", "no two wheels at one spot", "drive1")


def test_passive_wheel_not_on_a_drive(robot):
    robot["passive_wheels"] = {"passive0": {"type": "caster", "x": 0.547, "y": 0.30}}
    assert_problem(robot, "passive_wheels.passive0", "no two wheels at one spot")


def test_steered_wheels_must_not_collide(robot):
    # Swept radius of a 0.2 m wheel, 0.16 m wide: hypot(0.2, 0.08) = 0.2154 m; two need 0.431 m.
    robot["motor_drives"]["drive3"].update(x=0.547, y=-0.30 + 0.40)
    assert_problem(robot, "motor_drives.drive3", "collide", "0.431")


def test_caster_must_not_sweep_into_a_steered_wheel(robot):
    # drive reach hypot(0.2, 0.08) = 0.21541 m; caster hypot(0.1, 0.025) = 0.10308 m + 0.05 m trail: 0.36849 m
    robot["passive_wheels"] = {"passive0": {"type": "caster", "x": 0.547 + 0.30, "y": 0.30}}
    assert_problem(robot, "passive_wheels.passive0", "collide", "0.368")
    robot["passive_wheels"]["passive0"]["x"] = 0.547 + 0.40
    parse_robot_config(robot)


def test_calculator_name_format(robot):
    robot["base_calculator"] = "PltfClcStd"
    assert_problem(robot, "base_calculator", "calculator class")


def test_calculator_of_another_package_passes_the_loader(robot):
    robot["base_calculator"] = "my_pkg::MyCalculator"
    assert parse_robot_config(robot).base_calculator == "my_pkg::MyCalculator"
    robot["base_calculator"] = "my_pkg.calculators:MyCalculator"
    assert parse_robot_config(robot).base_calculator == "my_pkg.calculators:MyCalculator"


def test_wheels_that_cannot_steer_share_one_axle(robot):
    robot["motor_drives"]["drive0"].update(type=1, node=5)
    robot["motor_drives"]["drive2"].update(type=1, node=5, x=-0.3)
    assert_problem(robot, "motor_drives.drive2", "share one axle line", "drive0")


def test_fixed_passive_wheel_yaw_sets_its_axle(robot):
    # Two fixed wheels at x = -0.547 rolling along x share the axle line x = -0.547 ...
    robot["passive_wheels"] = {
        "passive0": {"type": "fixed", "x": -0.547, "y": 0.8},
        "passive1": {"type": "fixed", "x": -0.547, "y": -0.8},
    }
    parse_robot_config(robot)
    # ... but turned 90 degrees their axles run along x, two different lines.
    robot["passive_wheels"]["passive1"]["yaw"] = math.pi / 2
    assert_problem(robot, "passive_wheels.passive1", "share one axle line")


# The layouts each calculator can serve are its own rules: thorvald_base's test_layout_rules.py.


def test_beams_join_existing_drives(robot):
    robot["beams"] = {"beam0": {"start": "drive0", "end": "drive9"}, "beam1": {"start": "drive1", "end": "drive1"}}
    assert_problem(robot, "beams.beam0.end", "must name a drive")
    assert_problem(robot, "beams.beam1.end", "must differ from start")


def test_suspension_carries_an_existing_drive_once(robot):
    robot["suspensions"] = {
        "susp0": {"drive": "drive0"},
        "susp1": {"drive": "drive0"},
        "susp2": {"drive": "drive7"},
    }
    assert_problem(robot, "suspensions.susp1.drive", "already carries")
    assert_problem(robot, "suspensions.susp2.drive", "must name a drive")


def test_suspension_is_attached_to_its_drive(robot):
    robot["suspensions"] = {"susp0": {"drive": "drive2", "travel": 0.12}}
    config = parse_robot_config(robot)
    assert config.drives[2].suspension.travel == 0.12
    assert config.drives[0].suspension is None


def test_battery_node_is_the_deprecated_id(robot):
    robot["batteries"] = {
        "bat0": {"node": 345, "type": 1, "x": 0.0, "y": 0.445, "z": 0.72, "yaw": 0, "bat_mesh": 0},
        "bat1": {"node": -1, "type": 0, "x": 0.0, "y": -0.445, "z": 0.72, "yaw": 0, "bat_mesh": 1},
    }
    config = parse_robot_config(robot)
    assert [b.id for b in config.batteries] == [1, -1]  # id = node - 344


def test_battery_id_or_node_not_both(robot):
    robot["batteries"] = {"bat0": {"node": 345, "id": 1}}
    assert_problem(robot, "batteries.bat0.node", "not both")


def test_kc_battery_needs_an_id(robot):
    robot["batteries"] = {"bat0": {"type": 1}}
    assert_problem(robot, "batteries.bat0.id", "needs an id")


def test_battery_ids_are_unique(robot):
    robot["batteries"] = {"bat0": {"id": 2}, "bat1": {"id": 2, "y": -0.4}}
    assert_problem(robot, "batteries.bat1.id", "also used by bat0")


def test_io_board_ids_are_unique(robot):
    robot["io"] = {"io0": {"id": 0}, "io1": {"id": 0, "type": 1}}
    assert_problem(robot, "io.io1.id", "also used by io0")


def test_io_board_type(robot):
    robot["io"] = {"io0": {"id": 0, "type": 5}}
    assert_problem(robot, "io.io0.type", "UV lamp")


def test_the_main_io_board_is_on_the_bus_without_an_io_section(robot):
    """The original's default board: a robot file without io still has the main enclosure PCB on
    its CAN bus (id 0, type 0, relays off at start); an io section replaces it."""
    config = parse_robot_config(robot)
    assert config.io == ()
    (main,) = config.io_boards_on_bus
    assert (main.id, main.type, main.rl0_init_state, main.rl1_init_state) == (0, 0, False, False)
    assert main.is_main
    robot["io"] = {"io0": {"id": 3, "type": 1}, "io1": {"id": 5, "type": 0, "rl1_init_state": 1}}
    config = parse_robot_config(robot)
    assert [(b.id, b.is_main) for b in config.io_boards_on_bus] == [(3, False), (5, True)]
    assert config.io_boards_on_bus == config.io


def test_pipe_ends_differ(robot):
    robot["pipes"] = {"pipe0": {"x1": 0.3, "y1": 0.3, "x2": 0.3, "y2": 0.3}}
    assert_problem(robot, "pipes.pipe0", "two ends must differ")


def test_passive_wheel_type(robot):
    robot["passive_wheels"] = {"passive0": {"type": "swivel", "x": -1.0, "y": 0.0}}
    assert_problem(robot, "passive_wheels.passive0.type", "'caster' or 'fixed'")


def test_frame_part_needs_the_dimensions_of_its_shape(robot):
    robot["frame_parts"] = {
        "part0": {"shape": "box", "size_x": 1.0, "size_y": 0.1, "mass": 5},
        "part1": {"shape": "cylinder", "radius": 0.02, "length": 1.0, "size_x": 1.0, "mass": 2},
        "part2": {"shape": "cone", "mass": 1},
        "part3": {"shape": "sphere", "radius": 0.1, "mass": 1, "color": "pink"},
    }
    assert_problem(robot, "frame_parts.part0.size_z", "a box needs size_x, size_y, size_z")
    assert_problem(robot, "frame_parts.part1.size_x", "a cylinder has only radius, length")
    assert_problem(robot, "frame_parts.part2.shape", "'box', 'cylinder' or 'sphere'")
    assert_problem(robot, "frame_parts.part3.color", "must be one of")


def test_frame_part_mass_is_required_and_positive(robot):
    robot["frame_parts"] = {
        "part0": {"shape": "sphere", "radius": 0.1},
        "part1": {"shape": "sphere", "radius": 0.1, "mass": 0},
    }
    assert_problem(robot, "frame_parts.part0.mass", "is required")
    assert_problem(robot, "frame_parts.part1.mass", "> 0")


# --- all problems at once, messages ----------------------------------------------------------
def test_several_mistakes_are_reported_together(robot):
    robot["motor_drives"]["drive0"]["str_lim"] = 4.0
    robot["motor_drives"]["drive1"]["r_wheel"] = -0.2
    robot["motor_drives"]["drive2"]["str_sim_vel"] = 4.0
    robot["motor_drives"]["drive3"]["node"] = 1
    robot["batteries"] = {"bat0": {"type": 3, "id": 1}}
    with pytest.raises(ConfigError) as info:
        parse_robot_config(robot, "my_robot.yaml")
    paths = [p.path for p in info.value.problems]
    assert paths == [
        "motor_drives.drive0.str_lim",
        "motor_drives.drive1.r_wheel",
        "motor_drives.drive2.str_sim_vel",
        "batteries.bat0.type",
        "motor_drives.drive3.node",
    ]
    text = str(info.value)
    assert text.startswith("my_robot.yaml: invalid robot configuration (5 problems):")
    # each line names the file, the dotted path, the value and the rule
    assert "my_robot.yaml: motor_drives.drive0.str_lim: 4.0: must be in (0, pi] [rad]" in text
    assert "my_robot.yaml: motor_drives.drive1.r_wheel: -0.2: must be > 0" in text


def test_yaml_syntax_error_names_the_line(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("motor_drives:\n  drive0: {node: 1, x: 0\n")
    with pytest.raises(ConfigError) as info:
        load_robot_config(str(path))
    assert "not valid YAML at line" in str(info.value)
    assert str(path) in str(info.value)


def unreadable(path):
    """The one-line message load_robot_config gives for a file it cannot read."""
    with pytest.raises(ConfigError) as info:
        load_robot_config(str(path))
    text = str(info.value)
    assert "\n" not in text, text
    assert text.startswith(f"{path}: ")
    return text


def test_missing_file(tmp_path):
    assert unreadable(tmp_path / "nope.yaml").endswith("cannot read the robot configuration: No such file or directory")


def test_directory(tmp_path):
    (tmp_path / "robot.yaml").mkdir()
    assert unreadable(tmp_path / "robot.yaml").endswith("cannot read the robot configuration: Is a directory")


def test_file_that_is_not_utf8(tmp_path):
    path = tmp_path / "latin1.yaml"
    path.write_bytes("motor_drives: {drive0: {node: 1, x: 0, y: 0}}  # Ås\n".encode("latin-1"))
    # "Å" is 0xc5 in Latin-1; in UTF-8 it would start a two-byte sequence that "s" cannot continue
    offset = path.read_bytes().index(b"\xc5")
    assert unreadable(path).endswith(
        f"not a text file: byte 0xc5 at offset {offset} is not UTF-8 (invalid continuation byte)"
    )


def test_binary_file(tmp_path):
    path = tmp_path / "robot.yaml"
    path.write_bytes(b"motor_drives: \x00\x01\x02")
    assert "character #x0000 at offset 14 is not allowed in a YAML file" in unreadable(path)


def test_a_problem_of_the_content_keeps_the_multi_line_report(tmp_path):
    path = tmp_path / "robot.yaml"
    path.write_text("motor_drives: {drive0: {node: 1, x: 0, y: 0, r_wheel: -1}}\n")
    with pytest.raises(ConfigError) as info:
        load_robot_config(str(path))
    assert str(info.value).splitlines()[1].strip() == f"{path}: motor_drives.drive0.r_wheel: -1: must be > 0"


def test_drives_sharing_a_controller_get_its_channels_in_file_order():
    config = parse_robot_config(
        {
            "motor_drives": {
                "drive0": {"node": 7, "x": 0.0, "y": -0.3, "type": 1},
                "drive1": {"node": 2, "x": 0.8, "y": 0.0},
                "drive2": {"node": 7, "x": 0.0, "y": 0.3, "type": 1},
            }
        }
    )
    assert [d.channel for d in config.drives] == [1, 1, 2]
    assert [d.max_steering_speed for d in config.drives] == [0.0, 4.0, 0.0]


# --- the paper's figure and the example robots -------------------------------------------------
def test_paper_figure5_loads_as_printed():
    config = load_robot_config(FIGURE5)
    assert [(d.x, d.y) for d in config.drives] == [(-0.547, -0.30), (0.547, -0.30), (-0.547, 0.30), (0.547, 0.30)]
    assert all(d.prp_sim_a == 1.5 and d.str_sim_v == 4.0 for d in config.drives)
    assert all(d.str_lim == 3.078027759 and d.str_gr_rt == 42.8571429 for d in config.drives)


def test_every_example_robot_of_the_paper_is_there():
    names = {os.path.basename(p)[:-5] for p in EXAMPLE_ROBOTS}
    assert len(names) >= 10, names
    assert "thorvald_ii_4wd4ws_std" in names


@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: os.path.basename(p)[:-5])
def test_example_robot_loads(path):
    config = load_robot_config(path)
    assert config.drives
    # The file's folder is its name, as the original's thorvald_model/config/<model>/<model>.yaml.
    assert os.path.basename(os.path.dirname(path)) == os.path.basename(path)[:-5]


def test_standard_example_robot_is_figure5():
    std = next(p for p in EXAMPLE_ROBOTS if p.endswith("thorvald_ii_4wd4ws_std.yaml"))
    assert load_robot_config(std).drives == load_robot_config(FIGURE5).drives


@pytest.mark.parametrize("path", [*EXAMPLE_ROBOTS, FIGURE5], ids=lambda p: os.path.basename(p)[:-5])
def test_to_dict_round_trips(path):
    config = load_robot_config(path)
    again = parse_robot_config(yaml.safe_load(yaml.safe_dump(config_to_dict(config))), config.source)
    assert again == config


def test_drive_parameter_changed_at_run_time(robot):
    config = parse_robot_config(robot)
    changed = with_drive_param(config, 2, "r_wheel", 0.25)
    assert changed.drives[2].r_wheel == 0.25
    assert config.drives[2].r_wheel == 0.2  # frozen: the original stays as it was
    with pytest.raises(ConfigError) as info:
        with_drive_param(config, 2, "r_wheel", -1)
    assert info.value.problems[0].path == "motor_drives.drive2.r_wheel"


def test_drive_parameters_changed_together_are_the_changes_one_by_one(robot):
    config = parse_robot_config(robot)
    changes = [(0, "r_wheel", 0.21), (2, "steering_offset", 0.01), (3, "r_wheel", 0.19)]
    one_by_one = config
    for index, key, value in changes:
        one_by_one = with_drive_param(one_by_one, index, key, value)
    assert with_drive_params(config, changes) == one_by_one
    assert with_drive_params(config, []) is config
    with pytest.raises(ConfigError) as info:
        with_drive_params(config, [(0, "r_wheel", 0.21), (9, "r_wheel", 0.2)])
    assert info.value.problems[0].path == "motor_drives.drive9"
