"""The quasi-static limits (thorvald_design.quasi_static) against closed forms worked out here by other
routes: the two-axle vehicle's load transfer, a triangle's barycentric statics, the textbook grade
limits of front, rear and all-wheel drive, and the overturning angle of a rectangle and a triangle;
then on the example robots."""

import glob
import math
import os

import pytest

from thorvald_design.quasi_static import (
    TIPPING,
    TORQUE,
    TRACTION,
    Contact,
    Layout,
    contact_loads,
    gradeability,
    max_pull,
    normal_loads,
    overturning_angles,
    support_polygon,
    with_payload,
)
from thorvald_design.robot_layout import layout_of, load_layout
from thorvald_model import load_robot_config
from thorvald_model.description import generate_urdf

G = 9.81
SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
ROBOTS = os.path.join(SRC, "thorvald_example_robots", "config")
UNLIMITED = 1e9  # [N] a motor that never binds
TOL = 2e-6  # [rad] the limits are bisected to 1e-6 rad


def robot_file(name):
    return os.path.join(ROBOTS, name, name + ".yaml")


def two_axle(driven="fr", *, mass=200.0, xc=0.0, yc=0.0, h=0.5, half_length=0.5, half_track=0.3, force=UNLIMITED):
    """Four wheels at (+-half_length, +-half_track): f front, r rear; driven names the driven axles."""
    contacts = []
    for axle, x in (("f", half_length), ("r", -half_length)):
        for side, y in (("l", half_track), ("r", -half_track)):
            on = axle in driven
            contacts.append(Contact(axle + side, x, y, on, force if on else 0.0))
    return Layout(mass, (xc, yc, h), tuple(contacts))


def axle_loads(layout, loads):
    by_name = dict(zip((c.name for c in layout.contacts), loads))
    return by_name["fl"] + by_name["fr"], by_name["rl"] + by_name["rr"]


# ---- loads -----------------------------------------------------------------------------------------
def test_a_symmetric_four_wheeler_on_level_ground_shares_its_weight_equally():
    layout = two_axle()
    for loads in (normal_loads(layout, 0.0), contact_loads(layout, 0.0)):
        assert loads == pytest.approx([200.0 * G / 4] * 4)


@pytest.mark.parametrize("pitch_deg", [-25.0, -5.0, 10.0, 30.0])
def test_on_a_pitch_the_axle_loads_are_the_two_axle_vehicles(pitch_deg):
    # the two-axle vehicle: moments about the rear axle's contact line, N_f L = W (cos b_r - sin h),
    # b_r the centre of mass's distance ahead of the rear axle; N_r = W cos - N_f
    layout = two_axle(xc=0.1, h=0.6)
    pitch = math.radians(pitch_deg)
    w, length, b_r, h = 200.0 * G, 1.0, 0.6, 0.6
    front = w * (math.cos(pitch) * b_r - math.sin(pitch) * h) / length
    rear = w * math.cos(pitch) - front
    loads = normal_loads(layout, pitch)
    assert axle_loads(layout, loads) == pytest.approx((front, rear))
    assert loads[0] == pytest.approx(loads[1])  # centred sideways: left and right alike


def test_on_a_roll_the_load_moves_to_the_low_side_as_across_a_two_axle_vehicle():
    # roll > 0 lifts the left side: N_left t = W (cos (t/2 + yc) - sin h), the same form across the track
    layout = two_axle(yc=0.05, h=0.6, half_track=0.4)
    roll = math.radians(12.0)
    w, t = 200.0 * G, 0.8
    left = w * (math.cos(roll) * (t / 2 + 0.05) - math.sin(roll) * 0.6) / t
    loads = dict(zip((c.name for c in layout.contacts), normal_loads(layout, 0.0, roll)))
    assert loads["fl"] + loads["rl"] == pytest.approx(left)
    assert loads["fr"] + loads["rr"] == pytest.approx(w * math.cos(roll) - left)


