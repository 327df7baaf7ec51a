"""Frame and joint names of a robot: the tf_prefix of the original's two conventions.

The original's generator changed how it joined ``tf_prefix`` to names (reconstruction notes,
section 6): newer launch files pass ``tf_prefix:="thorvald_001/"`` and the names are concatenated;
older ones (the CMP9767M course) pass ``tf_prefix:="thorvald_001"`` and the generator inserted the
slash. Both give ``thorvald_001/base_link``. Every part that names frames or joints (base_driver,
the model, the simulator through the model) takes the prefix through :func:`normalize_tf_prefix`.
"""


def normalize_tf_prefix(tf_prefix) -> str:
    """The prefix to concatenate to frame and joint names: empty, or ending in exactly one slash.

    ``""`` and ``"/"`` give ``""``; ``"thorvald_001"``, ``"thorvald_001/"`` and ``"/thorvald_001"``
    give ``"thorvald_001/"`` (tf2 frame names never start with a slash).
    """
    name = str(tf_prefix or "").strip().strip("/")
    return name + "/" if name else ""


__all__ = ["normalize_tf_prefix"]
