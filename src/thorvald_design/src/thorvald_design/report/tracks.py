"""A tracks file read back (``DIR/tracks/CANDIDATE/SCENARIO.json``, :func:`thorvald_design.runs.write_tracks`):
the world its map shows and each drive's poses, world and marks (what the scenario said to draw
beside it). Pure."""

from dataclasses import dataclass, field
from typing import Any, Mapping, Tuple

from ..errors import ReportError
from .table import number


@dataclass(frozen=True)
class Drive:
    """One drive of a tracks file: its poses, how it ended, its world and what to draw beside it."""

    label: str  # "climb 14 deg"
    outcome: str  # "ok", "traction", ...
    x: Tuple[float, ...]  # [m] world frame
    y: Tuple[float, ...]
    yaw: Tuple[float, ...] = ()  # [rad] as many as x, or none
    t: Tuple[float, ...] = ()  # [s] as many as x, or none (each of these: an older file has none)
    z: Tuple[float, ...] = ()  # [m] base_link's height
    pitch: Tuple[float, ...] = ()  # [rad] nose up positive
    roll: Tuple[float, ...] = ()  # [rad]
    world: Mapping[str, Any] = field(default_factory=dict)  # its own world (a series' tries differ)
    marks: Mapping[str, Any] = field(default_factory=dict)  # what the scenario said to draw beside it


@dataclass(frozen=True)
class Tracks:
    """A tracks file: the world its map shows (the file's) and the drives."""

    world: Mapping[str, Any]
    drives: Tuple[Drive, ...]


def parse_tracks(data: Any) -> Tracks:
    """A tracks file's contents (``{"world": {...}, "tracks": [{"label", "outcome", "world", "marks",
    "t", "x", "y", "yaw", "z", "pitch", "roll"}]}``, all but x and y optional); ReportError saying
    what is wrong."""
    if not isinstance(data, Mapping) or not isinstance(data.get("tracks"), list):
        raise ReportError("not a mapping with a list of tracks")
    drives = []
    for k, track in enumerate(data["tracks"]):
        if not isinstance(track, Mapping):
            raise ReportError(f"track {k} is not a mapping")
        xs, ys = track.get("x"), track.get("y")
        if not isinstance(xs, list) or not isinstance(ys, list) or len(xs) != len(ys):
            raise ReportError(f"track {k}: x and y must be lists of one length")
        if not all(number(v) is not None for v in xs + ys):
            raise ReportError(f"track {k}: x and y must be finite numbers")
        more = {}
        for key in ("yaw", "t", "z", "pitch", "roll"):
            values = track.get(key)
            if values is not None and (
                not isinstance(values, list) or len(values) != len(xs) or not all(number(v) is not None for v in values)
            ):
                raise ReportError(f"track {k}: {key} must be as many finite numbers as x")
            more[key] = tuple(values or ())
        for key in ("world", "marks"):
            if track.get(key) is not None and not isinstance(track.get(key), Mapping):
                raise ReportError(f"track {k}: {key} must be a mapping")
            more[key] = dict(track.get(key) or {})
        label, outcome = str(track.get("label", "")), str(track.get("outcome", ""))
        drives.append(Drive(label, outcome, tuple(xs), tuple(ys), **more))
    world = data.get("world")
    if not isinstance(world, Mapping) or not world:  # an older file: the first track's own world
        world = next((t["world"] for t in data["tracks"] if isinstance(t.get("world"), Mapping)), {})
    return Tracks(world, tuple(drives))


__all__ = ["Drive", "Tracks", "parse_tracks"]