def test_three_contacts_carry_the_exact_statics_the_barycentric_coordinates_of_the_centre_of_pressure():
    contacts = (
        Contact("a", 0.7, 0.1, True, 300.0),
        Contact("b", -0.4, 0.5, False, 0.0),
        Contact("c", -0.3, -0.45, False, 0.0),
    )
    layout = Layout(120.0, (0.05, 0.02, 0.55), contacts)
    pitch, roll, pull, hp = math.radians(8.0), math.radians(-6.0), 150.0, 0.3
    w = 120.0 * G
    # another route: the resultant W cos cos acts at the centre of pressure p, which the slope moves
    # h tan(pitch) / cos(roll) back and h tan(roll) right, and the pull hp P / Nz back; each load is
    # Nz times p's barycentric coordinate (areas of the sub-triangles over the whole).
    nz = w * math.cos(pitch) * math.cos(roll)
    px = 0.05 - 0.55 * math.tan(pitch) / math.cos(roll) - hp * pull / nz
    py = 0.02 - 0.55 * math.tan(roll)

    def area(p, q, r):
        return 0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))

    a, b, c = ((k.x, k.y) for k in contacts)
    total = area(a, b, c)
    expected = [nz * area((px, py), b, c) / total, nz * area(a, (px, py), c) / total, nz * area(a, b, (px, py)) / total]
    assert normal_loads(layout, pitch, roll, pull=pull, pull_height=hp) == pytest.approx(expected)
    assert contact_loads(layout, pitch, roll, pull=pull, pull_height=hp) == pytest.approx(expected)


@pytest.mark.parametrize(
    "pitch, roll, pull, hp",
    [(0.3, 0.0, 0.0, 0.0), (-0.2, 0.25, 0.0, 0.0), (0.0, -0.1, 400.0, 0.7), (0.4, 0.3, 100, 0.2)],
)
def test_the_loads_balance_the_weight_and_its_moments_on_an_irregular_layout(pitch, roll, pull, hp):
    contacts = tuple(
        Contact(f"w{k}", x, y, True, 200.0)
        for k, (x, y) in enumerate([(0.9, 0.6), (0.8, -0.5), (0.0, 0.7), (-0.1, -0.6), (-0.9, 0.5), (-1.0, -0.4)])
    )
    layout = Layout(300.0, (0.1, -0.05, 0.8), contacts)
    w = 300.0 * G
    for loads in (
        normal_loads(layout, pitch, roll, pull=pull, pull_height=hp),
        contact_loads(layout, pitch, roll, pull=pull, pull_height=hp),
    ):
        nz = w * math.cos(pitch) * math.cos(roll)
        assert sum(loads) == pytest.approx(nz)
        # moments about base_link's y and x axes in the ground plane (the module's statics)
        my = nz * 0.1 - w * 0.8 * math.sin(pitch) - pull * hp
        mx = nz * -0.05 - w * 0.8 * math.cos(pitch) * math.sin(roll)
        assert sum(n * c.x for n, c in zip(loads, contacts)) == pytest.approx(my)
        assert sum(n * c.y for n, c in zip(loads, contacts)) == pytest.approx(mx)
    assert min(contact_loads(layout, pitch, roll, pull=pull, pull_height=hp)) >= 0.0


def three_axles(driven=True):
    contacts = tuple(
        Contact(f"{axle}{side}", x, y, driven, UNLIMITED if driven else 0.0)
        for axle, x in (("f", 0.9), ("m", 0.0), ("r", -0.9))
        for side, y in (("l", 0.5), ("r", -0.5))
    )
    return Layout(300.0, (0.0, 0.0, 0.5), contacts)


