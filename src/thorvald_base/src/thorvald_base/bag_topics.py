"""A recording's topics found by their ending, so a robot in any namespace is read alike.

Shared by ``calibrate_odometry`` and the odometry report (thorvald_bringup). Pure: topic names in,
names out.
"""

from typing import Dict, Iterable, Mapping, Type


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
