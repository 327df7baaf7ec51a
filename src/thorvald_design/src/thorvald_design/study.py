"""A design study file: the candidates (robot files, sweeps, payloads) and the scenarios they are
put through, read and checked as a robot file is (every problem with the file, the key path, the
value and the rule; "did you mean" for a key that looks like a known one).

A study file::

    description: "Which of the example robots for a grass field with 0.75 m rows?"
    seed: 0                      # of every run's sensor noise and as-built draw
    candidates:
      std: {robot: thorvald_ii_4wd4ws_std}                # an example robot's name, or a robot file
      std_loaded: {robot: thorvald_ii_4wd4ws_std, payload: {mass: 80, x: 0.0, y: 0.0, z: 0.9}}
      wide:
        robot: thorvald_ii_4wd4ws_std
        sweep: {"motor_drives.*.y": [0.6, 0.75, 0.9]}      # one candidate per combination
    scenarios:
      gradeability: {surface: grass, speed: 0.5}
      turning: {}

A robot file named by a relative path is found from the study file's folder; a bare name without
``.yaml`` is an example robot (``thorvald_model/config/NAME/NAME.yaml``).

A sweep's key path is a robot file's (``motor_drives.drive0.r_wheel``); ``*`` stands for every entry
of a section (``motor_drives.*.y``). A number set through ``*`` keeps each entry's sign, so that a
symmetric robot stays symmetric: ``motor_drives.*.y: 0.75`` puts the left wheels at +0.75 m and the
right ones at -0.75 m. Every combination of the sweep's values is one candidate, named
``NAME[y=0.75]`` (``NAME[y=0.75,r_wheel=0.25]``), whose robot file the study writes (and checks with
the robot files' own loader) before anything runs.

A payload is a box of its mass [kg] on the frame, centred at (x, y, z) in base_link [m], added to the
robot file as a frame part, so the description, its mass properties and the physics all carry it.

Pure: YAML in, frozen values out (no ROS, no pybullet).
"""

import copy
import itertools
import math
import os
import re
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from thorvald_model.config import parse_robot_config
from thorvald_model.description import package_file
from thorvald_model.errors import MISSING, ConfigError, Problem
from thorvald_model.plugins import calculator_problems
from thorvald_model.schema import (
    NON_NEGATIVE,
    Key,
    check_top_level,
    close_key,
    parse_entry,
    parse_scalar,
    read_yaml_file,
    short,
    unknown_key_rule,
)

from .optimise import Range, parse_optimise, parse_range
from .scenarios import SCENARIOS

WHAT = "design study"
MAX_CANDIDATES = 256  # after sweeps: more runs than a study on one machine finishes in a day
MAX_SWEEP_VALUES = 64  # of one key path
PAYLOAD_SIZE = (0.4, 0.4, 0.2)  # [m] the payload box's size (its mass is what matters)
NAME_RULE = "must be letters, digits, '_' or '-' (it names the candidate's files)"
_NAME = re.compile(r"^[A-Za-z0-9_-]{1,64}$")

TOP_KEYS = (
    Key("description", str, ""),
    Key("seed", int, 0, check=lambda v: 0 <= v < 2**31, rule="must be in [0, 2^31)"),
)
CANDIDATE_KEYS = (
    Key("robot", str),
    Key("as_built", str, ""),  # an as-built file or PROFILE:SEED (thorvald_sim.as_built)
)
PAYLOAD_KEYS = (
    Key("mass", float, **NON_NEGATIVE),
    Key("x", float, 0.0),
    Key("y", float, 0.0),
    Key("z", float, 0.8),
)
KNOWN = ("description", "seed", "candidates", "scenarios", "optimise", "pareto")


@dataclass(frozen=True)
class Payload:
    mass: float  # [kg]
    x: float  # [m] its centre in base_link
    y: float
    z: float


@dataclass(frozen=True)
class Candidate:
    """One robot of the study: what its runs load (its robot file, after the sweep and the payload)."""

    name: str
    robot_file: str  # the file as given (an example robot's path for a bare name)
    robot_data: Mapping  # the robot file's contents with the sweep's values and the payload applied
    as_built: str = ""
    payload: Optional[Payload] = None
    swept: Tuple[Tuple[str, float], ...] = ()  # (key path, value) of a sweep's combination
    family: str = ""  # the candidate a sweep's combination comes from ("" for a plain one)


