"""Fixtures of the reasoning tests: a scripted HTTP server on 127.0.0.1, a subgraph, a task."""

from __future__ import annotations

import pytest

from hiconav.types import TaskSpec

from .fake_server import FakeVLMServer
from .helpers import FakeSubgraph, make_subgraph, make_task


@pytest.fixture
def subgraph() -> FakeSubgraph:
    return make_subgraph()


@pytest.fixture
def task() -> TaskSpec:
    return make_task()


@pytest.fixture(scope="module")
def server():
    with FakeVLMServer() as srv:
        yield srv


