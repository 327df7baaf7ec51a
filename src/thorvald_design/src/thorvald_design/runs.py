"""A study's runs: one (candidate, scenario) a run, each in a worker process of its own pybullet
client, their results gathered into ``results.json`` as each ends.

:func:`prepare` writes every candidate's robot file into ``DIR/candidates/`` (what its runs load,
kept so a run can be repeated by hand); :func:`run_one` is what a worker runs: it builds the
candidate's design and lab and runs the scenario's procedure, and never raises: a candidate that
cannot be built or spawned, or a scenario that breaks, comes back as ``"failed: why"``.

Not pure: the runs run pybullet.
"""

import json
import math
import os
import time
import traceback
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Tuple

import yaml

from thorvald_model.errors import ThorvaldModelError
from thorvald_sim.errors import ThorvaldSimError

from .scenarios import SCENARIOS
from .study import Candidate, Study

RESULTS = "results.json"


@dataclass(frozen=True)
class Job:
    candidate: str
    robot_file: str  # the candidate's file in DIR/candidates
    as_built: str
    seed: int
    scenario: str
    params: Tuple[Tuple[str, Any], ...]
    out_dir: str = ""  # where the run's tracks and the candidate's picture go ("": nowhere)

    @property
    def label(self) -> str:
        return f"{self.candidate}: {self.scenario}"


def candidate_file(out_dir: str, candidate: Candidate) -> str:
    return os.path.join(out_dir, "candidates", safe_name(candidate.name) + ".yaml")


def safe_name(name: str) -> str:
    return "".join(c if c.isalnum() or c in "_-=.," else "_" for c in name)


def prepare(study: Study, out_dir: str) -> List[Job]:
    """Writes each candidate's robot file; the runs, candidate by candidate, scenario by scenario."""
    jobs = []
    for candidate in study.candidates:
        path = prepare_candidate(out_dir, candidate)
        for scenario, params in study.scenarios:
            params_ = tuple(sorted(params.items()))
            jobs.append(Job(candidate.name, path, candidate.as_built, study.seed, scenario, params_, out_dir))
    return jobs


def prepare_candidate(out_dir: str, candidate: Candidate) -> str:
    """Writes the candidate's robot file (as its runs load it) into DIR/candidates; its path."""
    os.makedirs(os.path.join(out_dir, "candidates"), exist_ok=True)
    path = candidate_file(out_dir, candidate)
    text = yaml.safe_dump(dict(candidate.robot_data), sort_keys=False, default_flow_style=None)
    header = f"# {candidate.name}: {candidate.robot_file}"
    header += "".join(f", {k} = {v:g}" for k, v in candidate.swept)
    if candidate.payload is not None:
        header += f", payload {candidate.payload.mass:g} kg"
    _write_if_changed(path, header + "\n" + text)
    return path


def _write_if_changed(path: str, text: str) -> None:
    try:
        with open(path, encoding="utf-8") as f:
            if f.read() == text:
                return
    except OSError:
        pass
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def run_one(job: Job) -> Dict[str, Any]:
    """Runs one job: ``{"candidate", "scenario", "mass_kg", "result"}``, result a mapping of metrics or
    ``"failed: why"`` (``"build"`` failures: the candidate's own, before any scenario)."""
    from .design import design_of  # noqa: PLC0415 (the worker's imports: xacro, pybullet)
    from .lab import Lab  # noqa: PLC0415

    started = time.monotonic()
    out: Dict[str, Any] = {"candidate": job.candidate, "scenario": job.scenario, "mass_kg": None}
    try:
        design = design_of(job.candidate, job.robot_file)
    except (ThorvaldModelError, ValueError, RuntimeError) as e:
        out.update(result=f"failed: cannot be built: {_one_line(e)}", build_failed=True)
        return out
    out["mass_kg"] = round(design.mass, 3)
    lab = Lab(job.robot_file, job.as_built, job.seed)
    try:
        result = SCENARIOS[job.scenario].procedure(lab, design, dict(job.params))
    except (ThorvaldModelError, ThorvaldSimError) as e:  # the robot's own: its files, its spawn
        what = "cannot be spawned" if isinstance(e, ThorvaldSimError) else "cannot be built"
        out.update(result=f"failed: {what}: {_one_line(e)}", build_failed=True)
        return out
    except Exception as e:  # a run must never take the study down: the failure is its result
        where = traceback.extract_tb(e.__traceback__)[-1]
        out.update(result=f"failed: broke: {_one_line(e)} ({os.path.basename(where.filename)}:{where.lineno})")
        return out
    out["result"] = result
    out["timing"] = {"simulated_s": round(lab.simulated, 3), "wall_s": round(time.monotonic() - started, 3)}
    if job.out_dir:
        from .report import draw_tracks  # noqa: PLC0415 (the report imports this module)

        write_tracks(os.path.join(job.out_dir, "tracks", safe_name(job.candidate), job.scenario + ".json"), lab.drives)
        out["drawn"] = not draw_tracks(job.out_dir, job.candidate, job.scenario)  # the page's plot, drawn here
        picture = os.path.join(job.out_dir, "pictures", safe_name(job.candidate) + ".png")
        if not os.path.exists(picture):
            take_picture(Lab(job.robot_file, job.as_built, job.seed), picture)
    return out


