from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(
    **generate_distutils_setup(
        packages=[
            "thorvald_base",
            "thorvald_base.bases",
            "thorvald_base.kinematics",
            "thorvald_base.msg",
            "thorvald_base.srv",
        ],
        package_dir={"": "src"},
    )
)
