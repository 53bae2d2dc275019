"""Fixtures of the identification tests; the synthetic cases live in ``arx_cases.py``."""

import pytest
from arx_cases import simulate_arx


@pytest.fixture
def arx_data():
    return simulate_arx