def test_a_three_axle_robot_lifts_its_front_axle_long_before_it_tips():
    layout = three_axles()
    # linear sharing N = a + b x over x = 0.9, 0, -0.9 (two wheels each): the front axle's load is 0
    # when the centre of pressure is at -sum x^2 / (n 0.9) = -0.6 m, i.e. tan(pitch) = 0.6 / 0.5
    lift = math.atan(0.6 / 0.5)
    pitch = math.atan(0.75 / 0.5)  # the centre of pressure 0.75 m back: past the lift, before the tip
    linear = normal_loads(layout, pitch)
    assert min(linear[:2]) < 0.0  # the linear model pulls the front wheels down
    carried = contact_loads(layout, pitch)
    assert carried[:2] == pytest.approx([0.0, 0.0], abs=1e-6)
    # on the middle and rear axles alone (0.9 m apart), a two-axle vehicle with b_r = 0.9
    w = 300.0 * G
    middle = w * (math.cos(pitch) * 0.9 - math.sin(pitch) * 0.5) / 0.9
    assert carried[2] + carried[3] == pytest.approx(middle)
    assert carried[4] + carried[5] == pytest.approx(w * math.cos(pitch) - middle)
    limits = gradeability(layout, friction=2.0)
    assert limits.lift == pytest.approx(lift, abs=TOL)
    assert limits.tipping == pytest.approx(math.atan(0.9 / 0.5), abs=TOL)  # the rear axle, not the lift


def test_a_robot_that_tips_has_no_contact_loads_but_its_linear_loads_say_which_wheels_lift():
    layout = two_axle(h=0.5)
    pitch = math.radians(50.0)  # past atan(0.5 / 0.5)
    front, _ = axle_loads(layout, normal_loads(layout, pitch))
    assert front < 0.0
    with pytest.raises(ValueError, match="tips"):
        contact_loads(layout, pitch)


def test_a_payload_moves_the_centre_of_mass_and_the_load_with_it():
    layout = with_payload(two_axle(), 50.0, -0.4, 0.0, 1.0)
    assert layout.mass == 250.0
    assert layout.com == pytest.approx((-0.08, 0.0, 0.6))
    front, rear = axle_loads(layout, normal_loads(layout, 0.0))
    assert front == pytest.approx(250.0 * G * 0.42)  # b_r = 0.5 - 0.08
    assert rear == pytest.approx(250.0 * G * 0.58)


# ---- grade limits ----------------------------------------------------------------------------------
def test_grade_limits_of_front_rear_and_all_wheel_drive_are_the_textbook_ones():
    # 200 kg, L = 1 m, centre of mass in the middle (a = b = 0.5 m from either axle), h = 0.5 m, mu 0.8
    mu, length, a, b, h = 0.8, 1.0, 0.5, 0.5, 0.5
    all_wheel = gradeability(two_axle("fr"), mu)
    rear = gradeability(two_axle("r"), mu)
    front = gradeability(two_axle("f"), mu)
    # all wheels: mu W cos >= W sin
    assert all_wheel.climb == pytest.approx(math.atan(mu), abs=TOL)
    # rear: mu N_r = W sin, N_r = W (cos a + sin h) / L -> tan = mu a / (L - mu h)
    assert rear.climb == pytest.approx(math.atan(mu * a / (length - mu * h)), abs=TOL)
    # front: mu N_f = W sin, N_f = W (cos b - sin h) / L -> tan = mu b / (L + mu h)
    assert front.climb == pytest.approx(math.atan(mu * b / (length + mu * h)), abs=TOL)
    for limits in (all_wheel, rear, front):
        assert limits.limited_by == TRACTION
        assert limits.traction == pytest.approx(limits.climb, abs=TOL)
        assert limits.torque == pytest.approx(math.pi / 2)
        assert limits.tipping == pytest.approx(math.atan(a / h), abs=TOL)
    # as the Thorvald II paper found on its incline: front drive loses grip first
    assert front.climb < rear.climb < all_wheel.climb
    # nose down, braking, the load moves forward: the front drive holds what the rear drive climbs
    assert front.descent == pytest.approx(rear.climb, abs=TOL)
    assert rear.descent == pytest.approx(front.climb, abs=TOL)
    assert all_wheel.descent == pytest.approx(math.atan(mu), abs=TOL)


