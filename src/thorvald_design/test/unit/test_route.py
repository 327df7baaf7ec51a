"""thorvald_design.route: the headland turns' geometry and pure pursuit, against closed forms (pure)."""

import math

import numpy as np
import pytest

from thorvald_design.route import PurePursuit, field_route, path_of, turn


def test_a_u_turn_is_a_half_circle_into_the_next_row():
    points = np.array(turn((5.0, 0.0), 0.0, 0.75, 0.3))
    assert points[0] == pytest.approx((5.0, 0.0)) and points[-1] == pytest.approx((5.0, 0.75))
    r = np.hypot(points[:, 0] - 5.0, points[:, 1] - 0.375)
    assert r == pytest.approx(0.375, abs=1e-9)
    assert path_of(points).length == pytest.approx(math.pi * 0.375, rel=1e-3)


@pytest.mark.parametrize("d, r", [(0.75, 0.5), (0.75, 1.0), (1.5, 2.0)])
def test_an_omega_turn_is_three_touching_arcs_of_the_radius(d, r):
    points = np.array(turn((0.0, 0.0), 0.0, d, r))
    assert points[0] == pytest.approx((0.0, 0.0)) and points[-1] == pytest.approx((0.0, d))
    steps = np.hypot(np.diff(points[:, 0]), np.diff(points[:, 1]))
    assert steps.max() < 0.03  # continuous: the arcs meet
    # every point lies on one of the three circles: (0, -r), (xc, d/2), (0, d + r)
    xc = math.sqrt(4 * r * r - (d / 2 + r) ** 2)
    on = [
        np.abs(np.hypot(points[:, 0] - cx, points[:, 1] - cy) - r) < 1e-6
        for cx, cy in ((0, -r), (xc, d / 2), (0, d + r))
    ]
    assert np.all(on[0] | on[1] | on[2])
    # it bulges out to the far side of the middle circle: the headland it needs
    assert points[:, 0].max() == pytest.approx(xc + r, abs=1e-3)


def test_a_field_route_alternates_rows_joined_by_turns():
    path = field_route(4, 10.0, 0.75, 0.3)
    assert path.length == pytest.approx(4 * 10.0 + 3 * math.pi * 0.375, rel=1e-3)
    assert (path.x[-1], path.y[-1]) == pytest.approx((0.0, 2.25))  # the 4th row ends where the 1st began
    assert path.x.min() == pytest.approx(-0.375, abs=1e-3) and path.x.max() == pytest.approx(10.375, abs=1e-3)


def test_pure_pursuit_follows_a_field_route_with_a_unicycle():
    """A kinematic unicycle driven by the follower stays within a few centimetres of the route."""
    path = field_route(3, 6.0, 1.0, 0.5)
    pursuit = PurePursuit(path, lookahead=0.5, speed=1.0, max_rate=4.0)
    x = y = yaw = 0.0
    dt, worst = 0.01, 0.0
    for _ in range(5000):
        vx, wz = pursuit.command(x, y, yaw)
        if pursuit.done():
            break
        x, y, yaw = x + vx * math.cos(yaw) * dt, y + vx * math.sin(yaw) * dt, yaw + wz * dt
        worst = max(worst, float(np.min(np.hypot(path.x - x, path.y - y))))
    assert pursuit.done()
    assert worst < 0.08
