"""Fixtures of these tests; the helpers live in sim_test_helpers.py."""

from sim_test_helpers import client  # noqa: F401