def test_rolling_resistance_lowers_the_rear_drives_climb_as_its_closed_form_says():
    # the rear wheels grip mu N_r, the free front ones roll against C N_f (a torque at each wheel):
    # mu W (a cos + h sin) / L - C W (b cos - h sin) / L = W sin -> tan = (mu a - C b) / (L - (mu + C) h);
    # off-centre, xc = 0.1
    mu, c_rr, length, h = 0.7, 0.05, 1.0, 0.4
    a = 0.5 - 0.1  # from the front axle to the centre of mass
    b = length - a
    limits = gradeability(two_axle("r", xc=0.1, h=h), mu, c_rr)
    assert limits.climb == pytest.approx(math.atan((mu * a - c_rr * b) / (length - (mu + c_rr) * h)), abs=TOL)
    # braking downhill with all wheels: the grip holds the slope, mu cos = sin -> tan = mu (the
    # rolling resistance helps the motors, not the grip)
    assert gradeability(two_axle("fr"), mu, c_rr).descent == pytest.approx(math.atan(mu), abs=TOL)


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_rolling_the_loads_act_ahead_of_the_contacts_and_the_climb_tips_that_much_sooner():
    # rolling forward, each load acts e ahead of its contact (the rolling resistance's moment): the
    # centre of pressure lies e further back, so the rear axle carries W e / L more on level ground,
    # and climbing, the robot tips where h tan(theta) = d - e (d: from the centre of mass back to the
    # rear axle), not d
    e, h = 0.03, 0.8
    layout = two_axle("fr", h=h)
    front, rear = axle_loads(layout, contact_loads(layout, 0.0, rolling_offset=e))
    w = 200.0 * G
    assert rear - front == pytest.approx(2 * w * e / 1.0)
    assert front + rear == pytest.approx(w)
    assert normal_loads(layout, 0.0, rolling_offset=e) == pytest.approx(contact_loads(layout, 0.0, rolling_offset=e))
    standing, rolling = gradeability(layout, 0.9), gradeability(layout, 0.9, rolling_offset=e)
    assert standing.tipping == pytest.approx(math.atan(0.5 / h), abs=TOL)
    assert rolling.tipping == pytest.approx(math.atan((0.5 - e) / h), abs=TOL)
    assert rolling.limited_by == TIPPING and rolling.climb == pytest.approx(rolling.tipping, abs=TOL)
    # nose down it tips forwards, the centre of pressure that much further from the front axle
    assert rolling.descent == pytest.approx(math.atan((0.5 + e) / h), abs=TOL)
    # the pull tips the robot backwards at P hp = W (d - e)
    tipped = max_pull(two_axle("fr"), 0.9, 0.0, pull_height=1.2, rolling_offset=e)
    assert tipped.limited_by == TIPPING and tipped.pull == pytest.approx(w * (0.5 - e) / 1.2)
    # the rear-driven tricycle's own: 12 mm of grass take its climb from 15.45 to 14.17 degrees
    tricycle = load_layout(robot_file("thorvald_ii_1wd1ws_rwd"))
    assert math.degrees(gradeability(tricycle, 0.55, 0.072).climb) == pytest.approx(15.45, abs=0.01)
    assert math.degrees(gradeability(tricycle, 0.55, 0.072, rolling_offset=0.012).climb) == pytest.approx(
        14.17, abs=0.01
    )
    with pytest.raises(ValueError, match="rolling_offset"):
        contact_loads(layout, 0.0, rolling_offset=-0.01)


