"""Fixtures of these tests; the helpers live in base_test_helpers.py (a unique module name, so the
conftest.py files of several packages never shadow each other in one pytest run)."""

from base_test_helpers import any_robot  # noqa: F401
