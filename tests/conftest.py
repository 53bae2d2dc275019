"""Shared test configuration: headless plotting and deterministic hypothesis runs."""

import os

os.environ.setdefault("MPLBACKEND", "Agg")

from hypothesis import settings  # noqa: E402

settings.register_profile("gripkit", deadline=None, max_examples=60, derandomize=True)
settings.load_profile("gripkit")
