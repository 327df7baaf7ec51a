"""A recording's topics found by their ending, so a robot in any namespace is read alike, and the
messages a recording lost.

Shared by ``calibrate_odometry`` and the odometry report (thorvald_bringup). Pure: topic names and
numbers in, names and numbers out.
"""

from typing import Dict, Iterable, List, Mapping, Sequence, Tuple, Type


def topics_by_ending(
    names: Iterable[str], endings: Mapping[str, str], source: str, error: Type[Exception] = ValueError
) -> Dict[str, str]:
    """{key: the topic of names ending in endings[key]} for each key some topic ends in (``ending``
    itself, or ``.../ending``); error naming source if several topics end alike."""
    names = sorted(names)
    found = {}
    for key, ending in endings.items():
        matches = [n for n in names if n.lstrip("/") == ending or n.endswith("/" + ending)]
        if len(matches) > 1:
            raise error(f"{source}: several topics end in {ending}: {', '.join(matches)}")
        if matches:
            found[key] = matches[0]
    return found


def lost_messages(sequences: Mapping[str, Sequence[int]]) -> List[Tuple[str, int, int]]:
    """(topic, messages lost, the first lost one's seq) of each topic whose recorded messages skip
    numbers. A ROS publisher numbers the messages it publishes (header.seq, one a publish), so a gap
    between two recorded ones is a message published and never recorded (a reader that fell behind
    dropped it), not a cycle that did not run."""
    lost = []
    for topic, seqs in sorted(sequences.items()):
        ordered = sorted(set(seqs))
        gaps = [(b - a - 1, a + 1) for a, b in zip(ordered, ordered[1:]) if b - a > 1]
        if gaps:
            lost.append((topic, sum(n for n, _ in gaps), gaps[0][1]))
    return lost


def lost_sentence(lost: Sequence[Tuple[str, int, int]]) -> str:
    return "; ".join(f"{topic}: {n} lost, the first seq {first}" for topic, n, first in lost)
