"""``design_study STUDY.yaml --out DIR --optimise [--against-sweep]``: the study's ``optimise:`` search
run on the simulator, one combination's runs after another (:func:`thorvald_design.optimise.optimise`
chooses each from the ones before), and, on a small space, the full sweep of the same space to
compare the fronts and the runs each needed.

Every run is a study's run (:func:`thorvald_design.runs.run_one`): the combination's robot file in
``DIR/candidates/``, its tracks and picture; a combination and scenario run once (the sweep takes the
search's runs again: runs are deterministic) though each counts its own. Writes ``DIR/optimise.json``.

Not pure: the runs run pybullet.
"""

import os
import sys
from typing import Any, Dict, Mapping, Tuple

from .optimise import compare, full_sweep, optimise
from .runs import Job, prepare_candidate, run_one, write_json
from .study import Study

OPTIMISE = "optimise.json"


def run_search(study: Study, out_dir: str, against_sweep: bool = False) -> Dict[str, Any]:
    spec, space = study.optimise, study.space
    params = dict(study.scenarios)
    cache: Dict[Tuple[Tuple[float, ...], str], Any] = {}
    order = _order(study)

    def evaluate(values: Mapping[str, float], scenario: str) -> Any:
        key = (tuple(float(values[k]) for k, _ in space.dimensions), scenario)
        if key in cache:
            return cache[key]
        try:
            candidate = space.candidate(values)
        except Exception as e:
            cache[key] = f"failed: cannot be built: {' '.join(str(e).split())}"
            return cache[key]
        path = prepare_candidate(out_dir, candidate)
        job = Job(candidate.name, path, candidate.as_built, study.seed, scenario,
                  tuple(sorted(params[scenario].items())), out_dir)  # fmt: skip
        print(f"[run {len(cache) + 1}] {job.label}", file=sys.stderr, flush=True)
        cache[key] = run_one(job)["result"]
        return cache[key]

    os.makedirs(out_dir, exist_ok=True)
    found = optimise(spec, space.dimensions, evaluate, order, seed=study.seed)
    out: Dict[str, Any] = {
        "candidate": spec.candidate,
        "objectives": dict(spec.objectives),
        "requirements": [str(r) for r in spec.requirements],
        "scenario_order": order,
        "search": found.as_dict(),
    }
    if against_sweep:
        full = full_sweep(spec, space.dimensions, evaluate, order)
        out["sweep"] = {
            "runs": full.runs,
            "front": [dict(full.values[i]) for i in full.front],
            "feasible": len(full.feasible),
            "combinations": len(full.values),
        }
        out["comparison"] = compare(found, full)
    write_json(os.path.join(out_dir, OPTIMISE), out)
    return out


def _order(study: Study):
    """The scenarios in the order they run: those the requirements read first (a trial that fails one
    is pruned before the others run), then the rest as the study lists them."""
    spec = study.optimise
    first = [r.metric.split(".")[0] for r in spec.requirements]
    names = [name for name, _ in study.scenarios]
    return sorted(names, key=lambda n: (n not in first, names.index(n)))


def search_table(out: Mapping[str, Any]) -> str:
    """The front found (and the sweep's comparison) as text."""
    search = out["search"]
    lines = [
        f"search: {len(search['trials'])} combinations, {search['runs']} runs ({search['saved']} saved by pruning)"
    ]
    for number in search["front"]:
        trial = search["trials"][number]
        values = ", ".join(f"{k.split('.')[-1]}={v:g}" for k, v in trial["values"].items())
        metrics = ", ".join(f"{m}={trial['metrics'].get(m)}" for m in out["objectives"])
        lines.append(f"  front: {values}: {metrics}")
    if "comparison" in out:
        c = out["comparison"]
        lines.append(
            f"sweep: {out['sweep']['combinations']} combinations, {c['runs']['sweep']} runs; the search found "
            f"{c['front']['found']} of its {c['front']['sweep']} front points with {c['runs']['search']} runs "
            f"(the farthest missed by {c['max_distance']:.3f} of the objectives' ranges)"
            if c["max_distance"] is not None
            else "sweep: the search found no front"
        )
    return "\n".join(lines)
