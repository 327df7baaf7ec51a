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
``.yaml`` is an example robot (``thorvald_model/config/NAME/NAME.yaml``, :mod:`thorvald_model.examples`:
a mistyped one gets "did you mean").

A sweep's key path is a robot file's (``motor_drives.drive0.r_wheel``); ``*`` stands for every entry
of a section (``motor_drives.*.y``). A number set through ``*`` keeps each entry's sign, so that a
symmetric robot stays symmetric: ``motor_drives.*.y: 0.75`` puts the left wheels at +0.75 m and the
right ones at -0.75 m. Every combination of the sweep's values is one candidate, named
``NAME[y=0.75]`` (``NAME[y=0.75,r_wheel=0.25]``), whose robot file the study writes (and checks with
the robot files' own loader) before anything runs.

A sweep that would change nothing is refused before anything runs, as a broken one is: a key path the
robot files' schema does not know (a robot file may carry keys of its owner's for their own xacro,
but a study's candidates have no xacro of their own: nothing would read it), a key that holds no
number, and combinations that make the same robot as its runs read it (:func:`as_read`: a key nothing
reads for those entries, such as a steering key of a drive that does not steer, or values the loader
reads as one). So are values that would give two candidates one name.

A payload is a box of its mass [kg] on the frame, centred at (x, y, z) in base_link [m], added to the
robot file as a frame part, so the description, its mass properties and the physics all carry it.

Pure: YAML in, frozen values out (no ROS, no pybullet).
"""

import copy
import difflib
import itertools
import json
import math
import os
import re
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from thorvald_model import config_to_dict
from thorvald_model.config import parse_robot_config
from thorvald_model.errors import MISSING, ConfigError, Problem, UnknownRobotError
from thorvald_model.examples import names_a_file, robot_file
from thorvald_model.keys import SECTIONS
from thorvald_model.motors import STEERING_KEYS
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

from .errors import StudyError
from .optimise_spec import Range, parse_optimise, parse_range
from .scenarios import SCENARIOS, declared

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
    Key("as_built", str, ""),  # an as-built file or PROFILE:SEED (thorvald_sim.physics.as_built)
)
PAYLOAD_KEYS = (
    Key("mass", float, **NON_NEGATIVE),
    Key("x", float, 0.0),
    Key("y", float, 0.0),
    Key("z", float, 0.8),
)
KNOWN = ("description", "seed", "candidates", "scenarios", "optimise", "pareto")
SWEEP_KINDS = (float, int, bool)  # of the keys a sweep can set: its values are numbers (a bool's 0 or 1)

# Words a designer may write for the original's abbreviated keys, for "did you mean": difflib finds a
# typing mistake (r_wheeel: 0.93 alike) but not another word for the thing (width and w_wheel: 0.33).
# Through *, x and y keep each entry's sign: a half wheelbase and a half track.
SPELLED_OUT = {
    "x": "half_wheelbase",
    "y": "half_track",
    "r_wheel": "wheel_radius",
    "w_wheel": "wheel_width",
    "prp_gr_rt": "propulsion_gear_ratio",
    "prp_enc_ppr": "propulsion_encoder_ppr",
    "prp_max_rpm": "propulsion_max_rpm",
    "prp_sim_a": "acceleration",
    "str_gr_rt": "steering_gear_ratio",
    "str_enc_ppr": "steering_encoder_ppr",
    "str_lim": "steering_limit",
    "str_sim_v": "steering_speed",
    "prp_motor_torque": "propulsion_motor_torque",
    "str_motor_torque": "steering_motor_torque",
    "prp_motor_kt": "propulsion_torque_constant",
    "prp_motor_r": "propulsion_motor_resistance",
    "prp_motor_i0": "propulsion_no_load_current",
    "prp_gear_eff": "propulsion_gear_efficiency",
    "str_motor_kt": "steering_torque_constant",
    "str_motor_r": "steering_motor_resistance",
    "str_motor_i0": "steering_no_load_current",
    "str_gear_eff": "steering_gear_efficiency",
    "rail_r_wheel": "rail_wheel_radius",
    "rail_w_wheel": "rail_wheel_width",
}

# What nothing reads for an entry's kind, so that a sweep of it changes nothing: (section, whether an
# entry's key is unread, why). A drive that does not steer stands on a fixed joint in the description
# and base_driver commands it no steering (thorvald_model.motors: "nothing reads" its steering
# motor); an enclosure without a KC battery holds no pack (energy, the CAN emulator and base_driver
# take the fitted batteries only); a fixed wheel has no trail (the description's caster fork only).
STEERING_ONLY = (*STEERING_KEYS, "str_enc_ppr", "str_lim", "str_sim_v", "str_motor_torque", "steering_offset")
PACK_KEYS = ("capacity", "voltage", "internal_resistance")
UNREAD = (
    (
        "motor_drives",
        lambda d, key: not d.steerable and key in STEERING_ONLY,
        "a drive that does not steer (type 1) has a fixed leg: nothing reads its steering keys",
    ),
    (
        "batteries",
        lambda b, key: not b.present and key in PACK_KEYS,
        "an enclosure without a KC battery (type 0, or with_battery 0) holds no pack",
    ),
    ("passive_wheels", lambda w, key: w.fixed and key == "caster_offset", "a fixed wheel has no caster trail"),
)


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
    dimensions: Tuple[Tuple[str, Any], ...]  # (key path, tuple of values or optimise_spec.Range)

    def candidate(self, values: Mapping[str, float]) -> Candidate:
        """The candidate of one combination (key path -> value), named as a sweep names it; StudyError
        if a key path names no entry of the robot file, thorvald_model's ConfigError if the robot
        files' rules refuse the robot it makes."""
        swept = tuple((key_path, float(values[key_path])) for key_path, _ in self.dimensions)
        problems: List[Problem] = []
        robot = _applied(self.robot_data, swept, self.payload, self.name, problems)
        label = _label(self.name, swept)
        if robot is None or problems:
            why = "; ".join(f"{p.path}: {p.rule}" for p in problems)
            raise StudyError(label, [Problem("", MISSING, why)], WHAT)  # one line: "LABEL: why"
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
    optimise: Any = None  # thorvald_design.optimise_spec.OptimiseSpec of an ``optimise:`` section, or None
    pareto: Optional[Tuple[str, str]] = None  # two SCENARIO.METRIC columns the report's Pareto plot compares
    space: Optional[Space] = None  # the optimised candidate's (among ``candidates`` too, unless it has a range)


def load_study(path: str) -> Study:
    """Reads and checks a study file; StudyError (a ConfigError) naming every problem (the file, key
    path, value, rule), or the one reason a file that cannot be read at all cannot."""
    try:
        data = read_yaml_file(path, WHAT)
    except ConfigError as e:
        raise StudyError(e.source, e.problems, e.what) from None
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    return parse_study(data, path, base_dir=os.path.dirname(os.path.abspath(path)), text=text)


def parse_study(data: Any, source: str = "<study>", base_dir: str = ".", text: str = "") -> Study:
    """A study file's contents (YAML read) checked; StudyError naming every problem."""
    problems: List[Problem] = []
    try:
        data = check_top_level(data, KNOWN, problems, source=source, what=WHAT)
    except ConfigError as e:  # not a mapping: the one problem of the whole file
        raise StudyError(e.source, e.problems, e.what) from None
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
        raise StudyError(source, problems, WHAT)
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
        elif declared(column) is None or declared(column).words:  # refused here, not by the report after the runs
            rule = "is a metric of words, not numbers: it has no better direction to plot a front by"
            problems.append(Problem(f"pareto[{k}]", column, rule))
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
    found = len(problems)
    sweep = _sweep(entry.get("sweep"), f"{path}.sweep", problems)
    swept_well = len(problems) == found
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
    if not swept_well:  # nothing to make of a sweep that names what is not there
        return []
    ranges = [key_path for key_path, dimension in sweep if isinstance(dimension, Range)]
    if spaces is not None:  # the search's space (--optimise); swept too when it has no range
        spaces.append(Space(name, robot_file, data, values["as_built"], payload, tuple(sweep)))
        if ranges:
            _each_dimension_changes_the_robot(spaces[-1], path, problems)
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
    read: Dict[str, Tuple[Candidate, Any]] = {}  # a robot as its runs read it -> the first making it, its config
    same: Dict[Tuple[str, ...], Tuple[Candidate, Candidate, Any]] = {}  # key paths -> two combinations alike
    combos = itertools.product(*(values_ for _, values_ in sweep)) if sweep else [()]
    for combo in combos:
        swept = tuple((key_path, value) for (key_path, _), value in zip(sweep, combo))
        robot = _applied(data, swept, payload, f"{path}.sweep", problems)
        if robot is None:  # a key path names no entry of the file: the same for every combination
            break
        label = _label(name, swept)
        config = _checked(robot, f"{robot_file} ({label})", path, label, problems)
        if config is None:
            continue
        family = name if swept else ""
        candidate = Candidate(label, robot_file, robot, values["as_built"], payload, swept, family=family)
        out.append(candidate)
        first, first_config = read.setdefault(_fingerprint(config), (candidate, config))
        if first is not candidate:
            differ = tuple(k for (k, a), (_, b) in zip(first.swept, candidate.swept) if a != b)
            same.setdefault(differ, (first, candidate, first_config))
    for differ, (a, b, config) in same.items():
        for key_path in differ:
            values_ = [dict(a.swept)[key_path], dict(b.swept)[key_path]]
            rule = f"{a.name} and {b.name} make the same robot: " + _why_the_same(key_path, config)
            problems.append(Problem(f"{path}.sweep.{key_path}", values_, rule))
    return out


def _checked(robot: Mapping, source: str, path: str, label: str, problems: List[Problem]):
    """The robot's configuration as its runs load it; None (a problem recorded) if the robot files'
    rules or its calculator (as base_driver checks) refuse it."""
    try:
        config = parse_robot_config(robot, source)
        refused = calculator_problems(config)
        if refused:
            raise ConfigError(source, refused)
    except ConfigError as e:
        problems.append(Problem(path, label, f"makes a robot the robot files' rules refuse:\n{e}"))
        return None
    return config


def _each_dimension_changes_the_robot(space: Space, path: str, problems: List[Problem]) -> None:
    """A search's space (a sweep with a range, which no sweep expands): each key path's values, the
    others at their first (a range at its min), make robots the rules take and that differ; a range
    from its min to its max."""
    base = [(k, dimension.min if isinstance(dimension, Range) else dimension[0]) for k, dimension in space.dimensions]
    for i, (key_path, dimension) in enumerate(space.dimensions):
        values_ = (dimension.min, dimension.max) if isinstance(dimension, Range) else dimension
        seen: Dict[str, float] = {}
        for value in values_:
            swept = tuple([*base[:i], (key_path, value), *base[i + 1 :]])
            robot = _applied(space.robot_data, swept, space.payload, f"{path}.sweep", problems)
            if robot is None:
                return
            label = _label(space.name, swept)
            config = _checked(robot, f"{space.robot_file} ({label})", path, label, problems)
            if config is None:
                return
            first = seen.setdefault(_fingerprint(config), value)
            if first != value:
                which = f"{first:g} and {value:g}"
                which = f"the range's min and max, {which}," if isinstance(dimension, Range) else which
                rule = f"{which} make the same robot: " + _why_the_same(key_path, config)
                problems.append(Problem(f"{path}.sweep.{key_path}", [first, value], rule))
                break


def _label(name: str, swept: Sequence[Tuple[str, float]]) -> str:
    """A combination's candidate name: NAME[KEY=VALUE,...], each value to 6 significant digits."""
    return name + ("[" + ",".join(f"{k.split('.')[-1]}={v:g}" for k, v in swept) + "]" if swept else "")


def as_read(config) -> Dict[str, Any]:
    """The robot file as a study's runs read it: every default filled in and every alias resolved
    (``RobotConfig.to_dict``, which leaves out what the loader drops), less what nothing reads for an
    entry's kind (:data:`UNREAD`). Two combinations of a sweep with the same are the same robot."""
    out = config_to_dict(config)
    for section, unread, _ in UNREAD:
        for item in getattr(config, _ATTR[section]):
            entry = out[section][item.name]
            for key in [k for k in entry if unread(item, k)]:
                del entry[key]
    return out


_ATTR = {s.key: s.attr for s in SECTIONS}


def _fingerprint(config) -> str:
    return json.dumps(as_read(config), sort_keys=True, default=repr)


def _why_the_same(key_path: str, config) -> str:
    """Why a key path's values make one robot: what nothing reads for the kind of every entry it sets,
    else the loader reading the values as one."""
    section, entry, key = key_path.split(".")
    items = [i for i in getattr(config, _ATTR[section]) if entry in ("*", i.name)]
    for unread_section, unread, why in UNREAD:
        if unread_section == section and items and all(unread(i, key) for i in items):
            return f"{why} ({', '.join(i.name for i in items)})"
    return "the robot files' loader reads the values as the same"


def _robot_file(value: str, base_dir: str, path: str, problems: List[Problem]) -> Optional[str]:
    try:
        full = robot_file(value, base_dir)
    except UnknownRobotError as e:
        problems.append(Problem(path, value, e.rule))
        return None
    if names_a_file(value) and not os.path.isfile(full):
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
        if not _schema_key(parts, where, values, problems):
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
            named = {}
            for v in numbers:
                other = named.setdefault(f"{v:g}", v)
                if other != v:
                    rule = (
                        f"{other!r} and {v!r} would name one candidate ({parts[2]}={v:g}): "
                        "names keep 6 significant digits"
                    )
                    problems.append(Problem(where, short(values), rule))
                    break
            else:
                out.append((str(key_path), tuple(numbers)))
    return out


def _schema_keys(section: str) -> Dict[str, Key]:
    """The keys of a section's entries by name and alias (the robot files' schema,
    :mod:`thorvald_model.keys`); empty for a section the schema does not have."""
    for s in SECTIONS:
        if s.key == section:
            return {**{a: k for k in s.keys for a in k.aliases}, **{k.name: k for k in s.keys}}
    return {}


def _schema_key(parts: Sequence[str], where: str, values: Any, problems: List[Problem]) -> bool:
    """Whether a sweep's key path names a number key the robot files' schema knows; a problem with
    "did you mean" if not. A robot file may carry keys of its owner's (the loader keeps them for the
    owner's xacro), but a study's candidate has no xacro of its own: swept, such a key changes nothing."""
    section, _, key = parts
    known = _schema_keys(section)
    if not known:
        sections = [s.key for s in SECTIONS]
        close = difflib.get_close_matches(section, sections, n=1, cutoff=0.6)
        hint = f"did you mean {close[0]!r}?" if close else "its sections: " + ", ".join(sections)
        rule = f"the robot files' schema has no section {section!r}: a sweep of it would change nothing ({hint})"
        problems.append(Problem(where, short(values), rule))
        return False
    if key not in known:
        close = difflib.get_close_matches(key, sorted(known), n=1, cutoff=0.6)
        if not close:  # another word for an abbreviated key (width for w_wheel)
            words = {SPELLED_OUT[k]: k for k in known if k in SPELLED_OUT}
            close = [words[w] for w in difflib.get_close_matches(key, sorted(words), n=1, cutoff=0.6)]
        hint = f"did you mean {close[0]!r}?" if close else f"the keys of {section} entries: " + ", ".join(sorted(known))
        rule = (
            f"the robot files' schema has no key {key!r} in {section} entries: nothing reads it, so a sweep of it "
            f"would change nothing ({hint})"
        )
        problems.append(Problem(where, short(values), rule))
        return False
    if known[key].kind not in SWEEP_KINDS:
        rule = f"{section} entries' {key!r} is not a number (a sweep's values are numbers)"
        problems.append(Problem(where, short(values), rule))
        return False
    return True


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
            entries[name] = {**entries[name], key: _as_kind(signed, _schema_keys(section).get(key))}
    if payload is not None:
        parts = dict(robot.get("frame_parts") or {})
        size_x, size_y, size_z = PAYLOAD_SIZE
        parts[f"part{len(parts)}"] = {
            "shape": "box", "x": payload.x, "y": payload.y, "z": payload.z,
            "size_x": size_x, "size_y": size_y, "size_z": size_z, "mass": payload.mass, "color": "orange",
        }  # fmt: skip
        robot["frame_parts"] = parts
    return robot


def _as_kind(value: float, key: Optional[Key]) -> Any:
    """A swept number as its key's kind: a whole number for an integer key (1024, not 1024.0, as a
    file has it) and 0 or 1 as false or true, which the loader reads for a flag; anything else as it is
    (the loader then names the rule it breaks)."""
    if key is not None and key.kind in (int, bool) and float(value).is_integer():
        number = int(value)
        return bool(number) if key.kind is bool and number in (0, 1) else number
    return value


def _like(name: str, known: Mapping) -> str:
    close = close_key(name, [str(k) for k in known])
    return f" (did you mean {close!r}?)" if close else ""


__all__ = ["Candidate", "Payload", "Space", "Study", "as_read", "load_study", "parse_study"]
