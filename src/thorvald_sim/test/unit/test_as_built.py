"""The as-built file and profile (thorvald_sim.physics.as_built): validated like a robot file, the profile
seeded and within its tolerances, encoder quantisation in whole counts. Pure: no pybullet, no ROS."""

import math
import os

import pytest

from thorvald_base.can.protocol import DriveScaling
from thorvald_model import load_robot_config
from thorvald_model.errors import ConfigError
from thorvald_sim.physics.as_built import (
    SimAsBuilt,
    as_built_for,
    as_configured,
    describe_as_built,
    draw_as_built,
    for_simulator,
    load_as_built,
    parse_as_built,
    quantise,
)

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIGS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "thorvald_model", "config"))


def robot(name):
    return load_robot_config(os.path.join(CONFIGS, name, name + ".yaml"))


STD_PATH = os.path.join(CONFIGS, "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
STD = robot("thorvald_ii_4wd4ws_std")  # four steered drives, r_wheel 0.2 ... as configured
DIFF = robot("thorvald_ii_2wd_diff")  # two drives that do not steer


def problems_of(data, config=STD):
    with pytest.raises(ConfigError) as e:
        parse_as_built(data, config, "built.yaml")
    assert "built.yaml" in str(e.value) and "as-built file" in str(e.value)
    return {p.path: p for p in e.value.problems}


def test_an_empty_file_is_the_robot_as_configured():
    built = parse_as_built(None, STD)
    assert built.drives == as_configured(STD).drives
    assert built.ideal and built.differences() == {}
    assert [d.r_wheel for d in built.drives] == [d.r_wheel for d in STD.drives]
    assert [d.name for d in built.drives] == [f"drive{i}" for i in range(len(STD.drives))]


def test_a_file_in_the_robot_files_shape():
    r0 = STD.drives[0].r_wheel
    built = parse_as_built(
        {
            "motor_drives": {"drive0": {"r_wheel": r0 * 1.01, "steering_offset": 0.005}, "drive2": {"r_wheel": 0.199}},
            "encoders": True,
            "delay": 0.02,
            "mass_offset": 30,
        },
        STD,
    )
    assert built.drive("drive0").r_wheel == pytest.approx(r0 * 1.01)
    assert built.drive("drive0").steering_offset == 0.005
    assert built.drive("drive1").r_wheel == STD.drives[1].r_wheel and built.drive("drive1").steering_offset == 0
    assert (built.encoders, built.delay, built.mass_offset) == (True, 0.02, 30.0)
    assert built.differences() == {
        "drive0": {"r_wheel": pytest.approx(r0 * 1.01), "steering_offset": 0.005},
        "drive2": {"r_wheel": 0.199},
    }
    assert not built.ideal


def test_every_problem_with_its_key_path_value_and_rule():
    found = problems_of(
        {
            "motor_drives": {
                "drive0": {"r_wheel": 0.5},  # 150 % of 0.2
                "drive1": {"steering_offset": 0.3},
                "drive7": {"r_wheel": 0.2},
                "drive2": {"r_wheeel": 0.2},
            },
            "delay": -1,
            "mass_offset": -5,
            "encoder": True,
        }
    )
    assert "within 20% of the configured r_wheel" in found["motor_drives.drive0.r_wheel"].rule
    assert found["motor_drives.drive1.steering_offset"].value == 0.3
    assert "not a drive of the robot (it has drive0, drive1, drive2, drive3)" in found["motor_drives.drive7"].rule
    assert "did you mean 'r_wheel'" in found["motor_drives.drive2.r_wheeel"].rule
    assert found["delay"].value == -1 and found["mass_offset"].value == -5
    assert "did you mean 'encoders'" in found["encoder"].rule


def test_a_drive_that_does_not_steer_has_no_steering_offset():
    found = problems_of({"motor_drives": {"drive1": {"steering_offset": 0.01}}}, DIFF)
    assert found["motor_drives.drive1.steering_offset"].rule == "must be 0: this drive does not steer"


def test_a_file_that_is_not_a_mapping_or_not_yaml(tmp_path):
    assert problems_of([1, 2])[""].rule == "the file must hold a mapping of keys"
    bad = tmp_path / "bad.yaml"
    bad.write_text("motor_drives: [\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_as_built(str(bad), STD)


def test_the_field_profile_is_seeded_and_within_its_tolerances():
    a, b, c = draw_as_built("field:1", STD), draw_as_built("field:1", STD), draw_as_built("field:2", STD)
    assert a == b and a != c and a.encoders and a.source == "field:1"
    for built in (a, c):
        # the loaded tyres: 1 to 2 % below the configured radius, one draw for the robot
        assert 0.01 <= built.loaded <= 0.02
        for d, conf in zip(built.drives, STD.drives):
            # then +-1 % per tyre
            assert abs(d.r_wheel / (conf.r_wheel * (1 - built.loaded)) - 1) <= 0.01
            assert abs(d.steering_offset) <= math.radians(0.5)
    # over many seeds the draws fill their tolerances (uniform): not all the same, both signs
    drawn = [draw_as_built(f"field:{s}", STD) for s in range(200)]
    scales = [d.drives[0].r_wheel / (STD.drives[0].r_wheel * (1 - d.loaded)) - 1 for d in drawn]
    assert min(scales) < -0.008 and max(scales) > 0.008
    loads = [d.loaded for d in drawn]
    assert min(loads) < 0.011 and max(loads) > 0.019
    # every tyre loaded alike: the radii's mean falls by the load, their spread is the tyres'
    assert "tyres loaded" in describe_as_built(a) and "tyres loaded" not in describe_as_built(as_configured(STD))
    # a drive that does not steer is drawn no offset
    assert all(d.steering_offset == 0 for d in draw_as_built("field:3", DIFF).drives)


def test_the_workshop_profile_is_radii_and_homing_alone_on_pneumatic_tyres():
    drawn = [draw_as_built(f"workshop:{s}", STD) for s in range(200)]
    for built in drawn:
        assert not built.encoders and built.loaded == 0.0
        assert built.tyre_deflection == pytest.approx(0.045 * STD.drives[0].r_wheel)  # 9 mm, not rigid
        for d, conf in zip(built.drives, STD.drives):
            assert abs(d.r_wheel / conf.r_wheel - 1) <= 0.0085
            assert abs(d.steering_offset) <= math.radians(0.3)
    scales = [d.drives[0].r_wheel / STD.drives[0].r_wheel - 1 for d in drawn]
    assert min(scales) < -0.007 and max(scales) > 0.007  # uniform over +-0.85 %


def test_the_rigid_profile_is_the_workshops_draw_on_rigid_tyres():
    for seed in range(20):
        workshop, rigid = draw_as_built(f"workshop:{seed}", STD), draw_as_built(f"rigid:{seed}", STD)
        assert rigid.drives == workshop.drives and rigid.tyre_deflection == 0.0 < workshop.tyre_deflection


def test_as_built_for_takes_nothing_a_profile_or_a_file(tmp_path):
    assert as_built_for("", STD).ideal
    assert as_built_for("field:4", STD) == draw_as_built("field:4", STD)
    path = tmp_path / "built.yaml"
    path.write_text("motor_drives:\n  drive3: {r_wheel: 0.202}\n")
    assert as_built_for(str(path), STD).drive("drive3").r_wheel == 0.202
    with pytest.raises(ConfigError, match="integer seed"):
        as_built_for("field:x", STD)
    with pytest.raises(ConfigError, match="cannot read"):
        as_built_for(str(tmp_path / "missing.yaml"), STD)


def test_quantisation_in_whole_counts_of_the_configured_encoders():
    drive = STD.drives[0]
    per_radian = DriveScaling.of(drive).counts_per_radian  # the CAN codec's steering scaling
    assert per_radian == pytest.approx(drive.str_enc_ppr * 4 * drive.str_gr_rt / (2 * math.pi))
    step = 1.0 / per_radian
    assert quantise(0.0, per_radian) == 0.0
    assert quantise(2.5 * step, per_radian) == pytest.approx(2 * step)
    assert quantise(-2.5 * step, per_radian) == pytest.approx(-2 * step)
    for angle in (0.1, 0.33, -1.2):
        q = quantise(angle, per_radian)
        assert abs(angle - q) < step and round(q * per_radian) == pytest.approx(q * per_radian)


def test_the_simulator_gets_radii_offsets_and_the_encoders_resolution():
    built = for_simulator(draw_as_built("field:5", STD), STD)
    drawn = draw_as_built("field:5", STD)
    assert [d.r_wheel for d in built.drives] == [d.r_wheel for d in drawn.drives]
    assert [d.steering_offset for d in built.drives] == [d.steering_offset for d in drawn.drives]
    scaling = DriveScaling.of(STD.drives[0])  # the CAN codec's: what the controllers count
    d = built.drives[0]
    assert d.steering_count == pytest.approx(1.0 / scaling.counts_per_radian)
    assert d.wheel_count == pytest.approx(2 * math.pi / (STD.drives[0].prp_enc_ppr * 4 * STD.drives[0].prp_gr_rt))
    assert d.speed_step == pytest.approx(scaling.wheel_speed(1.0))
    # what a controller reports: the homing error off, whole counts, whole rpm
    steering, speed, wheel, rate = d.measured(0.3, 0.5, 12.0, 0.2)
    assert steering == pytest.approx(0.3 - d.steering_offset, abs=d.steering_count)
    assert steering / d.steering_count == pytest.approx(round(steering / d.steering_count))
    assert speed / d.speed_step == pytest.approx(round(speed / d.speed_step)) and abs(speed - 0.5) <= d.speed_step / 2
    assert wheel / d.wheel_count == pytest.approx(round(wheel / d.wheel_count))
    assert rate / d.steering_rate_step == pytest.approx(round(rate / d.steering_rate_step))
    # without encoders, exactly what the joints say less the homing error
    exact = for_simulator(parse_as_built({"motor_drives": {"drive0": {"steering_offset": 0.01}}}, STD), STD)
    assert exact.drives[0].measured(0.3, 0.5, 12.0, 0.2) == (pytest.approx(0.29), 0.5, 12.0, 0.2)
    # a drive that does not steer counts no steering
    assert all(d.steering_count == 0 for d in for_simulator(draw_as_built("field:1", DIFF), DIFF).drives)


def test_spawn_robot_reads_the_as_built_robot(tmp_path):
    import argparse  # noqa: PLC0415

    from thorvald_sim.spawn.spawn_robot import read_as_built  # noqa: PLC0415

    def args(as_built, robot_model=STD_PATH):
        return argparse.Namespace(as_built=as_built, robot_model=robot_model)

    assert read_as_built(args("")) == ""
    assert SimAsBuilt.from_json(read_as_built(args("field:2"))) == for_simulator(draw_as_built("field:2", STD), STD)
    with pytest.raises(RuntimeError, match="needs -robot_model"):
        read_as_built(args("field:2", ""))
    bad = tmp_path / "bad.yaml"
    bad.write_text("motor_drives:\n  drive9: {r_wheel: 0.2}\n")
    with pytest.raises(ConfigError, match="drive9"):
        read_as_built(args(str(bad)))
