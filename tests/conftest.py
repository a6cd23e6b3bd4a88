"""Shared fixtures: built-in mechanisms loaded once per session."""

from __future__ import annotations

import numpy as np
import pytest

import pinmob


@pytest.fixture(scope="session")
def puu() -> pinmob.Mechanism:
    return pinmob.load("3-PUU")


@pytest.fixture(scope="session")
def puu_flat() -> pinmob.Mechanism:
    return pinmob.load("3-PUU-flat")


@pytest.fixture(scope="session")
def puu_vertical() -> pinmob.Mechanism:
    return pinmob.load("3-PUU-vertical")


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)
