"""The design-study metrics (thorvald_design.metrics) on synthetic tracks whose answers are known in
closed form: circles fitted, turning and clearance diameters of turns and spins, drift at a known
angle, ramp climbs reached, stalled and slid back, plants touched by rows and corners. Pure: numpy only."""

import math

import numpy as np
import pytest

from thorvald_design.metrics import (
    Track,
    body_point_path,
    climbed,
    distance_between,
    fit_circle,
    lateral_drift,
    path_length,
    plants_touched,
    turning_diameters,
)

# a rectangle robot: wheel contacts at (+-A, +-B), plan outline a rectangle LENGTH x WIDTH about the origin
A, B = 0.6, 0.7  # half wheelbase, half track [m]
LENGTH, WIDTH = 2.0, 1.7
WHEELS = [("front_left", A, B), ("front_right", A, -B), ("rear_left", -A, B), ("rear_right", -A, -B)]
OUTLINE = [(LENGTH / 2, WIDTH / 2), (LENGTH / 2, -WIDTH / 2), (-LENGTH / 2, -WIDTH / 2), (-LENGTH / 2, WIDTH / 2)]


def circle_track(radius, centre=(0.0, 0.0), *, start=0.0, sweep=2 * math.pi, n=400, left=True):
    """The origin on a circle about centre, heading along it: turning left (counter-clockwise) or right."""
    theta = start + np.linspace(0.0, sweep, n) * (1.0 if left else -1.0)
    x = centre[0] + radius * np.cos(theta)
    y = centre[1] + radius * np.sin(theta)
    yaw = theta + (math.pi / 2 if left else -math.pi / 2)
    return Track(np.linspace(0.0, 20.0, n), x, y, yaw)


def straight_track(length, angle, n=201, start=(0.0, 0.0), duration=10.0):
    s = np.linspace(0.0, length, n)
    return Track(
        np.linspace(0.0, duration, n), start[0] + s * math.cos(angle), start[1] + s * math.sin(angle), np.full(n, angle)
    )


# --- track, distances --------------------------------------------------------------------------


