"""A Gazebo world's populations (``<population>``): how many instances one makes, counted from its text
before anything is made (:func:`population_count`), and where Gazebo 11's ``Population`` puts them
(:func:`population_places`: random, uniform by ignition-math's k-means, grid, linear along an axis, in
a box or a cylinder). Read from a world by :mod:`~thorvald_sim.world.gazebo_world`, whose docstring
says what Gazebo does and where it says so.

Pure: no pybullet, no ROS (numpy for a uniform population's k-means only).
"""

import math
import random
import re
import xml.etree.ElementTree as ET
from typing import Any, Dict, Iterable, List, Optional

from ..models.spec import Vec3

POPULATION_TYPES = ("random", "uniform", "grid", "linear-x", "linear-y", "linear-z")
UNIFORM_STEP = 0.1  # [m] Population::CreatePosesBoxUniform's observations, over the box's x and y
UNIFORM_CYLINDER_POINTS = 10000  # Population::CreatePosesCylinderUniform's observations
MAX_KMEANS_OBSERVATIONS = 1_000_000  # of a uniform population's k-means (Gazebo's: one every 0.1 m of its box)
MAX_KMEANS_WORK = 20_000_000  # observations times clusters of a uniform population (each k-means pass)
MAX_KMEANS_PASSES = 1000


def population_count(element: ET.Element) -> int:
    """The instances a population makes, from its text alone (rows x cols of a grid, else model_count;
    1 where it cannot be read: its problem is reported when it is read)."""

    def whole(parent: Optional[ET.Element], tag: str) -> int:
        text = ((parent.findtext(tag) if parent is not None else None) or "").strip()
        return max(int(text), 0) if re.fullmatch(r"[+-]?\d+", text) else 1

    distribution = element.find("distribution")
    kind = ((distribution.findtext("type") if distribution is not None else None) or "random").strip()
    if kind == "grid":
        return whole(distribution, "rows") * whole(distribution, "cols")
    return whole(element, "model_count")


def population_places(params: Dict[str, Any], rng: random.Random):
    """The clones' positions as Population.cc makes them (module docstring, item 5), or why not."""
    kind = params["type"]
    pose = params["pose"]
    (px, py, pz), rotation = pose
    if kind == "grid":
        rows, cols, (sx, sy, _) = params["rows"], params["cols"], params["step"]
        px -= sx * (cols - 2) / 2.0 + sx / 2.0 if cols % 2 == 0 else sx * (cols - 1) / 2.0
        py -= sy * (rows - 2) / 2.0 + sy / 2.0 if rows % 2 == 0 else sy * (rows - 1) / 2.0
        offsets: Iterable[Vec3] = ((j * sx, i * sy, 0.0) for i in range(rows) for j in range(cols))
    else:
        count = params["count"]
        if params["region"] == "box":
            size = params["size"]
            px, py, pz = px - size[0] / 2.0, py - size[1] / 2.0, pz - size[2] / 2.0
            if kind == "random":
                offsets = [
                    (rng.uniform(0, size[0]), rng.uniform(0, size[1]), rng.uniform(0, size[2])) for _ in range(count)
                ]
            elif kind == "uniform":
                points = _box_observations(size, rng)
                if isinstance(points, str):
                    return points
                offsets = points
            else:
                axis = "xyz".index(kind[-1])
                half = [size[0] / 2.0, size[1] / 2.0, size[2] / 2.0]
                offsets = []
                for i in range(count):
                    offset = list(half)
                    offset[axis] = size[axis] * i / float(count)
                    offsets.append((offset[0], offset[1], offset[2]))
        else:
            radius, length = params["radius"], params["length"]

            def in_cylinder() -> Vec3:
                angle, r = rng.uniform(0, 2 * math.pi), rng.uniform(0, radius)
                return (r * math.cos(angle), r * math.sin(angle), rng.uniform(0, length))

            if kind == "random":
                offsets = [in_cylinder() for _ in range(count)]
            else:
                offsets = [in_cylinder() for _ in range(UNIFORM_CYLINDER_POINTS)]
        if kind == "uniform":
            offsets = _kmeans(offsets, count)
            if isinstance(offsets, str):
                return offsets
    return [_add(_rotate(rotation, offset), (px, py, pz)) for offset in offsets]


def _box_observations(size: Vec3, rng: random.Random):
    """CreatePosesBoxUniform's observations (numpy, n x 3): every 0.1 m over x (inner) and y, counted
    as Gazebo counts (x += .1 while below the size), each at a random height; or why not."""
    import numpy as np  # noqa: PLC0415  (a uniform population only)

    estimate = (math.ceil(size[0] / UNIFORM_STEP) + 1) * (math.ceil(size[1] / UNIFORM_STEP) + 1)
    if estimate > MAX_KMEANS_OBSERVATIONS:
        return (
            f"a uniform population over {size[0]:g} x {size[1]:g} m: Gazebo's k-means would cluster about "
            f"{estimate} observations (one every {UNIFORM_STEP:g} m); at most {MAX_KMEANS_OBSERVATIONS} here"
        )

    def steps(length: float) -> List[float]:
        values, at = [], 0.0
        while at < length:
            values.append(at)
            at += UNIFORM_STEP
        return values

    xs, ys = steps(size[0]), steps(size[1])
    grid_x, grid_y = np.meshgrid(np.asarray(xs), np.asarray(ys))  # rows of y, x inner
    heights = np.asarray([rng.uniform(0, size[2]) for _ in range(grid_x.size)])
    return np.column_stack([grid_x.ravel(), grid_y.ravel(), heights])


def _kmeans(points, k: int):
    """ignition-math's Kmeans::Cluster on points (n x 3): the centroids, or why not."""
    import numpy as np  # noqa: PLC0415  (a uniform population only)

    obs = np.asarray(points, dtype=np.float64)
    if k > len(obs):
        return f"model_count {k} is more than the {len(obs)} k-means observations Gazebo makes of the region"
    if len(obs) * k > MAX_KMEANS_WORK:
        return f"model_count {k} over {len(obs)} observations: more k-means work than {MAX_KMEANS_WORK} a pass"
    centroids = obs[:k].copy()
    labels = np.zeros(len(obs), dtype=np.int64)
    chunk = max(1, 2**18 // k)
    for _ in range(MAX_KMEANS_PASSES):
        new = np.empty_like(labels)
        for at in range(0, len(obs), chunk):
            part = obs[at : at + chunk]
            distances = np.sqrt(((part[:, None, :] - centroids[None, :, :]) ** 2).sum(axis=2))
            new[at : at + chunk] = distances.argmin(axis=1)  # the first of equals, as ClosestCentroid
        changed = int((new != labels).sum())
        labels = new
        counts = np.bincount(labels, minlength=k)
        if (counts == 0).any():
            return "Gazebo's k-means leaves a cluster empty for this region and count (its centroid is not a number)"
        sums = np.zeros((k, 3))
        np.add.at(sums, labels, obs)
        centroids = sums / counts[:, None]
        if changed <= len(obs) >> 10:
            break
    return [(float(c[0]), float(c[1]), float(c[2])) for c in centroids]


def _rotate(q, v: Vec3) -> Vec3:
    x, y, z, w = q
    vx, vy, vz = v
    # v + 2 w (u x v) + 2 u x (u x v), u the vector part
    cx, cy, cz = y * vz - z * vy, z * vx - x * vz, x * vy - y * vx
    return (
        vx + 2 * (w * cx + y * cz - z * cy),
        vy + 2 * (w * cy + z * cx - x * cz),
        vz + 2 * (w * cz + x * cy - y * cx),
    )


def _add(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])