TRACK_PERIOD = 0.1  # [s] between the poses a track file keeps


def write_tracks(path: str, drives) -> None:
    """The drives' tracks (world frame, a pose every TRACK_PERIOD: x, y, z [m], yaw, pitch, roll [rad]),
    worlds and marks (what the scenario says the report should draw beside a track), for the report's
    maps and side views."""
    tracks = []
    for drive in drives:
        kept, last = [], -math.inf
        for q in drive.track:
            if q.t - last >= TRACK_PERIOD - 1e-9:
                kept.append(q)
                last = q.t
        tracks.append(
            {
                "label": drive.label,
                "outcome": drive.outcome,
                "world": drive.world,
                **{k: [round(getattr(q, k), 4) for q in kept] for k in ("t", "x", "y", "yaw", "z", "pitch", "roll")},
                **({"marks": dict(drive.marks)} if getattr(drive, "marks", None) else {}),
            }
        )
    os.makedirs(os.path.dirname(path), exist_ok=True)
    write_json(path, {"world": drives[-1].world if drives else {}, "tracks": tracks})


def take_picture(lab, path: str) -> None:
    """The candidate standing on tarmac, rendered to PNG (written whole, then moved into place: two
    workers may take it at once)."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with lab.session({"ground": {"surface": "tarmac"}}, label="picture") as session:
        session.run(0.5, lambda t: (0.0, 0.0, 0.0))
        session.picture(path + f".{os.getpid()}.png")
    os.replace(path + f".{os.getpid()}.png", path)


def _one_line(e: BaseException) -> str:
    text = str(e).strip().replace("\n", " ")
    return text or type(e).__name__


# ---- results.json -----------------------------------------------------------------------------------
def empty_results(study: Study) -> Dict[str, Any]:
    return {
        "study": {"description": study.description, "seed": study.seed, "scenarios": [s for s, _ in study.scenarios]},
        "candidates": {
            c.name: {
                "status": "pending",
                "mass_kg": None,
                "robot": c.robot_file,
                "swept": {k: v for k, v in c.swept},
                "payload_kg": c.payload.mass if c.payload else 0.0,
                "scenarios": {},
            }
            for c in study.candidates
        },
    }


def merge(results: Dict[str, Any], run: Mapping[str, Any], study: Study) -> None:
    """Puts one run's result in its candidate's entry and updates the candidate's status."""
    entry = results["candidates"][run["candidate"]]
    if run["mass_kg"] is not None:
        entry["mass_kg"] = run["mass_kg"]
    entry["scenarios"][run["scenario"]] = run["result"]
    order = [s for s, _ in study.scenarios]
    entry["scenarios"] = {s: entry["scenarios"][s] for s in order if s in entry["scenarios"]}
    failures = [(s, r) for s, r in entry["scenarios"].items() if isinstance(r, str) and r.startswith("failed")]
    if failures:
        scenario, reason = failures[0]
        entry["status"] = reason if run.get("build_failed") else f"failed: {scenario}: {reason[len('failed: ') :]}"
    elif len(entry["scenarios"]) == len(order):
        entry["status"] = "ok"


def done(results: Mapping[str, Any], job: Job) -> bool:
    """Whether results already hold the job's result (--resume)."""
    entry = results.get("candidates", {}).get(job.candidate)
    return bool(entry) and job.scenario in entry.get("scenarios", {})


TIMING = "timing.json"  # each run's simulated and wall seconds (apart from results.json, which repeats to the byte)


def read_timing(out_dir: str) -> Dict[str, float]:
    """An earlier study's wall time of each run in out_dir [s], by the run's label; {} if none."""
    try:
        with open(os.path.join(out_dir, TIMING), encoding="utf-8") as f:
            runs = json.load(f)["runs"]
        return {str(r["run"]): float(r["wall_s"]) for r in runs}
    except (OSError, ValueError, KeyError, TypeError):
        return {}


def longest_first(jobs: List[Job], timed: Mapping[str, float], drives: Mapping[str, int]) -> List[Job]:
    """The jobs in the order to start them, the longest first, so that the workers end together (the
    runs started last are short ones). A run's length is its wall time in ``timed`` (an earlier study's,
    by label) or else its scenario's ``cost`` times the candidate's ``drives`` over four; equal ones
    keep the study's order."""

    def length(job: Job) -> float:
        if job.label in timed:
            return timed[job.label]
        return SCENARIOS[job.scenario].cost * drives.get(job.candidate, 4) / 4.0

    return sorted(jobs, key=length, reverse=True)


def read_results(out_dir: str) -> Optional[Dict[str, Any]]:
    try:
        with open(os.path.join(out_dir, RESULTS), encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def write_results(out_dir: str, results: Mapping[str, Any]) -> None:
    """results.json (:func:`write_json`)."""
    write_json(os.path.join(out_dir, RESULTS), results)


def write_json(path: str, value: Any) -> None:
    """JSON written whole to a new file, then moved over the old: a reader never sees half of it."""
    with open(path + ".part", "w", encoding="utf-8") as f:
        json.dump(value, f, indent=2, sort_keys=False)
        f.write("\n")
    os.replace(path + ".part", path)
