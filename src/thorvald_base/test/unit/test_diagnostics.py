"""What base_driver says on /diagnostics (thorvald_base.diagnostics), computed without ROS."""

from diagnostic_msgs.msg import DiagnosticStatus

from thorvald_base import diagnostics
from thorvald_base.bases import BatteryInfo, ControllerInfo
from thorvald_base.diagnostics import ERROR, NOT_HEARD_YET, OK, PATIENCE, WARN, LinkWatch, base_statuses
from thorvald_base.modes import BATTERY_LOST, BATTERY_OK, MODE_LOST_CONNECTION, MODE_ONLINE


def test_levels_are_the_messages_levels():
    assert (diagnostics.OK, diagnostics.WARN, diagnostics.ERROR) == (
        DiagnosticStatus.OK,
        DiagnosticStatus.WARN,
        DiagnosticStatus.ERROR,
    )


def controller(name, mode, flags=()):
    return ControllerInfo(name, "RoboteqFbl2360", "2.1.0", int(name[-1]) + 1, mode, 47.5, status_flags=flags)


def test_every_controller_battery_and_the_bus_get_a_status():
    controllers = [
        controller("drive0", MODE_ONLINE),
        controller("drive1", MODE_LOST_CONNECTION),
        controller("drive2", MODE_ONLINE, (("stall detected", True), ("power stage off", False))),
    ]
    batteries = [
        BatteryInfo(1, BATTERY_OK, 80.0, 99.0, 50.123, 2.0),
        BatteryInfo(2, BATTERY_OK, 80.0, 99.0, 50.0, 2.0, alarms=("over_temperature_protection",)),
        BatteryInfo(3, BATTERY_LOST, 0.0, 0.0, 0.0, 0.0),
    ]
    link = {"bus": "open", "send errors": "0"}
    out = base_statuses("robot_1", controllers, batteries, link)
    assert [(s.name, s.hardware_id, s.level, s.message) for s in out] == [
        ("base_driver (robot_1): motor controller drive0", "node 1", OK, "ok"),
        ("base_driver (robot_1): motor controller drive1", "node 2", ERROR, "lost connection"),
        ("base_driver (robot_1): motor controller drive2", "node 3", WARN, "stall detected"),
        ("base_driver (robot_1): battery 1", "battery 1", OK, "ok"),
        ("base_driver (robot_1): battery 2", "battery 2", WARN, "over_temperature_protection"),
        ("base_driver (robot_1): battery 3", "battery 3", ERROR, "lost connection"),
        ("base_driver (robot_1): CAN bus", "can", OK, "open"),
    ]
    assert dict(out[0].values) == {"mode": "3", "battery volts": "47.5", "version": "2.1.0"}
    assert dict(out[3].values) == {"voltage": "50.12", "state of charge": "80 %"}
    assert dict(out[-1].values) == link


def test_the_bus_is_an_error_when_closed_or_devices_are_lost_or_scripts_wrong():
    for link in (
        {"bus": "closed (reopening)"},
        {"bus": "open", "wheels stopped: lost": "drive1"},
        {"bus": "open", "wrong script": "drive0: prop/prop"},
    ):
        (status,) = base_statuses("", [], [], link)
        assert status.level == ERROR and status.name == "base_driver: CAN bus", link
    assert base_statuses("", [], [], {}) == []  # a base without a hardware link says nothing of one


def test_link_changes_are_said_once():
    watch = LinkWatch()
    assert watch.changes({"bus": "open"}) == []
    assert watch.changes({"last error": "send: CanError: x"}) == ["CAN: last error: send: CanError: x"]
    assert watch.changes({"last error": "send: CanError: x"}) == []
    assert watch.changes({"wheels stopped: lost": "drive1"}) == ["CAN: wheels stopped: lost: drive1"]
    assert watch.changes({}) == ["CAN: every device heard again: the wheels follow commands"]
    assert watch.changes({}) == []


def test_devices_not_heard_since_start_are_no_loss_and_logged_only_when_they_stay_unheard():
    """At start the controllers' first reports are on their way: the wheels wait, the bus is a warning,
    and nothing is logged unless a device stays unheard for PATIENCE looks (a wrong node id)."""
    link = {"bus": "open", NOT_HEARD_YET: "drive0, drive1"}
    (status,) = base_statuses("", [], [], link)
    assert status.level == WARN
    watch = LinkWatch()
    assert all(watch.changes(link) == [] for _ in range(PATIENCE - 1))
    (line,) = watch.changes(link)
    assert line.startswith("CAN: wheels stopped: not heard since start: drive0, drive1 (check each controller")
    assert watch.changes(link) == []  # said once
    assert watch.changes({"bus": "open"}) == []  # heard: no loss to recover from
