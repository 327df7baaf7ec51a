from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import find_packages, setup

# every package under src/, subpackages included: a list by hand left thorvald_base.can out of installs
setup(**generate_distutils_setup(packages=find_packages("src"), package_dir={"": "src"}))