def test_weak_motors_limit_the_climb_to_where_their_force_carries_the_slope():
    # W (sin + C cos) = sum F: sqrt(1 + C^2) sin(theta + atan C) = sum F / W
    c_rr, force = 0.03, 150.0
    layout = two_axle("fr", force=force)
    ratio = 4 * force / (200.0 * G)
    expected = math.asin(ratio / math.sqrt(1 + c_rr**2)) - math.atan(c_rr)
    limits = gradeability(layout, 0.8, c_rr)
    assert limits.climb == pytest.approx(expected, abs=TOL)
    assert limits.torque == pytest.approx(expected, abs=TOL)
    assert math.sin(limits.climb) + c_rr * math.cos(limits.climb) == pytest.approx(ratio, abs=1e-5)
    assert limits.limited_by == TORQUE
    assert limits.traction == pytest.approx(math.atan(0.8), abs=1e-3)  # mu cos = sin: rolling costs the motors


def test_a_tall_narrow_robot_tips_before_it_slips():
    layout = two_axle("fr", h=1.5, half_length=0.2)
    limits = gradeability(layout, 0.9)
    assert limits.limited_by == TIPPING
    assert limits.climb == pytest.approx(math.atan(0.2 / 1.5), abs=TOL)
    assert limits.traction > limits.climb  # friction alone would have carried it further
    assert limits.descent_limited_by == TIPPING
    assert limits.descent == pytest.approx(math.atan(0.2 / 1.5), abs=TOL)
    assert limits.to_dict()["climb_deg"] == pytest.approx(math.degrees(math.atan(0.2 / 1.5)), abs=1e-4)
    assert limits.climb_deg == pytest.approx(math.degrees(limits.climb))


def test_when_the_motors_bind_at_the_rear_and_grip_at_the_front_the_climb_is_below_both_alone():
    # per wheel min(mu N, F): the loaded rear wheels are capped by their motors, the unloaded front
    # wheels by their grip; the sum falls short before either limit alone does
    limits = gradeability(two_axle("fr", force=330.0), 0.9, 0.015)
    assert limits.climb < min(limits.traction, limits.torque) - math.radians(1.0)


# ---- drawbar pull ----------------------------------------------------------------------------------
def test_the_rear_drives_pull_gains_from_the_load_it_moves_to_the_rear():
    # level ground: N_r = (W a + P hp) / L, N_f = (W b - P hp) / L; the rear grips mu N_r, the free
    # front wheels roll against C N_f: mu N_r - C N_f = P -> P = (mu W a - C W b) / (L - (mu + C) hp)
    mu, c_rr, hp, a, length = 0.8, 0.02, 0.3, 0.5, 1.0
    b = length - a
    w = 200.0 * G
    rear = max_pull(two_axle("r"), mu, c_rr, hp)
    assert rear.pull == pytest.approx((mu * w * a - c_rr * w * b) / (length - (mu + c_rr) * hp), abs=1e-3)
    assert rear.limited_by == TRACTION
    front = max_pull(two_axle("f"), mu, c_rr, hp)  # loses load: mu N_f - C N_r = P
    assert front.pull == pytest.approx((mu * w * b - c_rr * w * a) / (length + (mu + c_rr) * hp), abs=1e-3)
    all_wheel = max_pull(two_axle("fr"), mu, c_rr, hp)  # the load moves, the sum stays: mu W
    assert all_wheel.pull == pytest.approx(mu * w, abs=1e-3)


def test_a_high_pull_tips_the_robot_and_weak_motors_cap_it():
    w = 200.0 * G
    tipped = max_pull(two_axle("fr"), 0.9, 0.0, pull_height=1.2)  # P hp / W reaches the rear axle: P = W 0.5 / 1.2
    assert tipped.limited_by == TIPPING
    assert tipped.pull == pytest.approx(w * 0.5 / 1.2)
    weak = max_pull(two_axle("fr", force=100.0), 0.9, 0.02, pull_height=0.3)
    assert weak.limited_by == TORQUE
    assert weak.pull == pytest.approx(400.0 - 0.02 * w, abs=1e-3)


