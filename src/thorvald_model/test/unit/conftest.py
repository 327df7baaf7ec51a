"""Fixtures of these tests; the helpers live in model_test_helpers.py (a unique module name, so the
conftest.py files of several packages never shadow each other in one pytest run)."""

from model_test_helpers import robot  # noqa: F401
