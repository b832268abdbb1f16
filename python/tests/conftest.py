"""Shared fixtures: the repository's scenes and a small render of one."""

from __future__ import annotations

from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def scenes() -> Path:
    """The scene suite's folder."""
    return REPOSITORY / "scenes"


@pytest.fixture(scope="session")
def cornell(scenes: Path) -> Path:
    """A small scene that renders in milliseconds."""
    return scenes / "cornell_box.xml"
