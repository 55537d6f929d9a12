"""Built-in node types of mission trees: py_trees composites/decorators and the mission behaviours.

Importing this package registers them in ``hiconav.trees.registry.BEHAVIOURS``.
"""

from hiconav.trees.behaviours import composites, mission  # noqa: F401  (registration)
from hiconav.trees.behaviours.base import MissionBehaviour
from hiconav.trees.behaviours.mission import (
                                              Approach,
                                              Explore,
                                              HealthOk,
                                              ParseInstruction,
                                              ReturnToStart,
                                              Stop,
                                              TargetConfirmed,
                                              VerifyTarget,
)
from hiconav.trees.behaviours.viewing import approach_cell

__all__ = [
                                              "Approach",
                                              "Explore",
                                              "HealthOk",
                                              "MissionBehaviour",
                                              "ParseInstruction",
                                              "ReturnToStart",
                                              "Stop",
                                              "TargetConfirmed",
                                              "VerifyTarget",
                                              "approach_cell",
]