@dataclass(frozen=True)
class Space:
    """A candidate whose sweep a search explores (``--optimise``): its robot file and what every
    combination shares, and its key paths' values (a list of choices, or a Range)."""

    name: str
    robot_file: str
    robot_data: Mapping
    as_built: str
    payload: Optional[Payload]
    dimensions: Tuple[Tuple[str, Any], ...]  # (key path, tuple of values or optimise.Range)

    def candidate(self, values: Mapping[str, float]) -> Candidate:
        """The candidate of one combination (key path -> value), named as a sweep names it; ValueError
        if the robot files' rules refuse it."""
        swept = tuple((key_path, float(values[key_path])) for key_path, _ in self.dimensions)
        problems: List[Problem] = []
        robot = _applied(self.robot_data, swept, self.payload, self.name, problems)
        label = self.name + "[" + ",".join(f"{k.split('.')[-1]}={v:g}" for k, v in swept) + "]"
        if robot is None or problems:
            raise ValueError(f"{label}: " + "; ".join(f"{p.path}: {p.rule}" for p in problems))
        config = parse_robot_config(robot, f"{self.robot_file} ({label})")  # ConfigError: refused
        refused = calculator_problems(config)
        if refused:
            raise ConfigError(f"{self.robot_file} ({label})", refused)
        return Candidate(label, self.robot_file, robot, self.as_built, self.payload, swept, family=self.name)


@dataclass(frozen=True)
class Study:
    source: str
    description: str
    seed: int
    candidates: Tuple[Candidate, ...]
    scenarios: Tuple[Tuple[str, Mapping[str, Any]], ...]  # (scenario, its checked parameters), in file order
    text: str = ""  # the study file as written (the report shows it)
    optimise: Any = None  # thorvald_design.optimise.OptimiseSpec of an ``optimise:`` section, or None
    pareto: Optional[Tuple[str, str]] = None  # two SCENARIO.METRIC columns the report's Pareto plot compares
    space: Optional[Space] = None  # the optimised candidate's (among ``candidates`` too, unless it has a range)


def load_study(path: str) -> Study:
    """Reads and checks a study file; ConfigError naming every problem (the file, key path, value, rule)."""
    data = read_yaml_file(path, WHAT)
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    return parse_study(data, path, base_dir=os.path.dirname(os.path.abspath(path)), text=text)


def parse_study(data: Any, source: str = "<study>", base_dir: str = ".", text: str = "") -> Study:
    problems: List[Problem] = []
    data = check_top_level(data, KNOWN, problems, source=source, what=WHAT)
    description = parse_scalar(data, TOP_KEYS[0], problems)
    seed = parse_scalar(data, TOP_KEYS[1], problems)
    scenarios = _scenarios(data.get("scenarios", MISSING), problems)
    raw_candidates = data.get("candidates", MISSING)
    spec = parse_optimise(
        data.get("optimise", MISSING),
        "optimise",
        problems,
        candidates=raw_candidates if isinstance(raw_candidates, Mapping) else None,
        scenarios=[name for name, _ in scenarios],
    )
    pareto = _pareto(data.get("pareto", MISSING), scenarios, problems)
    searched = spec.candidate if spec is not None else None
    spaces: List[Space] = []
    candidates = _candidates(raw_candidates, base_dir, problems, searched, spaces)
    if problems:
        raise ConfigError(source, problems, WHAT)
    space = spaces[0] if spaces else None
    return Study(
        source, description, seed, tuple(candidates), tuple(scenarios), text, optimise=spec, space=space, pareto=pareto
    )


def _pareto(
    raw: Any, scenarios: Sequence[Tuple[str, Mapping[str, Any]]], problems: List[Problem]
) -> Optional[Tuple[str, str]]:
    """``pareto: [SCENARIO.METRIC, SCENARIO.METRIC]``: the two metrics the report's Pareto plot compares."""
    if raw is MISSING or raw is None:
        return None
    rule = "must be a list of two metrics SCENARIO.METRIC of the study's scenarios, e.g. [gradeability.max_climb_deg, turning.turning_diameter_m]"  # noqa: E501
    if not isinstance(raw, Sequence) or isinstance(raw, str) or len(raw) != 2:
        problems.append(Problem("pareto", short(raw), rule))
        return None
    known = [f"{s}.{m}" for s, params in scenarios for m in SCENARIOS[s].columns(params)]
    found = len(problems)
    for k, column in enumerate(raw):
        if column not in known:
            close = close_key(str(column), known)
            hint = f" (did you mean {close!r}?)" if close else f" (the study's: {', '.join(known)})"
            problems.append(Problem(f"pareto[{k}]", column, "is not a metric of the study's scenarios" + hint))
    return (str(raw[0]), str(raw[1])) if len(problems) == found else None


