"""CLI fixtures."""

from __future__ import annotations

import pytest
from click.testing import CliRunner


@pytest.fixture()
def runner() -> CliRunner:
    """A click runner that keeps stdout and stderr apart."""
    return CliRunner()
