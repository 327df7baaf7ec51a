"""Where a package's files are: the devel or install space rospack finds, else the source tree.

Pure (rospkg only). Lookups are cached per ROS_PACKAGE_PATH: rospack crawls the whole path.
"""

import functools
import os


def package_folder(package: str, source_folder: str) -> str:
    """The folder of a ROS package where rospack finds it (devel or install space), else
    source_folder (plain Python use of the source tree, no ROS environment)."""
    return _package_folder(package, source_folder, os.environ.get("ROS_PACKAGE_PATH", ""))


@functools.lru_cache(maxsize=16)
def _package_folder(package: str, source_folder: str, ros_package_path: str) -> str:
    import rospkg  # noqa: PLC0415  (only when a file is looked up)

    try:
        return rospkg.RosPack().get_path(package)
    except rospkg.ResourceNotFound:
        return source_folder
