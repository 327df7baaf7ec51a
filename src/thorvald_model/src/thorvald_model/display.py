"""Whether RViz has a display to show on, and what to do without one: without a display RViz aborts
(Qt's "could not connect to display", exit status -6) and nothing says why.

Pure (the environment in, a sentence out); the ``rviz`` wrapper of thorvald_model and thorvald_sim's
``rviz_sensors`` say it before they start RViz.
"""

import os
from typing import Mapping, Optional

HEADLESS = "docs/description.md#rviz-without-a-display"


def display_problem(environ: Mapping[str, str] = os.environ) -> Optional[str]:
    """Why RViz cannot open a window here, with what to do instead; None when there is a display."""
    if environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY"):
        return None
    return (
        "no display (DISPLAY is not set): RViz needs one. Run RViz on a computer with a screen on the same "
        "ROS master (ROS_MASTER_URI), or here under a virtual one: xvfb-run -a -s '-screen 0 1280x1024x24' "
        f"env LIBGL_ALWAYS_SOFTWARE=1 roslaunch ... ({HEADLESS})"
    )


__all__ = ["HEADLESS", "display_problem"]