# ---- overturning -----------------------------------------------------------------------------------
def test_a_rectangles_overturning_angles_are_its_half_track_and_half_wheelbase_over_its_height():
    h = 0.6
    angles = overturning_angles(two_axle(h=h, half_length=0.5, half_track=0.3))
    assert angles.left == pytest.approx(math.atan(0.3 / h))
    assert angles.right == pytest.approx(math.atan(0.3 / h))
    assert angles.lateral == pytest.approx(math.atan(0.3 / h))
    assert angles.front == pytest.approx(math.atan(0.5 / h))
    assert angles.rear == pytest.approx(math.atan(0.5 / h))
    assert angles.minimum == pytest.approx(math.atan(0.3 / h))
    assert angles.to_dict()["lateral_deg"] == pytest.approx(math.degrees(math.atan(0.3 / h)))
    # the centre of mass 0.1 m to the left: nearer the left edge, further from the right
    shifted = overturning_angles(two_axle(yc=0.1, h=h))
    assert shifted.left == pytest.approx(math.atan(0.2 / h))
    assert shifted.right == pytest.approx(math.atan(0.4 / h))
    assert set(shifted.edge) == {"fl", "rl"}


def tricycle(xc=0.0, yc=0.0, h=0.5):
    contacts = (
        Contact("front", 0.6, 0.0, True, UNLIMITED),
        Contact("rear_left", -0.4, 0.35, False, 0.0),
        Contact("rear_right", -0.4, -0.35, False, 0.0),
    )
    return Layout(100.0, (xc, yc, h), contacts)


def test_a_tricycle_tips_sideways_about_its_slanted_edges():
    h, xc = 0.5, 0.0
    angles = overturning_angles(tricycle(xc=xc, h=h))
    # the edge from (0.6, 0) to (-0.4, 0.35): distance of (xc, 0) from its line = 0.35 (0.6 - xc) / sqrt(1 + 0.35^2)
    d = 0.35 * (0.6 - xc) / math.hypot(1.0, 0.35)
    assert angles.left == pytest.approx(math.atan(d / h))
    assert angles.right == pytest.approx(math.atan(d / h))
    assert angles.rear == pytest.approx(math.atan((0.4 + xc) / h))  # the rear axle's line
    # forwards it tips about one of the two edges meeting at its single front wheel
    assert angles.front == pytest.approx(math.atan(d / h))
    assert angles.minimum == pytest.approx(math.atan(d / h))
    # straight up a slope the tricycle tips backwards over its rear axle: the same as its rear angle;
    # nose down its centre of pressure runs along x to the front wheel, 0.6 m away: not the edge's angle
    limits = gradeability(tricycle(xc=xc, h=h), 2.0)
    assert limits.tipping == pytest.approx(math.atan(0.4 / h), abs=TOL)
    assert limits.descent == pytest.approx(math.atan(0.6 / h), abs=TOL)


def test_a_centre_of_mass_outside_the_polygon_gives_a_negative_angle_and_no_grade_limits():
    layout = two_axle(yc=0.4, half_track=0.3)
    assert overturning_angles(layout).left == pytest.approx(math.atan(-0.1 / 0.5))
    with pytest.raises(ValueError, match="falls over on level ground"):
        gradeability(layout, 0.8)


def test_the_support_polygon_leaves_out_a_contact_on_an_edge():
    assert {c.name for c in support_polygon(three_axles())} == {"fl", "fr", "rl", "rr"}


