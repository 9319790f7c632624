"""Fixtures of the tests; the helpers themselves live in testkit.py."""

from __future__ import annotations

import pytest

from testkit import simulate_toml


@pytest.fixture
def simulate():
    return simulate_toml