def test_track_refuses_arrays_of_different_lengths_and_decreasing_times():
    with pytest.raises(ValueError, match="x has 2 values"):
        Track([0.0, 1.0, 2.0], [0.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="must not decrease"):
        Track([0.0, 2.0, 1.0], [0.0] * 3, [0.0] * 3, [0.0] * 3)


def test_between_keeps_the_poses_in_the_window():
    track = straight_track(10.0, 0.0, n=11, duration=10.0)
    part = track.between(2.0, 5.0)
    assert list(part.t) == [2.0, 3.0, 4.0, 5.0]
    assert list(part.x) == [2.0, 3.0, 4.0, 5.0]


def test_body_point_path_rotates_then_translates():
    track = Track([0.0], [1.0], [2.0], [math.pi / 2])
    wx, wy = body_point_path(track, 1.0, 0.5)  # forward is +y, left is -x
    assert wx[0] == pytest.approx(1.0 - 0.5)
    assert wy[0] == pytest.approx(2.0 + 1.0)


def test_path_length_of_a_polygon_round_a_circle_and_of_a_slope():
    n, radius = 37, 3.0
    track = circle_track(radius, n=n)
    # n - 1 chords, each spanning 2 pi / (n - 1): 2 R sin(half that)
    assert path_length(track) == pytest.approx((n - 1) * 2 * radius * math.sin(math.pi / (n - 1)))
    slope = math.radians(15.0)
    s = np.linspace(0.0, 4.0, 9)
    ramp = Track(s, s, np.zeros_like(s), np.zeros_like(s), z=s * math.tan(slope))
    assert path_length(ramp) == pytest.approx(4.0 / math.cos(slope))
    assert distance_between(ramp) == pytest.approx(4.0)
    assert distance_between(track, 0, (n - 1) // 2) == pytest.approx(2 * radius)


# --- circle fit --------------------------------------------------------------------------------


@pytest.mark.parametrize("centre", [(0.0, 0.0), (1000.0, -2500.0)])
def test_fit_circle_recovers_an_exact_circle(centre):
    theta = np.linspace(0.3, 2.0, 25)
    cx, cy, r, rms = fit_circle(centre[0] + 4.5 * np.cos(theta), centre[1] + 4.5 * np.sin(theta))
    assert (cx, cy, r) == pytest.approx((centre[0], centre[1], 4.5), abs=1e-7)
    assert rms < 1e-7


def test_fit_circle_is_the_geometric_least_squares_circle_on_a_short_noisy_arc():
    rng = np.random.default_rng(7)
    theta = np.linspace(0.0, 0.8, 60)
    xs = 10.0 * np.cos(theta) + rng.normal(0.0, 0.05, theta.size)
    ys = 10.0 * np.sin(theta) + rng.normal(0.0, 0.05, theta.size)
    cx, cy, r, rms = fit_circle(xs, ys)

    def geometric_rms(a, b, c):
        return math.sqrt(float(np.mean((np.hypot(xs - a, ys - b) - c) ** 2)))

    assert rms == pytest.approx(geometric_rms(cx, cy, r))
    # a minimum of the geometric residual: every small step away from it is worse
    for step in np.eye(3) * 1e-3:
        for sign in (1.0, -1.0):
            assert geometric_rms(cx + sign * step[0], cy + sign * step[1], r + sign * step[2]) > rms
    assert r == pytest.approx(10.0, rel=0.05)


def test_fit_circle_refuses_too_few_and_collinear_points():
    with pytest.raises(ValueError, match="at least 3"):
        fit_circle([0.0, 1.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="line"):
        fit_circle([0.0, 1.0, 2.0, 3.0], [1.0, 3.0, 5.0, 7.0])
    with pytest.raises(ValueError, match="line"):
        fit_circle([2.0, 2.0, 2.0], [1.0, 1.0, 1.0])


# --- turning -----------------------------------------------------------------------------------


@pytest.mark.parametrize("left", [True, False])
@pytest.mark.parametrize(("radius", "centre", "sweep"), [(3.0, (0.0, 0.0), 2 * math.pi), (5.0, (120.0, -40.0), 1.5)])
def test_turning_diameters_of_a_steady_turn(left, radius, centre, sweep):
    result = turning_diameters(circle_track(radius, centre, start=0.4, sweep=sweep, left=left), WHEELS, OUTLINE)
    # the centre lies on the robot's inner side at distance radius, level with the origin: the outer
    # wheels are B farther out and A ahead or behind, the outer corners WIDTH/2 and LENGTH/2
    assert result.turning_diameter == pytest.approx(2 * math.hypot(radius + B, A), abs=1e-6)
    assert result.clearance_diameter == pytest.approx(2 * math.hypot(radius + WIDTH / 2, LENGTH / 2), abs=1e-6)
    assert result.centre == pytest.approx(centre, abs=1e-6)
    outer_side = "right" if left else "left"
    assert result.outer_wheel.endswith(outer_side)
    assert not result.spin
    assert result.radius_spread < 1e-6


def test_a_noisy_turn_still_gives_its_diameters_within_the_noise():
    rng = np.random.default_rng(3)
    clean = circle_track(4.0, n=800)
    noisy = Track(clean.t, clean.x + rng.normal(0.0, 0.01, 800), clean.y + rng.normal(0.0, 0.01, 800), clean.yaw)
    result = turning_diameters(noisy, WHEELS, OUTLINE)
    assert result.turning_diameter == pytest.approx(2 * math.hypot(4.0 + B, A), abs=0.01)


def test_a_spin_on_the_spot_sweeps_the_corners():
    yaw = np.linspace(0.0, 2 * math.pi, 200)
    spin = Track(np.linspace(0.0, 8.0, 200), np.full(200, 3.0), np.full(200, 4.0), yaw)
    result = turning_diameters(spin, WHEELS, OUTLINE)
    assert result.spin
    assert result.centre == pytest.approx((3.0, 4.0))
    assert result.turning_diameter == pytest.approx(2 * math.hypot(A, B))
    assert result.clearance_diameter == pytest.approx(2 * math.hypot(LENGTH / 2, WIDTH / 2))


def test_a_spin_about_a_point_off_the_origin_is_a_turn_about_that_point():
    # rotation about the body point (0.5, 0): the origin circles it at radius 0.5
    yaw = np.linspace(0.0, 2 * math.pi, 300)
    pivot = (2.0, -1.0)
    x = pivot[0] - 0.5 * np.cos(yaw)
    y = pivot[1] - 0.5 * np.sin(yaw)
    result = turning_diameters(Track(np.linspace(0.0, 9.0, 300), x, y, yaw), WHEELS, OUTLINE)
    assert not result.spin
    assert result.centre == pytest.approx(pivot, abs=1e-6)
    assert result.turning_diameter == pytest.approx(2 * math.hypot(A + 0.5, B), abs=1e-6)
    assert result.outer_wheel.startswith("rear")
    assert result.clearance_diameter == pytest.approx(2 * math.hypot(LENGTH / 2 + 0.5, WIDTH / 2), abs=1e-6)


def test_the_outermost_point_is_the_outlines_corner_or_else_the_outer_wheels_contact():
    # about the body point (0.5, 0), the rear corners are the farthest: (-LENGTH/2, +-WIDTH/2)
    yaw = np.linspace(0.0, 2 * math.pi, 300)
    x, y = 2.0 - 0.5 * np.cos(yaw), -1.0 - 0.5 * np.sin(yaw)
    result = turning_diameters(Track(np.linspace(0.0, 9.0, 300), x, y, yaw), WHEELS, OUTLINE)
    assert result.outer_point[0] == pytest.approx(-LENGTH / 2) and abs(result.outer_point[1]) == pytest.approx(
        WIDTH / 2
    )
    # an outline inside the wheels: the clearance circle is the outer wheel's, its point the contact
    inside = [(0.5 * px, 0.5 * py) for px, py in OUTLINE]
    spin = Track(np.linspace(0.0, 8.0, 200), np.full(200, 3.0), np.full(200, 4.0), np.linspace(0.0, 6.0, 200))
    result = turning_diameters(spin, WHEELS, inside)
    assert result.clearance_diameter == pytest.approx(result.turning_diameter)
    wheel = next((px, py) for name, px, py in WHEELS if name == result.outer_wheel)
    assert result.outer_point == pytest.approx(wheel)


def test_a_straight_track_is_not_a_turn():
    with pytest.raises(ValueError, match="not a turn"):
        turning_diameters(straight_track(5.0, 0.3), WHEELS, OUTLINE)


# --- drift -------------------------------------------------------------------------------------


@pytest.mark.parametrize("heading", [0.0, 2.0, -2.5])
@pytest.mark.parametrize("angle", [0.05, -0.1, 0.3])
def test_drift_of_a_straight_track_at_an_angle_off_the_heading(heading, angle):
    drift = lateral_drift(straight_track(20.0, heading + angle, start=(5.0, -3.0)), heading)
    assert drift.per_m == pytest.approx(math.tan(angle))
    assert drift.total == pytest.approx(20.0 * math.sin(angle))  # positive: to the left
    assert drift.distance == pytest.approx(20.0 * math.cos(angle))
    assert drift.max_offset == pytest.approx(drift.total)


def test_drift_reports_the_largest_offset_along_the_way():
    s = np.linspace(0.0, 10.0, 101)
    offset = -0.3 * np.sin(np.pi * s / 10.0)  # swerves right by 0.3 m and comes back
    drift = lateral_drift(Track(s, s, offset, np.zeros_like(s)), 0.0)
    assert drift.total == pytest.approx(0.0, abs=1e-12)
    assert drift.max_offset == pytest.approx(-0.3)


def test_drift_refuses_a_track_that_did_not_advance():
    with pytest.raises(ValueError, match="advanced"):
        lateral_drift(straight_track(5.0, math.pi), 0.0)


# --- ramps -------------------------------------------------------------------------------------

# module-level numpy arrays trip the workspace conftest's scan of module globals (`v in tuple`): functions


def ramp_track(x):
    t = np.linspace(0.0, 20.0, 401)
    return Track(t, x(t), np.zeros_like(t), np.zeros_like(t))


def test_a_climb_that_reaches_the_top():
    climb = climbed(ramp_track(lambda t: 0.3 * t), ramp_start_x=-1.0, ramp_top_x=3.0)
    assert climb.reached and not climb.stalled
    assert climb.max_progress_m == pytest.approx(6.0 + 1.0)
    assert climb.slid_back_m == 0.0


def test_a_robot_that_rolls_back_on_top_has_not_slid_back_down_the_ramp():
    def x(t):  # over the top (3 m) to 5 m, then back to 4 m: still on top
        return np.where(t <= 10.0, 0.5 * t, 5.0 - 0.1 * (t - 10.0))

    climb = climbed(ramp_track(x), ramp_start_x=0.0, ramp_top_x=3.0)
    assert climb.reached and not climb.stalled
    assert climb.max_progress_m == pytest.approx(5.0)
    assert climb.slid_back_m == 0.0


def test_a_climb_that_stalls_below_the_top():
    climb = climbed(ramp_track(lambda t: 2.0 * (1.0 - np.exp(-t))), ramp_start_x=0.0, ramp_top_x=3.0)
    assert not climb.reached and climb.stalled
    assert climb.max_progress_m == pytest.approx(2.0 * (1.0 - math.exp(-20.0)))
    assert climb.slid_back_m == pytest.approx(0.0, abs=1e-12)


def test_a_climb_that_slides_back():
    def x(t):  # up to 2.5 m, then back down to 1.0 m
        return np.where(t <= 10.0, 0.25 * t, 2.5 - 0.15 * (t - 10.0))

    climb = climbed(ramp_track(x), ramp_start_x=-1.0, ramp_top_x=3.0)
    assert not climb.reached and climb.stalled
    assert climb.max_progress_m == pytest.approx(3.5)
    assert climb.slid_back_m == pytest.approx(1.5)


def test_a_climb_still_under_way_when_the_run_ended():
    climb = climbed(ramp_track(lambda t: 0.1 * t), ramp_start_x=0.0, ramp_top_x=3.0)
    assert not climb.reached and not climb.stalled
    assert climb.max_progress_m == pytest.approx(2.0)


# --- plants ------------------------------------------------------------------------------------

WHEEL_A, WHEEL_B, WHEEL_L, WHEEL_W = 0.6, 0.3, 0.4, 0.15
FOOTPRINTS = [(sx * WHEEL_A, sy * WHEEL_B, WHEEL_L, WHEEL_W) for sx in (1, -1) for sy in (1, -1)]
ROW_Y = 0.75
PLANT_R = 0.05


def row_x():
    return np.arange(-5.0, 15.0 + 1e-9, 0.25)  # 81 plants a row


def two_rows():
    """The plants of the row at y = ROW_Y (indices 0..80), then of the row at -ROW_Y."""
    return np.concatenate([np.column_stack([row_x(), np.full(row_x().size, y)]) for y in (ROW_Y, -ROW_Y)])


def drive(offset_y, n=501):
    x = np.linspace(0.0, 5.0, n)
    return Track(np.linspace(0.0, 10.0, n), x, np.full(n, offset_y), np.zeros(n))


def rotated(track, plants, angle, about=(1.0, 2.0)):
    """The same scene turned by angle about a point: the plants touched do not change."""
    c, s = math.cos(angle), math.sin(angle)

    def turn(x, y):
        return about[0] + c * (x - about[0]) - s * (y - about[1]), about[1] + s * (x - about[0]) + c * (y - about[1])

    tx, ty = turn(track.x, track.y)
    px, py = turn(plants[:, 0], plants[:, 1])
    return Track(track.t, tx, ty, track.yaw + angle), np.column_stack([px, py])


def test_a_robot_between_two_rows_touches_none():
    # the wheels' outer edges at y = +-(0.3 + 0.075), the plants' inner edges at +-(0.75 - 0.05)
    assert plants_touched(drive(0.0), FOOTPRINTS, two_rows(), PLANT_R).count == 0


@pytest.mark.parametrize("angle", [0.0, 0.7, -2.9])
def test_a_robot_offset_onto_a_row_touches_that_row_within_its_reach(angle):
    # offset by 0.45 m the left wheels run along the left row (y = 0.75): a plant is touched when
    # |x_plant - x_wheel| <= WHEEL_L / 2 + PLANT_R for some pose, the wheel centres at x + -0.6 for x in
    # [0, 5]: x_plant in [-0.6 - 0.25, 5.6 + 0.25]; the right wheels (y = 0.15) reach no row
    track, plants = rotated(drive(0.45), two_rows(), angle)
    result = plants_touched(track, FOOTPRINTS, plants, PLANT_R)
    reach = WHEEL_A + WHEEL_L / 2 + PLANT_R
    expected = [i for i, x in enumerate(row_x()) if -reach <= x <= 5.0 + reach]
    assert list(result.indices) == expected
    assert result.count == len(expected) == 27


@pytest.mark.parametrize(
    ("plant", "radius", "touched"),
    [
        ((0.58, 0.33), 0.11, False),  # off the corner (0.5, 0.25) by hypot(0.08, 0.08) = 0.113
        ((0.58, 0.33), 0.115, True),
        ((0.59, 0.0), 0.08, False),  # off the front edge by 0.09
        ((0.59, 0.0), 0.1, True),
        ((0.1, -0.1), 0.0, True),  # inside
    ],
)
def test_rectangle_and_circle_meet_by_the_nearest_point_not_the_bounding_box(plant, radius, touched):
    track = Track([0.0], [0.0], [0.0], [0.0])
    assert plants_touched(track, [(0.0, 0.0, 1.0, 0.5)], [plant], radius).count == int(touched)


def brute_force(track, footprints, plants, radius):
    """Every pose against every plant and footprint, no culling."""
    dx = plants[None, :, 0] - track.x[:, None]
    dy = plants[None, :, 1] - track.y[:, None]
    c, s = np.cos(track.yaw)[:, None], np.sin(track.yaw)[:, None]
    bx, by = c * dx + s * dy, -s * dx + c * dy
    hit = np.zeros(dx.shape, dtype=bool)
    for cx, cy, length, width in footprints:
        ex = np.clip(np.abs(bx - cx) - length / 2, 0.0, None)
        ey = np.clip(np.abs(by - cy) - width / 2, 0.0, None)
        hit |= np.hypot(ex, ey) <= radius
    return list(np.nonzero(hit.any(axis=0))[0])


def test_plants_touched_agrees_with_brute_force_on_a_wandering_track():
    rng = np.random.default_rng(11)
    n = 600
    yaw = np.cumsum(rng.normal(0.0, 0.05, n))
    x = np.cumsum(0.03 * np.cos(yaw))
    y = np.cumsum(0.03 * np.sin(yaw))
    track = Track(np.arange(n) * 0.1, x, y, yaw)
    plants = np.column_stack([rng.uniform(x.min() - 2, x.max() + 2, 800), rng.uniform(y.min() - 2, y.max() + 2, 800)])
    footprints = [*FOOTPRINTS, (0.0, 0.0, 1.0, 0.3)]
    result = plants_touched(track, footprints, plants, 0.04)
    assert 0 < result.count < 800
    assert list(result.indices) == brute_force(track, footprints, plants, 0.04)


def test_plants_touched_is_fast_on_a_field():
    # 4000 poses down a field of 40 rows x 200 plants: straddling row 20 with the wheels in the gaps
    rows = np.arange(40) * 0.75
    xs = np.arange(200) * 0.1
    plants = np.column_stack([np.tile(xs, rows.size), np.repeat(rows, xs.size)])
    n = 4000
    x = np.linspace(-2.0, 22.0, n)
    track = Track(np.linspace(0.0, 60.0, n), x, np.full(n, 20 * 0.75), np.zeros(n))
    wheels = [(sx * 0.6, sy * 0.375, 0.4, 0.15) for sx in (1, -1) for sy in (1, -1)]
    assert plants_touched(track, wheels, plants, 0.1).count == 0
    shifted = Track(track.t, track.x, track.y + 0.375, track.yaw)  # right wheels on row 20, left on row 21
    assert plants_touched(shifted, wheels, plants, 0.1).count == 2 * xs.size