# ---- bad input -------------------------------------------------------------------------------------
def test_a_layout_needs_three_contacts_not_on_one_line():
    two = (Contact("a", 0.5, 0.0, True, 100.0), Contact("b", -0.5, 0.0, True, 100.0))
    with pytest.raises(ValueError, match=r"at least 3 wheel contacts.*has 2"):
        Layout(100.0, (0.0, 0.0, 0.5), two)
    in_line = (*two, Contact("c", 0.0, 0.0, False, 0.0), Contact("d", 1.0, 1e-9, False, 0.0))
    with pytest.raises(ValueError, match="lie on one line"):
        Layout(100.0, (0.0, 0.0, 0.5), in_line)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: gradeability(two_axle(), -0.1), "friction"),
        (lambda: gradeability(two_axle(), 0.8, -0.01), "rolling_resistance"),
        (lambda: max_pull(two_axle(), -1.0, 0.0, 0.3), "friction"),
        (lambda: max_pull(two_axle(), 0.8, 0.0, -0.3), "pull_height"),
        (lambda: gradeability(two_axle(driven=""), 0.8), "no wheel of the layout is driven"),
        (lambda: normal_loads(two_axle(), 2.0), "pitch"),
        (lambda: Layout(-5.0, (0.0, 0.0, 0.5), two_axle().contacts), "mass"),
        (lambda: Layout(100.0, (0.0, 0.0, -0.1), two_axle().contacts), "below the ground"),
        (lambda: with_payload(two_axle(), -1.0, 0.0, 0.0, 1.0), "payload"),
    ],
)
def test_bad_input_is_refused_with_a_clear_message(call, message):
    with pytest.raises(ValueError, match=message):
        call()


# ---- the example robots ----------------------------------------------------------------------------
EXAMPLES = sorted(os.path.basename(os.path.dirname(p)) for p in glob.glob(os.path.join(ROBOTS, "*", "*.yaml")))


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
@pytest.mark.parametrize("name", EXAMPLES)
def test_an_example_robots_layout_is_its_configurations_wheels_and_its_descriptions_mass(name):
    config = load_robot_config(robot_file(name))
    layout = layout_of(config, generate_urdf(robot_file(name)))
    assert layout.mass > 0.0
    assert 0.2 < layout.height < 1.5
    assert len(layout.contacts) == len(config.drives) + len(config.passive_wheels)
    assert [c.name for c in layout.driven] == [d.name for d in config.drives]
    for c in layout.contacts:
        assert c.max_force == (pytest.approx(336.0) if c.driven else 0.0)  # 1.6 N m x 42 at a 0.2 m rim
    overturning_angles(layout)  # every example stands: no ValueError
    gradeability(layout, 0.9, 0.015)


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_the_one_wheel_drives_drive_one_contact_front_or_rear_on_three():
    fwd, rwd = load_layout(robot_file("thorvald_ii_1wd1ws_fwd")), load_layout(robot_file("thorvald_ii_1wd1ws_rwd"))
    for layout, sign in ((fwd, 1.0), (rwd, -1.0)):
        assert len(layout.contacts) == 3
        (driven,) = layout.driven
        assert driven.x * sign > 0.0
        assert all(c.x * sign < 0.0 for c in layout.contacts if not c.driven)


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_a_chosen_set_of_drives_drives_and_an_unknown_name_is_refused():
    config = load_robot_config(robot_file("thorvald_ii_4wd4ws_std"))
    urdf = generate_urdf(robot_file("thorvald_ii_4wd4ws_std"))
    layout = layout_of(config, urdf, driven={"drive1", "drive2"})
    assert {c.name for c in layout.driven} == {"drive1", "drive2"}
    assert all(c.max_force == 0.0 for c in layout.contacts if not c.driven)
    with pytest.raises(ValueError, match="drive9"):
        layout_of(config, urdf, driven={"drive9"})


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_the_one_wheel_drives_climb_less_than_the_four_wheel_drive_and_front_drive_grips_least():
    mu, c_rr = 0.9, 0.015
    fwd, rwd, std = (
        gradeability(load_layout(robot_file(f"thorvald_ii_{n}")), mu, c_rr)
        for n in ("1wd1ws_fwd", "1wd1ws_rwd", "4wd4ws_std")
    )
    assert fwd.traction < rwd.traction  # the rear wheel gains the load a climb moves back
    assert max(fwd.climb, rwd.climb) < std.climb
    # the rear-driven three-wheeler tips backwards before it slips: its single rear wheel's edges
    # run close past a centre of mass that sits towards its left battery
    assert rwd.limited_by == TIPPING and rwd.climb < fwd.climb