# ---- scenarios ------------------------------------------------------------------------------------
def _scenarios(section: Any, problems: List[Problem]) -> List[Tuple[str, Mapping[str, Any]]]:
    if section is MISSING:
        problems.append(Problem("scenarios", MISSING, "is required: a mapping of scenario -> its parameters"))
        return []
    if not isinstance(section, Mapping) or not section:
        problems.append(Problem("scenarios", short(section), "must be a mapping of scenario -> its parameters"))
        return []
    out = []
    for name, params in section.items():
        kind = SCENARIOS.get(name)
        if kind is None:
            problems.append(Problem(f"scenarios.{name}", short(params), unknown_key_rule(name, list(SCENARIOS))))
            continue
        values = parse_entry({} if params is None else params, f"scenarios.{name}", kind.keys, problems)
        if values is not None:
            found = len(problems)
            kind.check(values, f"scenarios.{name}", problems)
            if len(problems) == found:
                out.append((name, values))
    return out


# ---- candidates -----------------------------------------------------------------------------------
def _candidates(
    section: Any, base_dir: str, problems: List[Problem], searched: Optional[str] = None, spaces: Optional[List] = None
) -> List[Candidate]:
    """The candidates, sweeps expanded; the one a search explores (``searched``) goes to ``spaces`` too
    (and only there when a key path of its sweep is a range, which no sweep runs)."""
    if section is MISSING:
        problems.append(Problem("candidates", MISSING, "is required: a mapping of name -> {robot: ...}"))
        return []
    if not isinstance(section, Mapping) or not section:
        problems.append(Problem("candidates", short(section), "must be a mapping of name -> {robot: ...}"))
        return []
    out: List[Candidate] = []
    for name, entry in section.items():
        path = f"candidates.{name}"
        if not _NAME.match(str(name)):
            problems.append(Problem(path, MISSING, NAME_RULE))
            continue
        out.extend(_candidate(str(name), entry, path, base_dir, problems, spaces=spaces if name == searched else None))
    if len(out) > MAX_CANDIDATES:
        rule = f"the sweeps make {len(out)} candidates: at most {MAX_CANDIDATES} (search with --optimise instead)"
        problems.append(Problem("candidates", MISSING, rule))
    return out


def _candidate(
    name: str, entry: Any, path: str, base_dir: str, problems: List[Problem], *, spaces: Optional[List] = None
) -> List[Candidate]:
    if not isinstance(entry, Mapping):
        problems.append(Problem(path, short(entry), "must be a mapping with robot: (and as_built, payload, sweep)"))
        return []
    plain = {k: v for k, v in entry.items() if k not in ("payload", "sweep")}
    values = parse_entry(plain, path, CANDIDATE_KEYS, problems)
    payload = _payload(entry.get("payload"), f"{path}.payload", problems)
    sweep = _sweep(entry.get("sweep"), f"{path}.sweep", problems)
    if values is None:
        return []
    robot_file = _robot_file(values["robot"], base_dir, f"{path}.robot", problems)
    if robot_file is None:
        return []
    try:
        data = read_yaml_file(robot_file, "robot configuration")
    except ConfigError as e:
        problems.append(Problem(f"{path}.robot", values["robot"], str(e)))
        return []
    ranges = [key_path for key_path, dimension in sweep if isinstance(dimension, Range)]
    if spaces is not None:  # the search's space (--optimise); swept too when it has no range
        spaces.append(Space(name, robot_file, data, values["as_built"], payload, tuple(sweep)))
        if ranges:
            return []
    if ranges:
        rule = "is a range {min, max}: only a search (optimise: candidate: " + name + ") runs one"
        problems.append(Problem(f"{path}.sweep.{ranges[0]}", MISSING, rule))
        return []
    count = math.prod(len(values_) for _, values_ in sweep) if sweep else 1
    if count > MAX_CANDIDATES:  # refused before any is made: each is a robot file checked
        rule = f"the sweep makes {count} candidates: at most {MAX_CANDIDATES} (search with --optimise instead)"
        problems.append(Problem(f"{path}.sweep", MISSING, rule))
        return []
    out = []
    combos = itertools.product(*(values_ for _, values_ in sweep)) if sweep else [()]
    for combo in combos:
        swept = tuple((key_path, value) for (key_path, _), value in zip(sweep, combo))
        robot = _applied(data, swept, payload, f"{path}.sweep", problems)
        if robot is None:
            continue
        label = name + ("[" + ",".join(f"{k.split('.')[-1]}={v:g}" for k, v in swept) + "]" if swept else "")
        source = f"{robot_file} ({label})"
        try:
            config = parse_robot_config(robot, source)
            refused = calculator_problems(config)  # its calculator must serve its layout, as base_driver checks
            if refused:
                raise ConfigError(source, refused)
        except ConfigError as e:
            problems.append(Problem(path, label, f"makes a robot the robot files' rules refuse:\n{e}"))
            continue
        out.append(
            Candidate(label, robot_file, robot, values["as_built"], payload, swept, family=name if swept else "")
        )
    return out


