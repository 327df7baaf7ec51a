"""Where each kind of world element lies on the ground: the points [m] (x, y) of a box around it, for
the world's extent (``check_world``). One function a kind, named in its registry entry
(:attr:`thorvald_sim.world.kind.ElementKind.footprint`)."""

import math
from typing import List

from .geometry import Point, _along
from .values import HeightField, Patch, Polytunnel, Rail, Rows, Slope, Wall, WorldObject


def rectangle(x: float, y: float, yaw: float, us, vs) -> List[Point]:
    """The corners of the rectangle us[0]..us[1] by vs[0]..vs[1] in a frame at (x, y) turned by yaw."""
    return [_along(x, y, yaw, u, v) for u in us for v in vs]


def height_field(hf: HeightField) -> List[Point]:
    return rectangle(hf.x, hf.y, 0.0, (-hf.size_x / 2, hf.size_x / 2), (-hf.size_y / 2, hf.size_y / 2))


def patch(pa: Patch) -> List[Point]:
    return list(pa.corners())


def slope(sl: Slope) -> List[Point]:
    half = sl.footprint_length / 2
    return rectangle(sl.x, sl.y, sl.yaw, (-half, half), (-sl.width / 2, sl.width / 2))


def rail(ra: Rail) -> List[Point]:
    side = ra.gauge / 2 + ra.radius
    return rectangle(ra.x, ra.y, ra.yaw, (-ra.length / 2, ra.length / 2), (-side, side))


def world_object(ob: WorldObject) -> List[Point]:
    """A sphere around its centre (a mesh's: its origin)."""
    reach = {
        "box": math.sqrt(ob.size_x**2 + ob.size_y**2 + ob.size_z**2) / 2,
        "cylinder": math.hypot(ob.radius, ob.length / 2),
        "sphere": ob.radius,
    }.get(ob.shape, 0.0)
    return [(ob.x - reach, ob.y - reach), (ob.x + reach, ob.y + reach)]


def rows(ro: Rows) -> List[Point]:
    """The plants' rectangle, widened by their jitter and radius."""
    margin = ro.jitter + ro.plant_radius
    across = (ro.count - 1) * ro.spacing
    return rectangle(ro.x, ro.y, ro.yaw, (-margin, ro.length + margin), (-margin, across + margin))


def polytunnel(tu: Polytunnel) -> List[Point]:
    side = (tu.width + tu.tube) / 2
    return rectangle(tu.x, tu.y, tu.yaw, (-tu.length / 2, tu.length / 2), (-side, side))


def wall(wa: Wall) -> List[Point]:
    return rectangle(wa.x, wa.y, wa.yaw, (-wa.length / 2, wa.length / 2), (-wa.thickness / 2, wa.thickness / 2))
