"""Settings shared by every pytest suite of the workspace.

Hypothesis explores new random examples on every local run; under CI (CI=true) it is derandomized,
so a landing never depends on the luck of the draw. A failure found locally prints its example.
"""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None)
settings.load_profile("ci" if os.environ.get("CI") else "dev")