def _robot_file(value: str, base_dir: str, path: str, problems: List[Problem]) -> Optional[str]:
    if not value.endswith((".yaml", ".yml")) and os.sep not in value:
        found = package_file("config", value, value + ".yaml")
        if os.path.isfile(found):
            return found
        examples = sorted(os.listdir(package_file("config")))
        problems.append(Problem(path, value, "no example robot of that name (examples: " + ", ".join(examples) + ")"))
        return None
    full = os.path.normpath(os.path.join(base_dir, os.path.expanduser(value)))
    if not os.path.isfile(full):
        problems.append(Problem(path, value, f"no such file: {full} (a relative path is from the study file's folder)"))
        return None
    return full


def _payload(raw: Any, path: str, problems: List[Problem]) -> Optional[Payload]:
    if raw is None:
        return None
    values = parse_entry(raw, path, PAYLOAD_KEYS, problems)
    if values is None or values["mass"] == 0.0:
        return None
    return Payload(values["mass"], values["x"], values["y"], values["z"])


def _sweep(raw: Any, path: str, problems: List[Problem]) -> List[Tuple[str, Any]]:
    if raw is None:
        return []
    if not isinstance(raw, Mapping) or not raw:
        problems.append(Problem(path, short(raw), "must be a mapping of key path -> list of values"))
        return []
    out = []
    for key_path, values in raw.items():
        where = f"{path}.{key_path}"
        parts = str(key_path).split(".")
        if len(parts) != 3 or not all(parts):
            rule = "must be a robot file's key path SECTION.ENTRY.KEY (ENTRY may be *), e.g. motor_drives.*.y"
            problems.append(Problem(where, short(values), rule))
            continue
        if isinstance(values, Mapping):  # {min, max}: a range a search explores
            found = parse_range(values, where, problems)
            if found is not None:
                out.append((str(key_path), found))
            continue
        if not isinstance(values, Sequence) or isinstance(values, str) or not values:
            problems.append(Problem(where, short(values), "must be a list of numbers (or {min, max} for a search)"))
            continue
        if len(values) > MAX_SWEEP_VALUES:
            problems.append(Problem(where, short(values), f"at most {MAX_SWEEP_VALUES} values"))
            continue
        numbers = []
        for v in values:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                problems.append(Problem(where, short(values), f"{v!r} is not a finite number"))
                break
            numbers.append(float(v))
        else:
            if len(set(numbers)) != len(numbers):
                problems.append(Problem(where, short(values), "the values must differ"))
                continue
            out.append((str(key_path), tuple(numbers)))
    return out


def _applied(
    data: Mapping, swept: Sequence[Tuple[str, float]], payload: Optional[Payload], path: str, problems: List[Problem]
) -> Optional[Dict]:
    """The robot file's contents with the sweep's values set and the payload added; None (a problem
    recorded) if a key path names no entry of the file."""
    robot = copy.deepcopy(dict(data or {}))
    for key_path, value in swept:
        section, entry, key = key_path.split(".")
        entries = robot.get(section)
        if not isinstance(entries, Mapping) or not entries:
            rule = f"the robot file has no section {section!r}" + _like(section, robot)
            problems.append(Problem(f"{path}.{key_path}", value, rule))
            return None
        names = list(entries) if entry == "*" else [entry]
        for name in names:
            if name not in entries or not isinstance(entries[name], Mapping):
                rule = f"the robot file's {section} has no entry {name!r}" + _like(name, entries)
                problems.append(Problem(f"{path}.{key_path}", value, rule))
                return None
            old = entries[name].get(key)
            # through *, a number keeps each entry's sign: a symmetric robot stays symmetric
            signed = -value if entry == "*" and isinstance(old, (int, float)) and old < 0 else value
            entries[name] = {**entries[name], key: signed}
    if payload is not None:
        parts = dict(robot.get("frame_parts") or {})
        size_x, size_y, size_z = PAYLOAD_SIZE
        parts[f"part{len(parts)}"] = {
            "shape": "box", "x": payload.x, "y": payload.y, "z": payload.z,
            "size_x": size_x, "size_y": size_y, "size_z": size_z, "mass": payload.mass, "color": "orange",
        }  # fmt: skip
        robot["frame_parts"] = parts
    return robot


def _like(name: str, known: Mapping) -> str:
    close = close_key(name, [str(k) for k in known])
    return f" (did you mean {close!r}?)" if close else ""


__all__ = ["Candidate", "Payload", "Space", "Study", "load_study", "parse_study"]
